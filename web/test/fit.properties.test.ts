/**
 * The window simplifier with `least_squares` on (the least-squares core, `fit.ts`): its vectors
 * to the last bit, and its invariants on random paths and parameters (fast-check): every drawn
 * sample lies within max_error of a sent stroke, strokes join end to start from the press to the
 * release, a stroke drawn briefer than the sleeve's floor is sent to last the floor (none is
 * held or dropped but a path's only piece), and a stroke is sent once the pen has drawn
 * lookahead_ms past its end, unless the latency cap or the release sends it sooner.
 */
import fc from "fast-check";
import { describe, expect, it } from "vitest";
import { FitCore } from "../src/simplify/fit";
import { CanvasMapping } from "../src/simplify/mapping";
import { simplifyPaths } from "../src/simplify/registry";
import { type Point, type Sample, type Segment } from "../src/simplify/segment";
import { Merger, WindowSimplifier, restRadius } from "../src/simplify/window";
import { DEFAULT_WINDOW_PARAMS, type WindowParams } from "../src/simplify/window-params";
import { SHARED_PARAM_ARBS, pointerPathArb } from "./simplifier-arbitraries";
import { vectors } from "./testdata";

/** Room for a distance computed another way than the simplifier's (last bits only). */
const FLOAT_TOLERANCE = 1e-12;
/** Hundreds of random paths: generous, for a loaded machine (the work is bounded, not timed). */
const PROPERTY_TIMEOUT_MS = 120_000;

// Every sample its own time; one to three paths through one simplifier.
const pathsArb = fc.array(pointerPathArb({ minStepMs: 0.01, randomPressure: false }), {
  minLength: 1,
  maxLength: 3,
});

const paramsArb: fc.Arbitrary<WindowParams> = fc.record({
  algorithm: fc.constant("window" as const),
  max_error: fc.oneof(
    fc.constantFrom(0.001, 0.05, 0.15, 0.25, 1),
    fc.double({ min: 0.001, max: 2, noNaN: true }),
  ),
  max_window: fc.oneof(fc.constantFrom(1, 2, 8, 256), fc.integer({ min: 1, max: 300 })),
  max_stroke_ms: fc.constantFrom(0, 50, 100, 200, 300),
  // The window's own rules: the least-squares core reads neither.
  max_bend: fc.constantFrom(0, 0.1),
  bend_floor: fc.constantFrom(0, 0.05),
  floor_ms: fc.oneof(fc.constantFrom(0, 40, 73.701, 200), fc.double({ min: 0, max: 300, noNaN: true })),
  rest_ms: fc.constantFrom(0, 30, 100, 300),
  // Strict minimums let the bound yield to a wearer's limits: not these properties'.
  strict_minimums: fc.constant(false),
  least_squares: fc.constant(true),
  lookahead_ms: fc.oneof(fc.constantFrom(0, 30, 100), fc.double({ min: 0, max: 1000, noNaN: true })),
  ...SHARED_PARAM_ARBS,
});

/** Distance from a point to the segment start -> end (not its line), computed apart. */
function distance(point: Point, start: Point, end: Point): number {
  const dx = end[0] - start[0];
  const dy = end[1] - start[1];
  const qx = point[0] - start[0];
  const qy = point[1] - start[1];
  const lengthSq = dx * dx + dy * dy;
  const t = lengthSq === 0 ? 0 : Math.min(Math.max((qx * dx + qy * dy) / lengthSq, 0), 1);
  return Math.hypot(qx - t * dx, qy - t * dy);
}

/** Each path's strokes, drawn through one simplifier, path after path. */
function strokesOf(params: WindowParams, paths: readonly (readonly Sample[])[]): Segment[][] {
  const simplifier = new WindowSimplifier(params);
  return paths.map((samples) => {
    const strokes = samples.flatMap((sample) => simplifier.push(sample));
    strokes.push(...simplifier.end());
    return strokes;
  });
}

