/** The control message, read and written as the Python reference does (testdata/control). */
import { describe, expect, it } from "vitest";
import { formatControl, parseControl } from "../src/control";
import { hasVectors, vectors } from "./testdata";

interface Vector {
  payload: string;
  cancel: string;
  reason: string;
  field: string | null;
  text: string;
}

const present = hasVectors("control");
const group = (sub: string) => (present ? (vectors("control", sub) as [string, Vector][]) : []);
const valid = group("valid");
const invalid = group("invalid");
const format = group("format");

describe.skipIf(!present)("control vectors", () => {
  it("finds every group", () => {
    expect([valid.length, invalid.length, format.length].every((n) => n > 0)).toBe(true);
  });

  it.each(valid)("%s", (_name, vector) => {
    expect(parseControl(vector.payload)).toEqual({ cancel: vector.cancel });
  });

  it.each(invalid)("%s", (_name, vector) => {
    expect(parseControl(vector.payload)).toEqual({ reason: vector.reason, field: vector.field });
  });

  it.each(format)("%s", (_name, vector) => {
    expect(formatControl(vector.cancel)).toBe(vector.text);
  });
});

it("refuses to format a drawing id the sleeve would refuse", () => {
  expect(() => formatControl("a b")).toThrow(/Not a drawing id/);
});
