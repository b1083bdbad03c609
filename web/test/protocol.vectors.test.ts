/** formatJson / formatLegacy against every vector of testdata/protocol/format: the exact bytes. */
import { describe, expect, it } from "vitest";
import { formatJson, formatLegacy, strokeProblem, type Stroke } from "../src/protocol";
import { hasVectors, vectors } from "./testdata";

interface FormatVector {
  description: string;
  stroke: Stroke;
  legacy: string;
  json: string;
}

const present = hasVectors("protocol", "format");
const cases = present ? (vectors("protocol", "format") as [string, FormatVector][]) : [];

describe.skipIf(!present)("protocol format vectors", () => {
  it("finds the vectors", () => {
    expect(cases.length).toBeGreaterThan(0);
  });

  it.each(cases)("%s", (_name, vector) => {
    expect(formatJson(vector.stroke)).toBe(vector.json);
    expect(formatLegacy(vector.stroke)).toBe(vector.legacy);
  });
});

describe("invalid strokes are refused before they reach the wire", () => {
  const base: Stroke = { start: [0, 0], end: [1, 1], duration_ms: 100 };
  it.each<[string, Partial<Stroke>, string]>([
    ["zero duration", { duration_ms: 0 }, "duration_not_positive"],
    ["NaN point", { start: [Number.NaN, 0] }, "not_finite"],
    ["intensity above 1", { intensity: 1.5 }, "intensity_out_of_range"],
    ["negative seq", { seq: -1 }, "seq_out_of_range"],
    ["spaces in drawing id", { drawing: "a b" }, "bad_drawing_id"],
    ["negative sent_at_ms", { sent_at_ms: -5 }, "sent_at_out_of_range"],
    ["sent_at_ms beyond 2286", { sent_at_ms: 1e300 }, "sent_at_out_of_range"],
  ])("%s", (_what, change, reason) => {
    const stroke = { ...base, ...change };
    expect(strokeProblem(stroke)?.reason).toBe(reason);
    expect(() => formatJson(stroke)).toThrow();
    expect(() => formatLegacy(stroke)).toThrow();
  });
});