describe("least-squares vectors", () => {
  const cases = vectors("window").filter(([name]) => /\/(least-squares[^/]*|chord)\.json$/.test(name)) as [
    string,
    {
      params: Omit<WindowParams, "algorithm">;
      paths: [number, number, number, number][][];
      expected: { segments: (Record<string, unknown> & { path: number })[] };
    },
  ][];

  it("finds them", () => {
    expect(cases.filter(([name]) => name.includes("least-squares")).length).toBeGreaterThanOrEqual(80);
  });

  // The vector test allows the file's tolerance; the port's float operations are the reference's,
  // in its order, so every number is the same to the last bit.
  it.each(cases)("%s, to the last bit", (_name, vector) => {
    const params = { ...vector.params, algorithm: "window" } as WindowParams;
    const paths = vector.paths.map((path) =>
      path.map(([t_ms, x, y, pressure]) => ({ t_ms, x, y, pressure })),
    );
    const actual = simplifyPaths(params, paths).map(({ path, segment: s }) => ({
      path,
      start: [...s.start],
      end: [...s.end],
      start_ms: s.start_ms,
      end_ms: s.end_ms,
      emitted_at_ms: s.emitted_at_ms,
      dropped: s.dropped,
      merged: s.merged ?? 0,
      duration_ms: s.duration_ms,
    }));
    const expected = vector.expected.segments.map((want) => ({
      ...want,
      duration_ms: want.duration_ms ?? (want.end_ms as number) - (want.start_ms as number),
    }));
    expect(actual).toEqual(expected);
  });
});

describe("least-squares core", () => {
  it("is the window simplifier's with least_squares on, and its pieces are sent as they are", () => {
    const params: WindowParams = { ...DEFAULT_WINDOW_PARAMS, least_squares: true };
    // A quarter circle drawn in 600 ms: several strokes, each lasting the floor.
    const samples: Sample[] = Array.from({ length: 61 }, (_, k) => ({
      t_ms: 10 * k,
      x: 400 + 300 * Math.cos((Math.PI / 2) * (k / 60)),
      y: 100 + 300 * Math.sin((Math.PI / 2) * (k / 60)),
      pressure: 0.5,
    }));
    const core = new FitCore(params);
    const pieces = samples.flatMap((sample) => core.push(sample));
    pieces.push(...core.end());
    const [strokes] = strokesOf(params, [samples]);
    expect(pieces.length).toBeGreaterThan(2);
    // The core's pieces as they are, but that a path's first piece, if too short to send, merges
    // into the next (as the window's: a tap is dropped).
    const merged = pieces.length - strokes!.length;
    expect(merged === 0 || (merged === 1 && strokes![0]!.merged === 1)).toBe(true);
    expect(strokes!.slice(1).map((s) => [s.start, s.end, s.start_ms, s.end_ms, s.emitted_at_ms])).toEqual(
      pieces.slice(merged + 1).map((s) => [s.start, s.end, s.start_ms, s.end_ms, s.emitted_at_ms]),
    );
    expect(strokes![0]!.end).toEqual(pieces[merged]!.end);
    // Each but the last (the release's polyline ends where the pen lifts) lasts the floor as drawn.
    for (const stroke of strokes!.slice(0, -1)) {
      expect(stroke.end_ms - stroke.start_ms).toBeGreaterThanOrEqual(params.floor_ms);
    }
  });
});

describe("a merger that holds no short piece (the least squares' pieces)", () => {
  const FLOOR_MS = 73.701;
  const piece = (start: Point, end: Point, startMs: number, endMs: number): Segment => ({
    start,
    end,
    start_ms: startMs,
    end_ms: endMs,
    duration_ms: endMs - startMs,
    emitted_at_ms: endMs,
    dropped: null,
  });

  it.each([true, false])(
    "holdShort %s: a brief or short piece waits to merge, or is sent at once (a brief one to last the floor)",
    (holdShort) => {
      const merger = new Merger(0.25, 0.5, 0, FLOOR_MS, false, holdShort);
      merger.sample(0, 0, 0);
      merger.sample(30, 1, 0);
      const out: Segment[] = [];
      // A path's first piece, brief, waits either way (a tap is dropped, not sent).
      merger.take(piece([0, 0], [1, 0], 0, 30), 30, out);
      expect(out).toEqual([]);
      merger.sample(130, 2, 0);
      merger.take(piece([1, 0], [2, 0], 30, 130), 130, out);
      expect(out.map((s) => [s.start, s.end, s.duration_ms, s.merged ?? 0])).toEqual([
        [[0, 0], [2, 0], 130, 1],
      ]);
      out.length = 0;
      merger.sample(160, 3, 0);
      merger.take(piece([2, 0], [3, 0], 130, 160), 160, out);
      // Held to merge by the window's merger; sent as it is by the least squares'.
      expect(out.map((s) => s.duration_ms)).toEqual(holdShort ? [] : [FLOOR_MS]);
      merger.sample(260, 3.1, 0);
      merger.take(piece([3, 0], [3.1, 0], 160, 260), 260, out);
      // Lasting the floor but shorter than min_length: the window's merger sends the two as one
      // (within max_error of it), the least squares' sends it as drawn.
      expect(out.map((s) => [s.start, s.end, s.duration_ms, s.merged ?? 0])).toEqual(
        holdShort
          ? [[[2, 0], [3.1, 0], 130, 1]]
          : [
              [[2, 0], [3, 0], FLOOR_MS, 0],
              [[3, 0], [3.1, 0], 100, 0],
            ],
      );
      const before = out.length;
      merger.end(260, out);
      expect(out).toHaveLength(before);
      expect(merger.mergedBack).toBe(0);
    },
  );
});

