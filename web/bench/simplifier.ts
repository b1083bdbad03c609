/**
 * Throughput of the TypeScript angle simplifier, in frames per second, beside
 * a baseline measured in the same run: one distance computation per frame (the
 * least any per-frame algorithm does). Figures, not a test: nothing is asserted.
 */
import { AngleSimplifier } from "../src/simplify/angle";
import { DEFAULT_ANGLE_PARAMS } from "../src/simplify/params";
import type { Sample } from "../src/simplify/segment";

const FRAMES = 200_000;
const REPEATS = 7;

/** A wandering path: arcs and turns, so that checks both pass and fail. */
function makeFrames(count: number): Sample[] {
  const frames: Sample[] = [];
  let x = 600;
  let y = 400;
  let heading = 0;
  for (let k = 0; k < count; k++) {
    heading += k % 97 < 5 ? 1.2 : 0.01;
    x = Math.min(Math.max(x + 4 * Math.cos(heading), 0), 1200);
    y = Math.min(Math.max(y + 4 * Math.sin(heading), 0), 800);
    frames.push({ t_ms: k * (1000 / 60), x, y, pressure: 0.5 });
  }
  return frames;
}

function median(values: number[]): number {
  const sorted = [...values].sort((a, b) => a - b);
  return sorted[Math.floor(sorted.length / 2)]!;
}

export interface SimplifierFigures {
  framesPerSecond: number;
  baselineFramesPerSecond: number;
  strokes: number;
}

export function benchSimplifier(): SimplifierFigures {
  const frames = makeFrames(FRAMES);
  const params = { ...DEFAULT_ANGLE_PARAMS, canvas_width_px: 1200, canvas_height_px: 800 };
  const runs: number[] = [];
  const baselines: number[] = [];
  let strokes = 0;
  let sink = 0;
  for (let repeat = 0; repeat < REPEATS; repeat++) {
    const simplifier = new AngleSimplifier(params);
    let started = performance.now();
    let count = 0;
    for (const frame of frames) count += simplifier.push(frame).length;
    count += simplifier.end().length;
    runs.push(performance.now() - started);
    strokes = count;
    started = performance.now();
    let previous = frames[0]!;
    for (const frame of frames) {
      const dx = frame.x - previous.x;
      const dy = frame.y - previous.y;
      sink += Math.sqrt(dx * dx + dy * dy);
      previous = frame;
    }
    baselines.push(performance.now() - started);
  }
  if (Number.isNaN(sink)) throw new Error("unreachable: keeps the baseline loop from being optimised away");
  return {
    framesPerSecond: FRAMES / (median(runs) / 1000),
    baselineFramesPerSecond: FRAMES / (median(baselines) / 1000),
    strokes,
  };
}
