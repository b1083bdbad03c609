/**
 * The window simplifier's parameters that one of its cores reads and the other ignores (the
 * table's `only_when`): what the page's cores do agrees with the table, and the settings
 * panel's rows carry the condition and the note it shows while the switch is the other way.
 */
import { describe, expect, it } from "vitest";
import { DEFAULT_SETTINGS, FIELDS, conditionMet, conditionNote, fieldSpec } from "../src/settings";
import { PARAMETERS } from "../src/simplify/params";
import { simplifyPaths } from "../src/simplify/registry";
import type { Sample } from "../src/simplify/segment";
import { DEFAULT_WINDOW_PARAMS, type WindowParams } from "../src/simplify/window-params";
import { vectors } from "./testdata";

const CONDITIONAL = PARAMETERS.filter((spec) => spec.only_when !== null);
/** Values across each one's range, to try under either core. */
const VALUES: Record<string, number[]> = {
  lookahead_ms: [0, 80, 1000],
  max_bend: [0.05, 0.3, 1],
  bend_floor: [0, 0.5, 5],
};

function paths(): Sample[][] {
  const wanted = ["circle/defaults", "zigzag/defaults", "two-paths/defaults", "slow/defaults"];
  return vectors("window")
    .filter(([name]) => wanted.some((w) => name.endsWith(`${w}.json`)))
    .flatMap(([, vector]) =>
      (vector as { paths: [number, number, number, number][][] }).paths.map((path) =>
        path.map(([t_ms, x, y, pressure]) => ({ t_ms, x, y, pressure })),
      ),
    );
}

describe("parameters of one window core", () => {
  it("are the bend rule's (the chord core) and the lookahead (the least-squares core)", () => {
    expect(Object.fromEntries(CONDITIONAL.map((spec) => [spec.name, spec.only_when]))).toEqual({
      max_bend: { name: "least_squares", value: false },
      bend_floor: { name: "least_squares", value: false },
      lookahead_ms: { name: "least_squares", value: true },
    });
  });

  const drawn = paths();
  it.each(CONDITIONAL.map((spec) => [spec.name, spec] as const))(
    "%s changes no stroke under the other core, and some under its own",
    (name, spec) => {
      expect(drawn.length).toBeGreaterThan(3);
      const { name: key, value: needed } = spec.only_when!;
      // The bend floor acts only while the bend rule is on.
      const base = name === "bend_floor" ? { max_bend: 0.1 } : {};
      const strokes = (value: number, on: boolean): unknown[] => {
        const params = { ...DEFAULT_WINDOW_PARAMS, ...base, [key]: on, [name]: value } as WindowParams;
        return simplifyPaths(params, drawn).map(({ path, segment }) => ({ path, ...segment }));
      };
      const ignored = strokes(spec.default as number, !needed);
      const read = strokes(spec.default as number, needed);
      const values = VALUES[name]!;
      for (const value of values) expect(strokes(value, !needed), `${name} = ${value}`).toEqual(ignored);
      expect(values.some((value) => JSON.stringify(strokes(value, needed)) !== JSON.stringify(read))).toBe(
        true,
      );
    },
  );
});

describe("the settings panel's rows of one core", () => {
  it("carry the table's condition, and only those rows", () => {
    const conditional = FIELDS.filter((field) => field.onlyWhen !== undefined);
    expect(conditional.map((field) => [field.key, field.onlyWhen])).toEqual(
      CONDITIONAL.map((spec) => [spec.name, { key: spec.only_when!.name, value: spec.only_when!.value }]),
    );
  });

  it("apply while their switch chooses their core", () => {
    const lookahead = fieldSpec("lookahead_ms");
    const bend = fieldSpec("max_bend");
    expect(DEFAULT_SETTINGS.least_squares).toBe(true);
    expect(conditionMet(lookahead, DEFAULT_SETTINGS)).toBe(true);
    expect(conditionMet(bend, DEFAULT_SETTINGS)).toBe(false);
    const chord = { ...DEFAULT_SETTINGS, least_squares: false };
    expect(conditionMet(lookahead, chord)).toBe(false);
    expect(conditionMet(bend, chord)).toBe(true);
    expect(conditionMet(fieldSpec("max_error"), chord)).toBe(true);
  });

  it("say which core reads them, in a few words", () => {
    expect(conditionNote(fieldSpec("lookahead_ms"))).toBe("Lookahead: least squares only");
    expect(conditionNote(fieldSpec("max_bend"))).toBe("Max bend: only with least squares off");
    expect(conditionNote(fieldSpec("bend_floor"))).toBe("Bend floor: only with least squares off");
    expect(conditionNote(fieldSpec("max_error"))).toBeNull();
  });
});