describe("least-squares invariants", () => {
  it(
    "every drawn sample lies within max_error of a sent stroke; strokes join end to start",
    () => {
      fc.assert(
        fc.property(paramsArb, pathsArb, (params, paths) => {
          const map = CanvasMapping.fromParams(params);
          const rest = params.rest_ms > 0 ? restRadius(params, map) : 0;
          strokesOf(params, paths).forEach((strokes, p) => {
            const samples = paths[p]!;
            const sent = strokes.filter((s) => s.dropped === null);
            // None dropped but a path's one and only piece.
            expect(sent.length === strokes.length || strokes.length === 1).toBe(true);
            if (sent.length === 0) return;
            for (const sample of samples) {
              const point = map.toGrid(sample.x, sample.y);
              const nearest = Math.min(...sent.map((s) => distance(point, s.start, s.end)));
              expect(nearest, "a sample within max_error of a sent stroke").toBeLessThanOrEqual(
                params.max_error + FLOAT_TOLERANCE,
              );
            }
            // From the press (a rest there starts the first stroke later, at the press's point) ...
            const first = samples[0]!;
            expect(strokes[0]!.start).toEqual(map.toGrid(first.x, first.y));
            expect(strokes[0]!.start_ms).toBeGreaterThanOrEqual(first.t_ms);
            // ... each from where the one before ended (a rest between them is not played) ...
            for (let i = 1; i < strokes.length; i++) {
              expect(strokes[i]!.start).toEqual(strokes[i - 1]!.end);
              expect(strokes[i]!.start_ms).toBeGreaterThanOrEqual(strokes[i - 1]!.end_ms);
            }
            // ... to the release (or, where the pen rested until it, the rest's first sample).
            const last = samples[samples.length - 1]!;
            const end = strokes[strokes.length - 1]!.end;
            expect(distance(map.toGrid(last.x, last.y), end, end)).toBeLessThanOrEqual(
              2 * rest + FLOAT_TOLERANCE,
            );
          });
        }),
        { numRuns: 400 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );

  it(
    "a stroke drawn briefer than the floor lasts the floor; one drawn longer lasts as drawn",
    () => {
      fc.assert(
        fc.property(paramsArb, pathsArb, (params, paths) => {
          const floorMs = Math.max(params.floor_ms, params.min_duration_ms);
          for (const strokes of strokesOf(params, paths)) {
            for (const stroke of strokes) {
              if (stroke.dropped !== null) continue;
              const drawnMs = stroke.end_ms - stroke.start_ms;
              expect(stroke.duration_ms).toBe(drawnMs < floorMs ? floorMs : drawnMs);
              // Nothing waits to merge but a path's first piece: each is sent as the core lets it go.
              if (stroke !== strokes[0]) expect(stroke.merged ?? 0).toBe(0);
            }
          }
        }),
        { numRuns: 400 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );

  it(
    "a stroke is sent once the pen has drawn lookahead_ms past its end, or the cap or the release sends it",
    () => {
      fc.assert(
        fc.property(
          paramsArb.map((params) => ({ ...params, rest_ms: 0 })),
          pathsArb,
          (params, paths) => {
            const capMs = params.max_stroke_ms;
            strokesOf(params, paths).forEach((strokes, p) => {
              const samples = paths[p]!;
              const times = new Set(samples.map((sample) => sample.t_ms));
              const releaseMs = samples[samples.length - 1]!.t_ms;
              for (const stroke of strokes) {
                // Sent while drawing (at a sample's time), after its end was drawn.
                expect(times.has(stroke.emitted_at_ms)).toBe(true);
                expect(stroke.emitted_at_ms).toBeGreaterThanOrEqual(stroke.end_ms);
                const capped =
                  capMs > 0 &&
                  (stroke.end_ms - stroke.start_ms > capMs || stroke.emitted_at_ms - stroke.start_ms > capMs);
                if (stroke.emitted_at_ms !== releaseMs && !capped) {
                  expect(stroke.emitted_at_ms - stroke.end_ms).toBeGreaterThanOrEqual(params.lookahead_ms);
                }
              }
            });
          },
        ),
        { numRuns: 400 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );
});
