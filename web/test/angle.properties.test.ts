/**
 * Invariants of the TypeScript angle simplifier on random paths and
 * parameters (fast-check): strokes join end to start with recover on, the
 * first starts at the press and the last ends at the release, a dropped
 * segment carries the reason that matches its size, and the result depends on
 * the input alone.
 */
import fc from "fast-check";
import { describe, expect, it } from "vitest";
import { CanvasMapping } from "../src/simplify/mapping";
import { SHARED_PARAM_ARBS, expectDropRule, pointerPathArb } from "./simplifier-arbitraries";
import { AngleSimplifier } from "../src/simplify/angle";
import { framesFromSamples } from "../src/simplify/frames";
import { DEFAULT_ANGLE_PARAMS, type AngleParams } from "../src/simplify/params";
import { simplifyPaths } from "../src/simplify/registry";
import { type Sample, type Segment } from "../src/simplify/segment";

const pathArb = pointerPathArb({ minStepMs: 0, randomPressure: true });

const paramsArb: fc.Arbitrary<AngleParams> = fc.record({
  algorithm: fc.constant("angle" as const),
  check_frames: fc.integer({ min: 2, max: 20 }),
  max_angle_deg: fc.double({ min: 1, max: 179, noNaN: true }),
  frame_max: fc.oneof(fc.constant(0), fc.integer({ min: 1, max: 120 })),
  fps: fc.double({ min: 10, max: 240, noNaN: true }),
  recover: fc.boolean(),
  ...SHARED_PARAM_ARBS,
});

function runPath(params: AngleParams, samples: readonly Sample[]): { frames: Sample[]; segments: Segment[] } {
  const simplifier = new AngleSimplifier(params);
  const frames = framesFromSamples(samples, params.fps);
  const segments = frames.flatMap((frame) => simplifier.push(frame));
  segments.push(...simplifier.end());
  return { frames, segments };
}

describe("angle simplifier properties", () => {
  it("with recover on, consecutive segments join end to start exactly", () => {
    fc.assert(
      fc.property(paramsArb, pathArb, (params, samples) => {
        const withRecover = { ...params, recover: true, frame_max: 0 };
        const { segments } = runPath(withRecover, samples);
        for (let i = 1; i < segments.length; i++) {
          expect(segments[i]!.start).toEqual(segments[i - 1]!.end);
          expect(segments[i]!.start_ms).toBe(segments[i - 1]!.end_ms);
        }
      }),
    );
  });

  it("with frame_max too, a cut line goes on from where it was cut", () => {
    fc.assert(
      fc.property(paramsArb, pathArb, (params, samples) => {
        const { segments } = runPath({ ...params, recover: true }, samples);
        for (let i = 1; i < segments.length; i++) {
          expect(segments[i]!.start).toEqual(segments[i - 1]!.end);
        }
      }),
    );
  });

  it("the first segment starts at the press and the last ends at the release", () => {
    fc.assert(
      fc.property(paramsArb, pathArb, (params, samples) => {
        const { frames, segments } = runPath(params, samples);
        const grid = CanvasMapping.fromParams(params);
        const first = frames[0]!;
        const last = frames[frames.length - 1]!;
        expect(segments.length).toBeGreaterThanOrEqual(1);
        expect(segments[0]!.start).toEqual(grid.toGrid(first.x, first.y));
        expect(segments[0]!.start_ms).toBe(first.t_ms);
        expect(segments[segments.length - 1]!.end).toEqual(grid.toGrid(last.x, last.y));
        expect(segments[segments.length - 1]!.end_ms).toBe(last.t_ms);
      }),
    );
  });

  it("a dropped segment carries the reason its size gives, and a kept one is big enough", () => {
    fc.assert(
      fc.property(paramsArb, pathArb, (params, samples) => {
        for (const segment of runPath(params, samples).segments) expectDropRule(segment, params);
      }),
    );
  });

  it("every point lies on the grid and times never go back", () => {
    fc.assert(
      fc.property(paramsArb, pathArb, (params, samples) => {
        let previousEnd = -Infinity;
        for (const segment of runPath(params, samples).segments) {
          for (const [x, y] of [segment.start, segment.end]) {
            expect(x).toBeGreaterThanOrEqual(0);
            expect(x).toBeLessThanOrEqual(params.columns - 1);
            expect(y).toBeGreaterThanOrEqual(0);
            expect(y).toBeLessThanOrEqual(params.rows - 1);
          }
          expect(segment.end_ms).toBeGreaterThanOrEqual(segment.start_ms);
          expect(segment.emitted_at_ms).toBeGreaterThanOrEqual(segment.end_ms);
          expect(segment.start_ms).toBeGreaterThanOrEqual(previousEnd);
          previousEnd = segment.end_ms;
        }
      }),
    );
  });

  it("is deterministic: the same paths give the same segments", () => {
    fc.assert(
      fc.property(paramsArb, fc.array(pathArb, { minLength: 1, maxLength: 3 }), (params, paths) => {
        expect(simplifyPaths(params, paths)).toEqual(simplifyPaths(params, paths));
      }),
    );
  });

  it("refuses parameters outside the shared ranges, naming them", () => {
    expect(() => new AngleSimplifier({ ...DEFAULT_ANGLE_PARAMS, check_frames: 1 })).toThrow(
      /check_frames = 1/,
    );
    expect(() => new AngleSimplifier({ ...DEFAULT_ANGLE_PARAMS, max_angle_deg: 180 })).toThrow(
      /from 1 to 179/,
    );
  });
});
