/**
 * Invariants of the TypeScript window simplifier on random paths and
 * parameters (fast-check): every drawn sample lies within max_error of the
 * stroke that covers it, no stroke covers more than max_window samples after
 * its start nor lasts longer than max_stroke_ms (unless it is a single step or
 * was too short to send until its last sample),
 * strokes join end to start from the press to the release (a rest or a crawl
 * between them is not played: the next starts later, never earlier), no piece is
 * dropped but a path that is one piece too short in all (every drawn sample
 * lies within max_error of a sent stroke, at any setting), and a drawing along the
 * canvas edges gives strokes that start and end on the grid.
 */
import fc from "fast-check";
import { describe, expect, it } from "vitest";
import { CanvasMapping } from "../src/simplify/mapping";
import { SHARED_PARAM_ARBS, expectDropRule, pointerPathArb } from "./simplifier-arbitraries";
import { type Point, type Sample, type Segment } from "../src/simplify/segment";
import {
  LINE_SHARE,
  WindowCore,
  WindowSimplifier,
  restRadius as windowRestRadius,
  takenSamples,
} from "../src/simplify/window";
import { DEFAULT_WINDOW_PARAMS, type WindowParams } from "../src/simplify/window-params";

/** Room for a distance computed another way than the simplifier's (last bits only). */
const FLOAT_TOLERANCE = 1e-12;
/** Hundreds of random paths: generous, for a loaded machine (the work is bounded, not timed). */
const PROPERTY_TIMEOUT_MS = 120_000;

// Every sample its own time, so each stroke's samples are known from its times.
const pathArb = pointerPathArb({ minStepMs: 0.01, randomPressure: false });

const paramsArb: fc.Arbitrary<WindowParams> = fc.record({
  algorithm: fc.constant("window" as const),
  max_error: fc.oneof(
    fc.constantFrom(0.001, 0.02, 0.05, 0.2),
    fc.double({ min: 0.001, max: 2, noNaN: true }),
  ),
  max_window: fc.oneof(fc.constantFrom(1, 2, 64), fc.integer({ min: 1, max: 300 })),
  max_stroke_ms: fc.constantFrom(0, 50, 300),
  max_bend: fc.constantFrom(0, 0.1, 0.3),
  bend_floor: fc.constantFrom(0, 0.05),
  floor_ms: fc.constantFrom(0, 73.7, 200),
  rest_ms: fc.constantFrom(0, 30, 100, 300),
  // Strict minimums let the bound yield to a wearer's limits: not this property's.
  strict_minimums: fc.constant(false),
  // The window's own core (the least-squares one: fit.properties.test.ts).
  least_squares: fc.constant(false),
  lookahead_ms: fc.constant(30),
  ...SHARED_PARAM_ARBS,
});

/** Distance from a point to the segment start -> end (not its line). */
function distance(point: Point, start: Point, end: Point): number {
  const dx = end[0] - start[0];
  const dy = end[1] - start[1];
  const qx = point[0] - start[0];
  const qy = point[1] - start[1];
  const lengthSq = dx * dx + dy * dy;
  const t = lengthSq === 0 ? 0 : Math.min(Math.max((qx * dx + qy * dy) / lengthSq, 0), 1);
  return Math.hypot(qx - t * dx, qy - t * dy);
}

/** How far a sample the pen rested at may lie from the point that stands for the rest. */
function restRadius(params: WindowParams): number {
  return params.rest_ms > 0 ? windowRestRadius(params, CanvasMapping.fromParams(params)) : 0;
}

/**
 * Each segment with the first and last sample it covers: segments join, so
 * each starts where the one before ended, and ends on the first sample from there
 * drawn at or after its end time, at its point or within LINE_SHARE x max_error of it
 * (or, where the pen rested, the rest radius). Samples after the last segment
 * are a rest at its end, or the last piece, merged into it at release (within max_error).
 */
