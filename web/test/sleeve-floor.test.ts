/** The sleeve's floor raises the simplifier's minimums, never lowers them. */
import { describe, expect, it } from "vitest";
import { floorNote, withFloor } from "../src/sleeve-floor";

const user = { min_duration_ms: 6.1, min_length: 0.1, other: "kept" };
const floor = { min_duration_ms: 73.701, min_length: 0.05, wearer: null };

describe("withFloor", () => {
  it("raises a minimum below a wearer's floor and keeps one above it", () => {
    expect(withFloor(user, { ...floor, wearer: "P01" })).toEqual({
      min_duration_ms: 73.701,
      min_length: 0.1,
      other: "kept",
    });
  });

  it("keeps the settings under the motors' floor alone (the sleeve slows and catches up)", () => {
    expect(withFloor(user, floor)).toBe(user);
  });

  it("never lowers a user's higher setting", () => {
    const high = { min_duration_ms: 200, min_length: 1.5 };
    expect(withFloor(high, { ...floor, min_length: 0.62, wearer: "P01" })).toBe(high);
  });

  it("gives the window simplifier the sleeve's floor to merge up to, strict only with a wearer", () => {
    const window = { ...user, floor_ms: 73.7, strict_minimums: false };
    expect(withFloor(window, { ...floor, min_duration_ms: 90 })).toEqual({ ...window, floor_ms: 90 });
    expect(withFloor(window, { ...floor, min_duration_ms: 118.4, min_length: 0.62, wearer: "P01" })).toEqual({
      ...window,
      floor_ms: 118.4,
      strict_minimums: true,
      min_duration_ms: 118.4,
      min_length: 0.62,
    });
    const same = { ...user, floor_ms: 73.701, strict_minimums: false };
    expect(withFloor(same, floor)).toBe(same);
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
      "The sleeve plays strokes briefer than 73.7 ms slowed to that, and catches up after them; " +
        "a wearer file (feelmysign sleeve --wearer) sets limits the page keeps to.",
    );
    expect(floorNote({ min_duration_ms: 100, min_length: 1 }, { ...floor, wearer: "P01" })).toContain(
      "your settings are above it",
    );
  });

  it("says nothing without a floor", () => {
    expect(floorNote(user, undefined)).toBeNull();
  });
});
