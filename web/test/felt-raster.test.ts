/** The timeline's kept picture: painted bit by bit, it is the picture painted whole. */
import fc from "fast-check";
import { describe, expect, it } from "vitest";
import type { FeltStroke } from "../src/felt";
import { FeltPlacement } from "../src/felt-placement";
import { LaneRaster, PlacementRaster, STEP_MS, paintStroke } from "../src/ui/felt-raster";

const GRID = { rows: 3, columns: 4 };
const alpha = (stroke: { reported: boolean }, intensity: number) =>
  (stroke.reported ? 0.3 : 0.15) + 0.7 * intensity;

function cells(raster: LaneRaster): number[][] {
  return Array.from({ length: raster.lanes }, (_, lane) =>
    Array.from({ length: raster.capacity }, (_, bin) => raster.value(lane, bin)),
  );
}

describe("LaneRaster", () => {
  it("keeps the larger value of a bin", () => {
    const raster = new LaneRaster(2, 16);
    raster.paint(1, 0, 25, 0.5);
    raster.paint(1, 15, 18, 0.9);
    raster.paint(1, 10, 20, 0.2);
    // Stored as 32-bit floats.
    expect([0, 1, 2, 3].map((bin) => raster.value(1, bin))).toEqual([0.5, 0.9, 0.5, 0].map(Math.fround));
    expect(raster.value(0, 0)).toBe(0);
  });

  it("grown coarser, holds what painting at the coarser bins gives", () => {
    fc.assert(
      fc.property(
        fc.array(
          fc.record({
            lane: fc.integer({ min: 0, max: 2 }),
            from: fc.integer({ min: 0, max: 2000 }),
            length: fc.integer({ min: 1, max: 300 }),
            value: fc.double({ min: 0.01, max: 1, noNaN: true }),
          }),
          { minLength: 1, maxLength: 30 },
        ),
        (paints) => {
          // The last paint reaches 2,300 ms: too far for 32 bins of 10 ms.
          const all = [...paints, { lane: 1, from: 2290, length: 10, value: 0.5 }];
          const fine = new LaneRaster(3, 32, 10);
          for (const p of all) fine.paint(p.lane, p.from, p.from + p.length, p.value);
          const coarse = new LaneRaster(3, 32, fine.msPerBin);
          for (const p of all) coarse.paint(p.lane, p.from, p.from + p.length, p.value);
          expect(fine.msPerBin).toBeGreaterThanOrEqual(80); // 2300 ms in 32 bins
          expect(cells(fine)).toEqual(cells(coarse));
        },
      ),
    );
  });

  it("shows every painted bin at least one column wide, the larger value where bins share one", () => {
    const raster = new LaneRaster(1, 2048);
    raster.paint(0, 9_000, 9_010, 0.7);
    raster.paint(0, 9_010, 9_020, 0.4);
    const out = new Float32Array(100);
    raster.columns(0, 20_000, 100, out);
    expect([...out].filter((v) => v > 0).map((v) => v.toFixed(2))).toEqual(["0.70"]);
    expect(out[45]).toBeCloseTo(0.7);
    // Zoomed in: one bin over several columns.
    raster.columns(0, 100, 100, out);
    expect(out[0]).toBe(0);
  });

  it("cleared from a time, forgets every bin from the one holding it", () => {
    const raster = new LaneRaster(1, 64);
    raster.paint(0, 0, 100, 1);
    expect(raster.clearFrom(55)).toBe(50);
    expect([4, 5, 9].map((bin) => raster.value(0, bin))).toEqual([1, 0, 0]);
  });
});

const step = fc.oneof(
  fc.record({
    kind: fc.constant("append" as const),
    gap_ms: fc.integer({ min: 0, max: 3000 }),
    duration_ms: fc.integer({ min: 1, max: 800 }),
    x: fc.double({ min: 0, max: 3, noNaN: true }),
    y: fc.double({ min: 0, max: 2, noNaN: true }),
  }),
  fc.record({
    kind: fc.constant("report" as const),
    pick: fc.nat(),
    at_ms: fc.integer({ min: 0, max: 60_000 }),
  }),
  fc.record({ kind: fc.constant("cut" as const), pick: fc.nat(), cut_ms: fc.integer({ min: 0, max: 800 }) }),
  fc.record({ kind: fc.constant("cap" as const), pick: fc.nat() }),
  fc.record({ kind: fc.constant("refuse" as const), pick: fc.nat() }),
);

describe("PlacementRaster", () => {
  it("brought up to date after each change, is the picture of every stroke painted from scratch", () => {
    fc.assert(
      fc.property(fc.array(step, { maxLength: 40 }), (steps) => {
        const placement = new FeltPlacement();
        const kept = new PlacementRaster(alpha);
        const seqs: number[] = [];
        let arrives = 0;
        for (const s of steps) {
          if (s.kind === "append") {
            arrives += s.gap_ms;
            const stroke: FeltStroke = {
              seq: seqs.length,
              start: [s.x, s.y],
              end: [3 - s.x, 2 - s.y],
              duration_ms: s.duration_ms,
              intensity: 0.8,
              arrives_ms: arrives,
            };
            seqs.push(stroke.seq);
            placement.append(stroke);
          } else if (seqs.length > 0) {
            const seq = seqs[s.pick % seqs.length]!;
            if (s.kind === "report") placement.report(seq, s.at_ms);
            else if (s.kind === "cut") placement.cut(seq, s.cut_ms);
            else if (s.kind === "cap") placement.cap(seq);
            else placement.refuse(seq);
          }
          kept.sync(placement, GRID);
          const whole = new LaneRaster(GRID.rows * GRID.columns, kept.raster.capacity, kept.raster.msPerBin);
          for (const stroke of placement.placed) paintStroke(whole, GRID, stroke, alpha);
          expect(whole.msPerBin).toBe(kept.raster.msPerBin);
          expect(cells(kept.raster)).toEqual(cells(whole));
        }
      }),
      { numRuns: 40 },
    );
  });

  it("paints a stroke every STEP_MS along it on the actuators around the brush", () => {
    const raster = new LaneRaster(GRID.rows * GRID.columns);
    const stroke = {
      seq: 0,
      start: [0, 0] as [number, number],
      end: [3, 0] as [number, number],
      duration_ms: 30 * STEP_MS,
      intensity: 1,
      arrives_ms: 0,
      start_ms: 0,
      reported: false,
      played_ms: 30 * STEP_MS,
      capped: false,
    };
    paintStroke(raster, GRID, stroke, alpha);
    // Along row 0 from column 0 to 3: lane 0 first, lane 3 last, row 1 never.
    expect(raster.value(0, 0)).toBeCloseTo(0.85);
    expect(raster.value(3, 29)).toBeGreaterThan(0.5);
    expect(raster.value(0, 29)).toBe(0);
    expect(raster.value(4, 5)).toBe(0);
  });
});
