/**
 * The window simplifier's cost per sample at the widest settings the page offers (window cap
 * 10,000 samples, no latency cap, lookahead 1,000 ms, floor 10,000 ms): every piece is briefer
 * than the floor, so each sample's best polyline is searched over every sample since the anchor.
 * A slow arc at 1,000 Hz for 5 s, the least-squares core (the default) and the chord core, each
 * beside one distance per sample on the same points. The worst push is what a page would freeze
 * for once; the mean, what every sample costs. Figures, not a test: nothing is asserted.
 */
import type { Sample } from "../src/simplify/segment";
import { WindowSimplifier } from "../src/simplify/window";
import { DEFAULT_WINDOW_PARAMS, type WindowParams } from "../src/simplify/window-params";

const SAMPLES = 5000;
const REPEATS = 3;

export interface WidestFigures {
  samples: number;
  cores: { name: string; meanUs: number; worstMs: number }[];
}

function arc(): Sample[] {
  return Array.from({ length: SAMPLES }, (_, k) => {
    const angle = (k / SAMPLES) * Math.PI * 1.5;
    return { t_ms: k, x: 400 + 250 * Math.cos(angle), y: 300 + 250 * Math.sin(angle), pressure: 0.5 };
  });
}

export function benchWidest(): WidestFigures {
  const samples = arc();
  const widest: WindowParams = {
    ...DEFAULT_WINDOW_PARAMS,
    canvas_width_px: 800,
    canvas_height_px: 600,
    max_window: 10_000,
    max_stroke_ms: 0,
    lookahead_ms: 1000,
    floor_ms: 10_000,
  };
  const cores = (
    [
      ["least squares (the default)", widest],
      ["chord", { ...widest, least_squares: false }],
    ] as const
  ).map(([name, params]) => {
    let meanUs = Infinity;
    let worstMs = Infinity;
    // The least of a few runs (the first compiles): the cost of the code, not of the machine's load.
    for (let repeat = 0; repeat < REPEATS; repeat++) {
      const simplifier = new WindowSimplifier(params);
      let worst = 0;
      const started = performance.now();
      for (const sample of samples) {
        const before = performance.now();
        simplifier.push(sample);
        worst = Math.max(worst, performance.now() - before);
      }
      simplifier.end();
      meanUs = Math.min(meanUs, ((performance.now() - started) * 1000) / samples.length);
      worstMs = Math.min(worstMs, worst);
    }
    return { name, meanUs, worstMs };
  });
  return { samples: samples.length, cores };
}
