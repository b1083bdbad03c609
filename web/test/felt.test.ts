/** The felt view: strokes placed by the sleeve's playback rule, the brush funneled on the grid. */
import fc from "fast-check";
import { describe, expect, it } from "vitest";
import {
  brushAt,
  funnel,
  NEGLIGIBLE_WEIGHT,
  placeStrokes,
  playingAt,
  totalMs,
  type FeltStroke,
} from "../src/felt";
import { SLEEVE_FLOOR_MS } from "../src/sleeve-queue";

const GRID = { rows: 3, columns: 4 };

function stroke(seq: number, arrives_ms: number, duration_ms = 100): FeltStroke {
  return { seq, start: [0, 0], end: [2, 0], duration_ms, intensity: 0.8, arrives_ms };
}

describe("placeStrokes", () => {
  it("starts a stroke on arrival, or when the one before ends", () => {
    const placed = placeStrokes([stroke(0, 0), stroke(1, 50), stroke(2, 500)]);
    expect(placed.map((s) => s.start_ms)).toEqual([0, 100, 500]);
    expect(totalMs(placed)).toBe(600);
  });

  it("feels nothing of a stroke the duty-cycle cap kept from playing, and keeps its turn", () => {
    const placed = placeStrokes(
      [stroke(0, 0), stroke(1, 0), stroke(2, 0)],
      new Map(),
      new Map(),
      new Set([1]),
    );
    // The two that wait catch up to the sleeve's floor; the capped one's turn is its caught-up one.
    const F = SLEEVE_FLOOR_MS;
    expect(placed.map((s) => [s.start_ms, s.played_ms, s.capped])).toEqual([
      [0, 100, false],
      [100, 0, true],
      [100 + F, F, false],
    ]);
    expect(playingAt(placed, 150)).toBeNull();
  });

  it("takes the sleeve's reported start over its own estimate, and the cut length", () => {
    const placed = placeStrokes([stroke(0, 0), stroke(1, 0)], new Map([[0, 30]]), new Map([[0, 40]]));
    // The second waits 70 ms behind the first, so it catches up: down to the sleeve's floor.
    expect(placed.map((s) => [s.start_ms, s.played_ms, s.reported])).toEqual([
      [30, 40, true],
      [70, SLEEVE_FLOOR_MS, false],
    ]);
  });

  it("plays a stroke that waits faster by its wait, down to the floor, never slower", () => {
    const placed = placeStrokes([
      stroke(0, 0, 300),
      stroke(1, 100, 300),
      stroke(2, 120, 50),
      stroke(3, 900, 300),
    ]);
    expect(placed.map((s) => [s.start_ms, s.duration_ms])).toEqual([
      [0, 300],
      [300, 100], // 200 ms behind
      [400, 50], // below the floor: as it came
      [900, 300], // not behind
    ]);
    // The brush crosses a stroke that caught up in its shorter time.
    expect(brushAt(placed[1]!, 50)).toEqual([1, 0]);
    expect(placeStrokes([stroke(0, 0, 300), stroke(1, 10, 300)])[1]!.duration_ms).toBe(SLEEVE_FLOOR_MS);
  });
});

describe("the brush", () => {
  it("moves from start to end over the duration", () => {
    expect(brushAt(stroke(0, 0, 200), 100)).toEqual([1, 0]);
    expect(brushAt(stroke(0, 0, 200), 999)).toEqual([2, 0]);
    const placed = placeStrokes([stroke(0, 0, 200)]);
    expect(playingAt(placed, 50)?.into_ms).toBe(50);
    expect(playingAt(placed, 250)).toBeNull();
  });

  it("on an actuator, drives that one alone", () => {
    expect(funnel([2, 1], 0.5, GRID)).toEqual([{ row: 1, column: 2, intensity: 0.5 }]);
  });

  it("between actuators, shares the energy: the squares add up to the intensity squared", () => {
    fc.assert(
      fc.property(
        fc.double({ min: 0, max: 3, noNaN: true }),
        fc.double({ min: 0, max: 2, noNaN: true }),
        fc.double({ min: 0.01, max: 1, noNaN: true }),
        (x, y, intensity) => {
          const drives = funnel([x, y], intensity, GRID);
          const energy = drives.reduce((sum, d) => sum + d.intensity ** 2, 0);
          // Relative: up to three shares of NEGLIGIBLE_WEIGHT each are left out, and the
          // rounding of the products is relative to the intensity squared too.
          const tolerance = intensity ** 2 * (3 * NEGLIGIBLE_WEIGHT + 1e-12);
          expect(Math.abs(energy - intensity ** 2)).toBeLessThanOrEqual(tolerance);
          for (const d of drives) {
            expect(Math.abs(d.column - x)).toBeLessThanOrEqual(1);
            expect(Math.abs(d.row - y)).toBeLessThanOrEqual(1);
          }
        },
      ),
    );
  });
});