function covered(params: WindowParams, samples: readonly Sample[], pieces = false) {
  // `pieces`: the window's own pieces, before any is merged (the caps bound those).
  const simplifier = pieces ? new WindowCore(params) : new WindowSimplifier(params);
  const segments: Segment[] = samples.flatMap((sample) => simplifier.push(sample));
  segments.push(...simplifier.end());
  // The path's last piece merged at release into the last segment (nothing more was sent).
  const mergedBack = simplifier instanceof WindowSimplifier ? simplifier.mergedBack : 0;
  const map = CanvasMapping.fromParams(params);
  // An end is its sample, or within LINE_SHARE x max_error of it going on along a line the
  // latency cap cut.
  const moved = Math.max(LINE_SHARE * params.max_error, restRadius(params)) + FLOAT_TOLERANCE;
  const spans: { first: number; last: number; segment: Segment }[] = [];
  let start = 0;
  for (const segment of segments) {
    let last = -1;
    for (let j = start; j < samples.length && last < 0; j++) {
      const [x, y] = map.toGrid(samples[j]!.x, samples[j]!.y);
      const isEnd =
        samples[j]!.t_ms >= segment.end_ms && Math.hypot(x - segment.end[0], y - segment.end[1]) <= moved;
      if (isEnd && (j > start || samples.length === 1)) last = j;
    }
    expect(last, "a segment ends on a sample").toBeGreaterThanOrEqual(start);
    spans.push({ first: start, last, segment });
    start = last;
  }
  const lastSegment = segments[segments.length - 1]!;
  for (let j = start + 1; j < samples.length; j++) {
    const point = map.toGrid(samples[j]!.x, samples[j]!.y);
    expect(distance(point, lastSegment.start, lastSegment.end), "a rest at the end").toBeLessThanOrEqual(
      (mergedBack > 0 ? params.max_error : Math.min(2 * restRadius(params), params.max_error)) +
        FLOAT_TOLERANCE,
    );
  }
  return { spans, segments, map, mergedBack };
}

