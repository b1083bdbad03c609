/** The sleeve's floor raises the simplifier's minimums, never lowers them. */
import { describe, expect, it } from "vitest";
import { floorNote, withFloor } from "../src/sleeve-floor";

const user = { min_duration_ms: 6.1, min_length: 0.1, other: "kept" };
const floor = { min_duration_ms: 73.701, min_length: 0.05, wearer: null };

describe("withFloor", () => {
  it("raises a minimum below the floor and keeps one above it", () => {
    expect(withFloor(user, floor)).toEqual({ min_duration_ms: 73.701, min_length: 0.1, other: "kept" });
  });

  it("never lowers a user's higher setting", () => {
    const high = { min_duration_ms: 200, min_length: 1.5 };
    expect(withFloor(high, { ...floor, min_length: 0.62, wearer: "P01" })).toBe(high);
  });

  it("leaves the settings alone without a floor (an older sleeve)", () => {
    expect(withFloor(user, undefined)).toBe(user);
    expect(withFloor(user, null)).toBe(user);
  });
});

describe("floorNote", () => {
  it("says the floor and what it raised", () => {
    const note = floorNote(user, { min_duration_ms: 118.4, min_length: 0.62, wearer: "P01" });
    expect(note).toBe(
      "At least 118.4 ms and 0.62 grid units per stroke: the sleeve's floor with wearer P01's limits; " +
        "min duration and min length raised to it.",
    );
    expect(floorNote(user, floor)).toBe(
      "At least 73.7 ms and 0.05 grid units per stroke: the sleeve's floor; min duration raised to it.",
    );
    expect(floorNote({ min_duration_ms: 100, min_length: 1 }, floor)).toContain("your settings are above it");
  });

  it("says nothing without a floor", () => {
    expect(floorNote(user, undefined)).toBeNull();
  });
});
