/**
 * A rest lends a held piece briefer than the sleeve's floor the time it needs (`Merger.rest`): the
 * piece then lasts the floor, never a rounding below it. `start + floor - start` is 73.70099999999911
 * ms for a piece starting at 15000.1 ms (a page open for 15 s), which the sleeve slows to 73.701 and
 * reports `adjusted`: a stroke in the middle of a path the sleeve had to slow.
 */
import { describe, expect, it } from "vitest";
import type { Segment } from "../src/simplify/segment";
import { floorEndMs, Merger } from "../src/simplify/window";

/** The ERM sleeve's floor, as its status says it (Python `shortest_planned_ms`). */
const FLOOR_MS = 73.701;

describe("a piece lent the floor by a rest", () => {
  it.each([100.3, 2000.7, 15000.1, 612345.6])("lasts the floor to the last bit, from %s ms", (startMs) => {
    const merger = new Merger(0.25, 0.05, 0, FLOOR_MS);
    merger.sample(startMs, 0, 0);
    merger.sample(startMs + 30, 1, 0);
    const piece: Segment = {
      start: [0, 0],
      end: [1, 0],
      start_ms: startMs,
      end_ms: startMs + 30,
      duration_ms: 30,
      emitted_at_ms: startMs + 30,
      dropped: null,
    };
    const out: Segment[] = [];
    merger.take(piece, startMs + 30, out);
    expect(out).toEqual([]); // briefer than the floor: held
    merger.rest(startMs + 300, out);
    expect(out).toHaveLength(1);
    const sent = out[0]!;
    expect(sent.duration_ms).toBeGreaterThanOrEqual(FLOOR_MS);
    expect(sent.duration_ms).toBe(sent.end_ms - sent.start_ms);
    expect(sent.end_ms).toBe(floorEndMs(startMs, FLOOR_MS));
  });

  it("ends at the sum where it does not round down, one double above where it does", () => {
    expect(floorEndMs(1.2, FLOOR_MS)).toBe(1.2 + FLOOR_MS);
    const sum = 15000.1 + FLOOR_MS;
    expect(sum - 15000.1).toBeLessThan(FLOOR_MS);
    const end = floorEndMs(15000.1, FLOOR_MS);
    expect(end).toBeGreaterThan(sum);
    expect(end - 15000.1).toBeGreaterThanOrEqual(FLOOR_MS);
    // The least such double: the one below it is the sum, which falls short.
    expect(end - sum).toBeLessThan(1e-11);
  });
});
