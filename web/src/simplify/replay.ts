/**
 * A whole recording through a simplifier, deterministically (port of
 * `simplify/replay.py`): every path resampled into frames at `params.fps`,
 * pushed, and ended, in order. The parameters choose the simplifier, as in
 * the reference: window parameters (with `max_error`) run the window one.
 */
import { AngleSimplifier } from "./angle";
import { framesFromSamples } from "./frames";
import type { AngleParams } from "./params";
import type { Sample, Segment } from "./segment";
import { WindowSimplifier } from "./window";
import { isWindowParams, type WindowParams } from "./window-params";

export type Algorithm = "angle" | "window";

/** What every simplifier offers: frames in, finished segments out. */
export interface Simplifier {
  readonly drawing: boolean;
  /** Where the stroke being drawn starts (canvas pixels); null between paths. */
  readonly lineStart: Sample | null;
  push(frame: Sample): Segment[];
  end(): Segment[];
}

/** A segment and the index of the path it came from. */
export interface PathSegment {
  readonly path: number;
  readonly segment: Segment;
}

/** The simplifier the parameters belong to. */
export function makeSimplifier(params: AngleParams | WindowParams): Simplifier {
  return isWindowParams(params) ? new WindowSimplifier(params) : new AngleSimplifier(params);
}

export function algorithmOf(params: AngleParams | WindowParams): Algorithm {
  return isWindowParams(params) ? "window" : "angle";
}

export function simplifyPaths(
  params: AngleParams | WindowParams,
  paths: readonly (readonly Sample[])[],
): PathSegment[] {
  const simplifier = makeSimplifier(params);
  const out: PathSegment[] = [];
  paths.forEach((samples, path) => {
    for (const frame of framesFromSamples(samples, params.fps)) {
      for (const segment of simplifier.push(frame)) out.push({ path, segment });
    }
    for (const segment of simplifier.end()) out.push({ path, segment });
  });
  return out;
}
