/**
 * Animation frames from recorded samples: what a drawing loop at `fps` would
 * have seen (port of `simplify/frames.py`). The page itself feeds the
 * simplifier real animation frames; this is for replaying recordings and
 * reproducing the shared vectors.
 */
import type { Sample } from "./segment";

/**
 * One frame every 1000/fps ms from the first sample, holding the latest sample
 * seen. The first sample (the press) is the first frame and the last sample
 * (the release) the last, so a path's ends are never lost between two frames.
 */
export function framesFromSamples(samples: readonly Sample[], fps: number): Sample[] {
  const first = samples[0];
  const last = samples[samples.length - 1];
  if (first === undefined || last === undefined) return [];
  const periodMs = 1000 / fps;
  const t0 = first.t_ms;
  const frames: Sample[] = [first];
  let index = 0;
  // t0 + k * period, not an accumulated sum: the reference's rounding.
  for (let k = 1; ; k++) {
    const tMs = t0 + k * periodMs;
    if (tMs > last.t_ms) break;
    while (index + 1 < samples.length && samples[index + 1]!.t_ms <= tMs) index++;
    const held = samples[index]!;
    frames.push({ t_ms: tMs, x: held.x, y: held.y, pressure: held.pressure });
  }
  if (index < samples.length - 1) frames.push(last);
  return frames;
}
