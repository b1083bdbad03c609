/**
 * What the property tests of both simplifiers draw from: random pointer paths,
 * the parameters every simplifier shares, and the drop rule every simplifier
 * applies through segment.ts.
 */
import fc from "fast-check";
import { expect } from "vitest";
import {
  NOT_ENOUGH_DISTANCE,
  NOT_ENOUGH_DURATION,
  segmentLength,
  type Sample,
  type Segment,
} from "../src/simplify/segment";

const WIDTH_PX = 900;
const HEIGHT_PX = 600;

/**
 * A pointer path: a random walk inside (and a little outside) the canvas, times increasing.
 * `minStepMs` above 0 gives every sample its own time; `randomPressure` off keeps 0.5.
 */
export function pointerPathArb(options: {
  minStepMs: number;
  randomPressure: boolean;
}): fc.Arbitrary<Sample[]> {
  return fc
    .record({
      x0: fc.double({ min: -20, max: WIDTH_PX + 20, noNaN: true }),
      y0: fc.double({ min: -20, max: HEIGHT_PX + 20, noNaN: true }),
      steps: fc.array(
        fc.record({
          dt: fc.double({ min: options.minStepMs, max: 40, noNaN: true }),
          dx: fc.double({ min: -60, max: 60, noNaN: true }),
          dy: fc.double({ min: -60, max: 60, noNaN: true }),
          pressure: options.randomPressure ? fc.double({ min: 0, max: 1, noNaN: true }) : fc.constant(0.5),
        }),
        // "max": long paths, with many checks; fast-check favours tiny arrays otherwise.
        { minLength: 0, maxLength: 200, size: "max" },
      ),
    })
    .map(({ x0, y0, steps }) => {
      const samples: Sample[] = [{ t_ms: 0, x: x0, y: y0, pressure: 0.5 }];
      for (const step of steps) {
        const last = samples[samples.length - 1]!;
        samples.push({
          t_ms: last.t_ms + step.dt,
          x: last.x + step.dx,
          y: last.y + step.dy,
          pressure: step.pressure,
        });
      }
      return samples;
    });
}

/** The parameters both simplifiers take, to spread into each one's fc.record. */
export const SHARED_PARAM_ARBS = {
  clear_on_press: fc.boolean(),
  min_duration_ms: fc.double({ min: 0, max: 100, noNaN: true }),
  min_length: fc.double({ min: 0, max: 1, noNaN: true }),
  rows: fc.integer({ min: 2, max: 8 }),
  columns: fc.integer({ min: 2, max: 8 }),
  canvas_width_px: fc.constant(WIDTH_PX),
  canvas_height_px: fc.constant(HEIGHT_PX),
  stretch: fc.boolean(),
};

interface SharedParams {
  min_duration_ms: number;
  min_length: number;
  rows: number;
  columns: number;
  canvas_width_px: number;
  canvas_height_px: number;
  stretch: boolean;
}

/** A dropped segment carries the reason its size gives (distance first), and a kept one is big enough. */
export function expectDropRule(segment: Segment, params: SharedParams): void {
  const length = segmentLength(segment);
  const duration = segment.end_ms - segment.start_ms;
  if (segment.dropped === NOT_ENOUGH_DISTANCE) {
    expect(length).toBeLessThan(params.min_length);
  } else if (segment.dropped === NOT_ENOUGH_DURATION) {
    expect(length).toBeGreaterThanOrEqual(params.min_length);
    expect(duration).toBeLessThan(params.min_duration_ms);
  } else {
    expect(segment.dropped).toBeNull();
    expect(length).toBeGreaterThanOrEqual(params.min_length);
    expect(duration).toBeGreaterThanOrEqual(params.min_duration_ms);
  }
}
