/**
 * The simplifiers' parameter tables in the page equal the reference's
 * (testdata/<algorithm>/params.json, written by the Python reference), and the
 * registry derives which parameters belong to one simplifier only.
 */
import { readdirSync, readFileSync } from "node:fs";
import { join } from "node:path";
import { fileURLToPath } from "node:url";
import { describe, expect, it } from "vitest";
import { ALGORITHMS, ONLY_FOR, makeSimplifier } from "../src/simplify/registry";
import { AngleSimplifier } from "../src/simplify/angle";
import { WindowSimplifier } from "../src/simplify/window";
import { vectors } from "./testdata";

function table(algorithm: string): unknown[] {
  const found = vectors(algorithm).find(([name]) => name.endsWith("params.json"));
  if (found === undefined) throw new Error(`testdata/${algorithm}/params.json is missing`);
  return (found[1] as { parameters: unknown[] }).parameters;
}

describe("parameter tables", () => {
  it.each(Object.values(ALGORITHMS))("$name equals the reference's table", (entry) => {
    expect(entry.specs).toEqual(table(entry.name));
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
