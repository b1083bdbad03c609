/**
 * The simplifiers' parameter tables in the page equal the reference's
 * (testdata/params/params.json, the table of every parameter, and each
 * simplifier's testdata/<algorithm>/params.json, written by the Python
 * reference), the settings panel shows their rows, and the registry derives
 * which parameters belong to one simplifier only.
 */
import { readdirSync, readFileSync } from "node:fs";
import { join } from "node:path";
import { fileURLToPath } from "node:url";
import { describe, expect, it } from "vitest";
import { ALGORITHMS, ONLY_FOR, makeSimplifier } from "../src/simplify/registry";
import { ANGLE_PARAM_NAMES, PARAMETERS, WINDOW_PARAM_NAMES } from "../src/simplify/params";
import { DEFAULT_SETTINGS, FIELDS, SIMPLIFIER_PARAM_KEYS } from "../src/settings";
import { DETAIL_LEVELS, DETAIL_SPECS } from "../src/ui/detail";
import { AngleSimplifier } from "../src/simplify/angle";
import { WindowSimplifier } from "../src/simplify/window";
import { vectors } from "./testdata";

function table(algorithm: string): unknown[] {
  const found = vectors(algorithm).find(([name]) => name.endsWith("params.json"));
  if (found === undefined) throw new Error(`testdata/${algorithm}/params.json is missing`);
  return (found[1] as { parameters: unknown[] }).parameters;
}

interface Neutral {
  readonly algorithms: Record<string, string[]>;
  readonly parameters: Record<string, unknown>[];
}

function neutral(): Neutral {
  const found = vectors("params").find(([name]) => name.endsWith("params.json"));
  if (found === undefined) throw new Error("testdata/params/params.json is missing");
  return found[1] as Neutral;
}

describe("parameter tables", () => {
  it("holds every parameter once, as the reference's language-neutral table", () => {
    const reference = neutral();
    expect(PARAMETERS).toEqual(reference.parameters);
    expect(new Set(PARAMETERS.map((spec) => spec.name)).size).toBe(PARAMETERS.length);
    expect({ angle: ANGLE_PARAM_NAMES, window: WINDOW_PARAM_NAMES }).toEqual(reference.algorithms);
  });

  it.each(Object.values(ALGORITHMS))("$name equals the reference's table", (entry) => {
    const columns = ["name", "type", "default", "minimum", "maximum", "help"] as const;
    const rows = entry.specs.map((spec) => Object.fromEntries(columns.map((key) => [key, spec[key]])));
    expect(rows).toEqual(table(entry.name));
    for (const spec of entry.specs) expect(spec.algorithms).toContain(entry.name);
  });

  it("gives the settings panel a row for every parameter a person sets, with its label, unit and range", () => {
    const shown = PARAMETERS.filter((spec) => spec.panel !== null);
    for (const spec of shown) {
      const field = FIELDS.find((candidate) => candidate.key === spec.name);
      expect(field).toMatchObject({ section: spec.panel, label: spec.label, kind: spec.type });
      expect(field?.unit).toBe(spec.unit ?? undefined);
      expect(field?.minimum).toBe(spec.minimum ?? undefined);
      expect(field?.maximum).toBe(spec.maximum ?? undefined);
      if (spec.name !== "clear_on_press") {
        expect(field?.help).toBe(spec.help);
        expect(DEFAULT_SETTINGS[field!.key]).toBe(spec.default);
      }
    }
    expect(SIMPLIFIER_PARAM_KEYS).toEqual(shown.filter((s) => s.panel === "simplifier").map((s) => s.name));
    expect(FIELDS.some((field) => field.key === ("canvas_width_px" as string))).toBe(false);
  });

  it("has one detail parameter per simplifier, with a value for every level of the control", () => {
    for (const entry of Object.values(ALGORITHMS)) {
      const specs = DETAIL_SPECS.filter((spec) => spec.algorithms.includes(entry.name));
      expect(specs).toHaveLength(1);
      expect(specs[0]!.detail_levels).toHaveLength(DETAIL_LEVELS);
    }
  });

  it.each(Object.values(ALGORITHMS))("$name defaults are its table's, with its name", (entry) => {
    const { algorithm, ...rest } = entry.defaults;
    expect(algorithm).toBe(entry.name);
    expect(rest).toEqual(Object.fromEntries(entry.specs.map((spec) => [spec.name, spec.default])));
  });

  it("knows which parameters only one simplifier has", () => {
    expect(ONLY_FOR).toEqual({
      check_frames: "angle",
      max_angle_deg: "angle",
      frame_max: "angle",
      recover: "angle",
      fps: "angle",
      max_error: "window",
      max_window: "window",
      max_stroke_ms: "window",
      max_bend: "window",
      bend_floor: "window",
      rest_ms: "window",
      strict_minimums: "window",
      floor_ms: "window",
      least_squares: "window",
      lookahead_ms: "window",
    });
  });

  it("makes the simplifier the parameters name", () => {
    expect(makeSimplifier(ALGORITHMS.angle.defaults)).toBeInstanceOf(AngleSimplifier);
    expect(makeSimplifier(ALGORITHMS.window.defaults)).toBeInstanceOf(WindowSimplifier);
  });
});

describe("the page's sources", () => {
  it("import nothing from testdata (the bundle carries no test data)", () => {
    const root = fileURLToPath(new URL("../src", import.meta.url));
    const offenders = readdirSync(root, { recursive: true })
      .map(String)
      .filter((name) => name.endsWith(".ts"))
      .filter((name) => /from\s+["'][^"']*testdata\//.test(readFileSync(join(root, name), "utf8")));
    expect(offenders).toEqual([]);
  });
});