describe("window simplifier invariants", () => {
  it(
    "every drawn sample lies within max_error of its piece; the pieces keep the caps",
    () => {
      fc.assert(
        fc.property(paramsArb, pathArb, (params, samples) => {
          const { spans, map } = covered(params, samples, true);
          for (const { first, last, segment } of spans) {
            // The work cap counts the samples the stroke holds: not those of a rest before it.
            let held = 0;
            for (let j = first + 1; j <= last; j++) if (samples[j]!.t_ms > segment.start_ms) held++;
            expect(held).toBeLessThanOrEqual(params.max_window);
            if (params.max_stroke_ms > 0 && segment.end_ms - segment.start_ms > params.max_stroke_ms) {
              // Only a single step, or a stroke still too short to send a sample earlier.
              const [bx, by] = map.toGrid(samples[last - 1]!.x, samples[last - 1]!.y);
              const short = Math.hypot(bx - segment.start[0], by - segment.start[1]) < params.min_length;
              expect(last - first === 1 || short).toBe(true);
            }
            for (let j = first; j <= last; j++) {
              const point = map.toGrid(samples[j]!.x, samples[j]!.y);
              expect(distance(point, segment.start, segment.end)).toBeLessThanOrEqual(
                params.max_error + FLOAT_TOLERANCE,
              );
            }
          }
        }),
        { numRuns: 400 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );

  it(
    "strokes join end to start from the press to the release",
    () => {
      fc.assert(
        fc.property(paramsArb, pathArb, (params, drawn) => {
          const samples = takenSamples(drawn, params.rest_ms);
          const { segments, map, mergedBack } = covered(params, samples);
          const first = samples[0]!;
          const last = samples[samples.length - 1]!;
          expect(segments[0]!.start).toEqual(map.toGrid(first.x, first.y));
          const release = map.toGrid(last.x, last.y);
          const lastSegment = segments[segments.length - 1]!;
          if (mergedBack > 0) {
            // The last piece merged at release: the release lies within max_error of the stroke.
            expect(distance(release, lastSegment.start, lastSegment.end)).toBeLessThanOrEqual(
              params.max_error + FLOAT_TOLERANCE,
            );
          } else {
            const end = lastSegment.end;
            expect(Math.hypot(end[0] - release[0], end[1] - release[1])).toBeLessThanOrEqual(
              Math.max(LINE_SHARE * params.max_error, restRadius(params)) + FLOAT_TOLERANCE,
            );
          }
          for (let i = 1; i < segments.length; i++) {
            expect(segments[i]!.start).toEqual(segments[i - 1]!.end);
            expect(segments[i]!.start_ms).toBeGreaterThanOrEqual(segments[i - 1]!.end_ms);
          }
          // No stroke the sleeve must slow: one drawn briefer than the floor lasts the floor,
          // any other as long as it was drawn.
          const floorMs = Math.max(params.min_duration_ms, params.floor_ms);
          for (const segment of segments) {
            if (segment.dropped !== null) continue;
            const drawnMs = segment.end_ms - segment.start_ms;
            expect(segment.duration_ms).toBe(drawnMs < floorMs ? floorMs : drawnMs);
          }
        }),
        { numRuns: 200 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );

  it(
    "no piece is dropped: every drawn sample lies within max_error of a sent stroke",
    () => {
      // Whatever the caps and minimums: a piece too short to send merges into the next, or is
      // sent; only a path that is one short piece in all (a tap) is dropped, with its reason.
      const errorArb = fc.constantFrom(0.001, 0.05, 0.1, 0.15, 0.25, 1);
      fc.assert(
        fc.property(paramsArb, errorArb, pathArb, (drawn, maxError, path) => {
          const params = { ...drawn, max_error: maxError };
          const samples = takenSamples(path, params.rest_ms);
          const { segments, map } = covered(params, samples);
          if (segments.some((segment) => segment.dropped !== null)) {
            expect(segments.length).toBe(1);
            expectDropRule(segments[0]!, params);
            return;
          }
          for (const sample of samples) {
            const point = map.toGrid(sample.x, sample.y);
            const nearest = Math.min(...segments.map((s) => distance(point, s.start, s.end)));
            expect(nearest).toBeLessThanOrEqual(params.max_error + FLOAT_TOLERANCE);
          }
          for (const segment of segments) {
            expect(segment.emitted_at_ms).toBeGreaterThanOrEqual(segment.end_ms);
          }
        }),
        { numRuns: 300 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );

  it(
    "a last piece merges at release where the stroke before covers it, or else could not",
    () => {
      // Merged at release: nothing dropped then, the last sent stroke ends by the release and
      // every sample drawn from its end on lies within max_error of it. Not merged, a last sent
      // stroke briefer than the floor has a stroke before it that leaves a sample drawn from its
      // end on farther than max_error (without rests, which send a held piece before the release;
      // with strict minimums, one still below them merges back or is dropped there).
      const errorArb = fc.constantFrom(0.05, 0.1, 0.15, 0.25);
      fc.assert(
        fc.property(paramsArb, errorArb, fc.boolean(), pathArb, (drawn, maxError, strict, path) => {
          const params = { ...drawn, max_error: maxError, strict_minimums: strict };
          const samples = takenSamples(path, params.rest_ms);
          const simplifier = new WindowSimplifier(params);
          const segments: Segment[] = samples.flatMap((sample) => simplifier.push(sample));
          const atRests = simplifier.mergedBack;
          const released = simplifier.end();
          segments.push(...released);
          const sent = segments.filter((segment) => segment.dropped === null);
          const map = CanvasMapping.fromParams(params);
          const farthestFrom = (stroke: Segment): number => {
            let farthest = 0;
            for (const sample of samples) {
              if (sample.t_ms < stroke.end_ms) continue;
              const point = map.toGrid(sample.x, sample.y);
              farthest = Math.max(farthest, distance(point, stroke.start, stroke.end));
            }
            return farthest;
          };
          if (simplifier.mergedBack > atRests) {
            expect(sent.length).toBeGreaterThan(0);
            expect(released.every((segment) => segment.dropped === null)).toBe(true);
            expect(sent[sent.length - 1]!.end_ms).toBeLessThanOrEqual(samples[samples.length - 1]!.t_ms);
            expect(farthestFrom(sent[sent.length - 1]!)).toBeLessThanOrEqual(
              params.max_error + FLOAT_TOLERANCE,
            );
            return;
          }
          const brief = Math.max(params.min_duration_ms, params.floor_ms);
          const lastSent = sent[sent.length - 1];
          if (params.rest_ms === 0 && sent.length >= 2 && lastSent!.end_ms - lastSent!.start_ms < brief) {
            expect(farthestFrom(sent[sent.length - 2]!)).toBeGreaterThan(params.max_error - FLOAT_TOLERANCE);
          }
        }),
        { numRuns: 300 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );
});

/**
 * A line drawn along the canvas edges, on them and beyond, that the latency cap cuts. The canvas
 * has the grid's aspect ratio (or is stretched onto it), so its edges map onto the grid's and a
 * sample beyond one maps onto it. The line runs along one edge, or turns its corners onto the
 * next ones (a "U"); it may start inside and drift across the edge at a shallow angle, wobble
 * about it or run exactly on it, so that a stroke the cap ended may point a little off the grid.
 */
const edgeDrawingArb = fc
  .record({
    columns: fc.integer({ min: 2, max: 8 }),
    rows: fc.integer({ min: 2, max: 8 }),
    unitPx: fc.constantFrom(100, 250), // canvas pixels per grid unit
    maxError: fc.constantFrom(0.02, 0.1, 0.25, 0.5),
    maxWindow: fc.constantFrom(7, 256),
    maxStrokeMs: fc.constantFrom(50, 100, 300),
    minLength: fc.constantFrom(0, 0.1),
    minDurationMs: fc.constantFrom(0, 6.1),
    stretch: fc.boolean(),
    firstEdge: fc.integer({ min: 0, max: 3 }),
    // How far inside the edge the line runs (in max_error; negative is beyond it) where it
    // starts and where it ends, and its noise across the edge: none, a line's or more.
    depthFrom: fc.double({ min: -0.5, max: 1, noNaN: true }),
    depthTo: fc.double({ min: -0.5, max: 1, noNaN: true }),
    noise: fc.constantFrom(0, 0.05, 0.2),
    stepMs: fc.constantFrom(4, 8, 16.7),
    // The first leg may start partway along, the last end partway (or overshoot a corner).
    start: fc.double({ min: -0.05, max: 0.5, noNaN: true }),
    stop: fc.double({ min: 0.5, max: 1.05, noNaN: true }),
    legs: fc.array(fc.array(fc.double({ min: -1, max: 1, noNaN: true }), { minLength: 2, maxLength: 60 }), {
      minLength: 1,
      maxLength: 3,
    }),
  })
  .map((d) => {
    const widthPx = (d.columns - 1) * d.unitPx;
    const heightPx = (d.rows - 1) * d.unitPx;
    const params: WindowParams = {
      algorithm: "window",
      max_error: d.maxError,
      max_window: d.maxWindow,
      max_stroke_ms: d.maxStrokeMs,
      max_bend: 0.1,
      bend_floor: 0.1,
      floor_ms: 73.7,
      rest_ms: 100,
      strict_minimums: false,
      least_squares: false,
      lookahead_ms: 30,
      clear_on_press: true,
      min_duration_ms: d.minDurationMs,
      min_length: d.minLength,
      rows: d.rows,
      columns: d.columns,
      canvas_width_px: widthPx,
      canvas_height_px: heightPx,
      stretch: d.stretch,
    };
    const errorPx = d.maxError * d.unitPx;
    // The canvas corners clockwise, and each edge's inward normal.
    const corners: Point[] = [
      [0, 0],
      [widthPx, 0],
      [widthPx, heightPx],
      [0, heightPx],
    ];
    const inward: Point[] = [
      [0, 1],
      [-1, 0],
      [0, -1],
      [1, 0],
    ];
    const samples: Sample[] = [];
    d.legs.forEach((noises, leg) => {
      const edge = (d.firstEdge + leg) % 4;
      const [x0, y0] = corners[edge]!;
      const [x1, y1] = corners[(edge + 1) % 4]!;
      const [nx, ny] = inward[edge]!;
      const start = leg === 0 ? d.start : 0;
      const stop = leg === d.legs.length - 1 ? d.stop : 1;
      noises.forEach((noise, k) => {
        const share = k / (noises.length - 1);
        const along = start + (stop - start) * share;
        const depthShare = ((leg + share) / d.legs.length) * (d.depthTo - d.depthFrom) + d.depthFrom;
        const depth = depthShare * errorPx + noise * d.noise * errorPx;
        samples.push({
          t_ms: samples.length * d.stepMs,
          x: x0 + (x1 - x0) * along + nx * depth,
          y: y0 + (y1 - y0) * along + ny * depth,
          pressure: 0.5,
        });
      });
    });
    return { params, samples };
  });

describe("window simplifier along the canvas edges", () => {
  it(
    "gives strokes that start and end on the grid",
    () => {
      // The sleeve refuses a stroke that starts or ends off the grid, and the mapping puts every
      // drawn sample on it: a line going on along a stroke the cap ended must not leave it.
      fc.assert(
        fc.property(edgeDrawingArb, ({ params, samples }) => {
          const simplifier = new WindowSimplifier(params);
          const segments = samples.flatMap((sample) => simplifier.push(sample));
          segments.push(...simplifier.end());
          for (const segment of segments) {
            for (const [x, y] of [segment.start, segment.end]) {
              expect(
                0 <= x && x <= params.columns - 1 && 0 <= y && y <= params.rows - 1,
                String([x, y]),
              ).toBe(true);
            }
          }
        }),
        { numRuns: 400 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );
});

/** The slowest steady pen that is never taken for a resting one: half a pixel a frame at 60 fps. */
const SLOW_PEN_PX_PER_MS = (0.5 * 60) / 1000;

/**
 * A straight leg drawn at a steady speed of at least `SLOW_PEN_PX_PER_MS`, in any direction, on any
 * canvas and grid, sampled every frame or every pointer event (times jittered), its samples at exact
 * or whole pixels; one stroke a leg (no latency cap), so only a rest could cut it.
 */
const slowLegArb = fc
  .record({
    widthPx: fc.double({ min: 200, max: 4000, noNaN: true }),
    heightPx: fc.double({ min: 200, max: 4000, noNaN: true }),
    restMs: fc.constantFrom(100, 200, 500),
    minLength: fc.constantFrom(0, 0.1, 0.4),
    maxError: fc.constantFrom(0.05, 0.25, 1),
    columns: fc.integer({ min: 2, max: 12 }),
    rows: fc.integer({ min: 2, max: 12 }),
    stretch: fc.boolean(),
    speed: fc.double({ min: SLOW_PEN_PX_PER_MS, max: 0.5, noNaN: true }),
    angle: fc.double({ min: 0, max: 2 * Math.PI, noNaN: true }),
    durationMs: fc.double({ min: 300, max: 4000, noNaN: true }),
    stepMs: fc.constantFrom(1000 / 60, 8),
    jitters: fc.array(fc.double({ min: 0.5, max: 1.5, noNaN: true }), { minLength: 1, maxLength: 50 }),
    wholePx: fc.boolean(),
    fx: fc.double({ min: 0, max: 1, noNaN: true }),
    fy: fc.double({ min: 0, max: 1, noNaN: true }),
  })
  .filter(({ widthPx, heightPx, speed, angle, durationMs }) => {
    const length = speed * durationMs;
    return (
      Math.abs(Math.cos(angle)) * length + 2 < widthPx && Math.abs(Math.sin(angle)) * length + 2 < heightPx
    );
  })
  .map((leg) => {
    const params: WindowParams = {
      ...DEFAULT_WINDOW_PARAMS,
      max_stroke_ms: 0,
      max_window: 10_000,
      rest_ms: leg.restMs,
      min_length: leg.minLength,
      max_error: leg.maxError,
      columns: leg.columns,
      rows: leg.rows,
      stretch: leg.stretch,
      canvas_width_px: leg.widthPx,
      canvas_height_px: leg.heightPx,
    };
    const ux = Math.cos(leg.angle);
    const uy = Math.sin(leg.angle);
    const length = leg.speed * leg.durationMs;
    // A start from which the whole leg stays on the canvas (no clamping onto the grid's edge).
    const x0 = leg.fx * (leg.widthPx - Math.abs(ux) * length - 2) + 1 + Math.max(0, -ux) * length;
    const y0 = leg.fy * (leg.heightPx - Math.abs(uy) * length - 2) + 1 + Math.max(0, -uy) * length;
    const samples: Sample[] = [];
    for (let t = 0, k = 0; t <= leg.durationMs; k++) {
      let x = x0 + ux * leg.speed * t;
      let y = y0 + uy * leg.speed * t;
      if (leg.wholePx) [x, y] = [Math.round(x), Math.round(y)];
      samples.push({ t_ms: t, x, y, pressure: 0.5 });
      t += leg.stepMs * leg.jitters[k % leg.jitters.length]!;
    }
    return { params, samples };
  });

/**
 * A leg, a rest of at least rest_ms at its end (the pen still, or trembling well within the rest
 * radius), then a leg in another direction; with the index of the rest's first and last samples.
 */
const restArb = fc
  .record({
    capMs: fc.constantFrom(0, 200),
    restPick: fc.integer({ min: 0, max: 2 }),
    stepMs: fc.constantFrom(1000 / 60, 8),
    stepPx: fc.double({ min: 1.5, max: 9, noNaN: true }),
    tremble: fc.constantFrom(0, 0.4),
    restShare: fc.double({ min: 1.2, max: 4, noNaN: true }),
    shakes: fc.array(
      fc.tuple(fc.double({ min: -1, max: 1, noNaN: true }), fc.double({ min: -1, max: 1, noNaN: true })),
      {
        minLength: 1,
        maxLength: 40,
      },
    ),
  })
  .map((r) => {
    // A rest longer than the latency cap is the crawl rule's: the stroke after it starts at most
    // the cap before the pen moves on.
    const rests = r.capMs > 0 ? [50, 100] : [50, 100, 300];
    const params: WindowParams = {
      ...DEFAULT_WINDOW_PARAMS,
      least_squares: false,
      max_stroke_ms: r.capMs,
      rest_ms: rests[r.restPick % rests.length]!,
      canvas_width_px: 1200,
      canvas_height_px: 800,
    };
    const mapping = CanvasMapping.fromParams(params);
    const radiusPx = windowRestRadius(params, mapping) / mapping.scale;
    const samples: Sample[] = [];
    for (let k = 0; k < 40; k++)
      samples.push({ t_ms: k * r.stepMs, x: 200 + r.stepPx * k, y: 400, pressure: 0.5 });
    const arrival = samples.length - 1;
    const { x, y } = samples[arrival]!;
    let t = samples[arrival]!.t_ms;
    const steps = Math.ceil((r.restShare * params.rest_ms) / r.stepMs);
    for (let k = 0; k < steps; k++) {
      t += r.stepMs;
      const [dx, dy] = r.shakes[k % r.shakes.length]!;
      const shake = (r.tremble * radiusPx) / Math.SQRT2;
      samples.push({ t_ms: t, x: x + dx * shake, y: y + dy * shake, pressure: 0.5 });
    }
    const leave = samples.length - 1;
    for (let k = 1; k < 40; k++)
      samples.push({ t_ms: t + k * r.stepMs, x, y: y - r.stepPx * k, pressure: 0.5 });
    return { params, samples, arrival, leave, mapping };
  });

describe("a resting pen and a slow, steady one", () => {
  it(
    "never cuts a slow steady leg for rest",
    () => {
      fc.assert(
        fc.property(slowLegArb, ({ params, samples }) => {
          const core = new WindowCore(params);
          for (const sample of samples) {
            expect(core.push(sample)).toEqual([]);
            expect(core.rested).toBe(false);
          }
          const strokes = core.end();
          expect(strokes).toHaveLength(1);
          const map = CanvasMapping.fromParams(params);
          const [stroke] = strokes;
          expect(stroke!.start_ms).toBe(samples[0]!.t_ms);
          expect(stroke!.end_ms).toBe(samples[samples.length - 1]!.t_ms);
          expect(stroke!.start).toEqual(map.toGrid(samples[0]!.x, samples[0]!.y));
          expect(stroke!.end).toEqual(
            map.toGrid(samples[samples.length - 1]!.x, samples[samples.length - 1]!.y),
          );
        }),
        { numRuns: 300 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );

  it(
    "ends the stroke before a rest while the pen rests, and does not play the rest",
    () => {
      fc.assert(
        fc.property(restArb, ({ params, samples, arrival, leave, mapping }) => {
          const simplifier = new WindowSimplifier(params);
          const duringRest: Segment[] = [];
          const after: Segment[] = [];
          samples.forEach((sample, index) => {
            const out = simplifier.push(sample);
            if (arrival < index && index <= leave) duringRest.push(...out);
            else if (index > leave) after.push(...out);
          });
          after.push(...simplifier.end());
          expect(duringRest.length, "a stroke let go while the pen rests").toBeGreaterThan(0);
          const last = duringRest[duringRest.length - 1]!;
          const [rx, ry] = mapping.toGrid(samples[arrival]!.x, samples[arrival]!.y);
          expect(Math.hypot(last.end[0] - rx, last.end[1] - ry)).toBeLessThanOrEqual(
            windowRestRadius(params, mapping) + FLOAT_TOLERANCE,
          );
          // A rest is told after rest_ms of it, and the latency cap may end a stroke first; a
          // piece held to merge, briefer than the sleeve's floor, takes the time it needs from it.
          expect(last.end_ms).toBeLessThanOrEqual(
            samples[arrival]!.t_ms + Math.max(params.rest_ms, params.floor_ms),
          );
          // Nothing plays the rest: the next stroke starts when the pen moves on (if the cap ended
          // a stroke in the rest, what is left of it may be too brief to tell: under rest_ms).
          expect(after.length, "the leg after the rest is sent").toBeGreaterThan(0);
          const toldMs = params.max_stroke_ms > 0 ? params.rest_ms : 0;
          expect(after[0]!.start_ms).toBeGreaterThanOrEqual(samples[leave]!.t_ms - toldMs);
        }),
        { numRuns: 200 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );
});
