/**
 * A whole recording through the simplifier, deterministically (port of
 * `simplify/replay.py`): every path resampled into frames at `params.fps`,
 * pushed, and ended, in order.
 */
import { AngleSimplifier } from "./angle";
import { framesFromSamples } from "./frames";
import type { AngleParams } from "./params";
import type { Sample, Segment } from "./segment";

/** A segment and the index of the path it came from. */
export interface PathSegment {
  readonly path: number;
  readonly segment: Segment;
}

export function simplifyPaths(params: AngleParams, paths: readonly (readonly Sample[])[]): PathSegment[] {
  const simplifier = new AngleSimplifier(params);
  const out: PathSegment[] = [];
  paths.forEach((samples, path) => {
    for (const frame of framesFromSamples(samples, params.fps)) {
      for (const segment of simplifier.push(frame)) out.push({ path, segment });
    }
    for (const segment of simplifier.end()) out.push({ path, segment });
  });
  return out;
}
