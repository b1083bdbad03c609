/**
 * Random drawings for the window simplifier's tests against simplifiers as first written
 * (`window.reference.test.ts`, `window.merger.test.ts`): made to put samples near max_error of
 * their strokes: steps scaled to max_error so that strokes both skip and make the full test, paths
 * on a coarse pixel grid so that distances tie exactly, times that stand still or run backwards,
 * samples off the canvas or NaN, several paths through one simplifier. `bits`: every number of
 * the segments exactly.
 */
import fc from "fast-check";
import { CanvasMapping } from "../src/simplify/mapping";
import type { Sample, Segment } from "../src/simplify/segment";
import type { WindowParams } from "../src/simplify/window-params";

const WIDTH_PX = 800;
const HEIGHT_PX = 600;
/** Every number exactly: -0 apart from 0, NaN equal to NaN (shortest round-trip decimal). */
export function bits(segments: readonly Segment[]): string[][] {
  const exact = (v: number) => (Object.is(v, -0) ? "-0" : String(v));
  return segments.map((s) => [
    ...[...s.start, ...s.end, s.start_ms, s.end_ms, s.duration_ms, s.emitted_at_ms].map(exact),
    String(s.dropped),
  ]);
}

const paramsArb: fc.Arbitrary<WindowParams> = fc.record({
  algorithm: fc.constant("window" as const),
  max_error: fc.constantFrom(0.001, 0.02, 0.25, 1),
  max_window: fc.constantFrom(1, 2, 7, 256, 1000),
  max_stroke_ms: fc.constantFrom(0, 50, 300),
  clear_on_press: fc.constant(true),
  min_duration_ms: fc.constantFrom(0, 6.1, 80),
  min_length: fc.constantFrom(0, 0.1, 0.4),
  max_bend: fc.constantFrom(0, 0.05, 0.1, 0.3),
  bend_floor: fc.constantFrom(0, 0.01, 0.05, 0.5),
  floor_ms: fc.constant(73.7),
  rest_ms: fc.constantFrom(0, 30, 100),
  strict_minimums: fc.boolean(),
  // The window's own core (the least-squares one is tested in fit.properties.test.ts).
  least_squares: fc.constant(false),
  lookahead_ms: fc.constant(30),
  rows: fc.integer({ min: 1, max: 8 }),
  columns: fc.integer({ min: 1, max: 8 }),
  canvas_width_px: fc.constant(WIDTH_PX),
  canvas_height_px: fc.constant(HEIGHT_PX),
  stretch: fc.boolean(),
});

const stepArb = fc.record({
  turn: fc.option(fc.double({ min: -Math.PI, max: Math.PI, noNaN: true }), { freq: 15 }),
  // Sideways noise in steps (or, on a pixel grid, whole grid steps); rarely NaN.
  dx: fc.oneof(
    { weight: 199, arbitrary: fc.double({ min: -1, max: 1, noNaN: true }) },
    { weight: 1, arbitrary: fc.constant(Number.NaN) },
  ),
  dy: fc.double({ min: -1, max: 1, noNaN: true }),
  dtMs: fc.constantFrom(0, -3, 8, 16.7, 40),
});

const pathArb = fc.record({
  x0: fc.double({ min: -50, max: 850, noNaN: true }),
  y0: fc.double({ min: -50, max: 650, noNaN: true }),
  t0: fc.double({ min: 0, max: 100, noNaN: true }),
  heading: fc.double({ min: -Math.PI, max: Math.PI, noNaN: true }),
  steps: fc.array(stepArb, { maxLength: 120 }),
});

export const drawingArb = fc.record({
  params: paramsArb,
  stepShare: fc.constantFrom(0.1, 0.5, 1, 3),
  // Sideways noise against max_error: none (lines the latency cap cuts, straight on), a line's
  // (within LINE_SHARE), or a scribble's.
  noiseShare: fc.constantFrom(0, 0.05, 0.3, 1),
  grid: fc.constantFrom("none", "none", "pixel", "step"),
  paths: fc.array(pathArb, { minLength: 1, maxLength: 3 }),
});

export type Drawing = typeof drawingArb extends fc.Arbitrary<infer T> ? T : never;

/** The drawing's paths in canvas pixels: mostly straight on, with sideways noise, and corners. */
export function pathsOf({ params, stepShare, noiseShare, grid, paths }: Drawing): Sample[][] {
  const mapping = new CanvasMapping({
    width_px: params.canvas_width_px,
    height_px: params.canvas_height_px,
    columns: params.columns,
    rows: params.rows,
    stretch: params.stretch,
  });
  const stepPx = (stepShare * params.max_error) / (mapping.scale || 1);
  const noisePx = (noiseShare * params.max_error) / (mapping.scale || 1);
  const gridPx = grid === "pixel" ? 1 : grid === "step" ? stepPx : null;
  return paths.map(({ x0, y0, t0, heading: heading0, steps }) => {
    let [x, y, tMs, heading] = [x0, y0, t0, heading0];
    const path: Sample[] = [{ t_ms: tMs, x, y, pressure: 0.5 }];
    for (const { turn, dx, dy, dtMs } of steps) {
      if (turn !== null) heading = turn;
      const along = gridPx === null ? stepPx : 0;
      const sideX = gridPx === null ? dx * noisePx : Math.round(dx * 3) * gridPx;
      const sideY = gridPx === null ? dy * noisePx : Math.round(dy * 3) * gridPx;
      const nextX = x + along * Math.cos(heading) + sideX;
      const nextY = y + along * Math.sin(heading) + sideY;
      if (Number.isNaN(nextX)) {
        path.push({ t_ms: tMs, x: nextX, y: nextY, pressure: 0.5 });
        continue;
      }
      [x, y, tMs] = [nextX, nextY, tMs + dtMs];
      path.push({ t_ms: tMs, x, y, pressure: 0.5 });
    }
    return path;
  });
}
