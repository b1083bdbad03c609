/**
 * Throughput of the TypeScript angle and window simplifiers on real pen data,
 * beside simplify-js (Douglas-Peucker, offline, on each whole path) and a
 * one-distance-per-point baseline, all on the same points in the same run.
 *
 * The points are the 210 LASA demonstrations as 60 fps frames in canvas
 * pixels, written by the Python bench (`python -m feelmysign.bench.lasa_points`,
 * run by `make bench` before this): the same frames its Python group times.
 * simplify-js gets the window simplifier's `max_error` (grid units) as a
 * tolerance in each canvas's pixels (the mapping keeps the aspect ratio: one
 * scale), with highQuality on (Douglas-Peucker alone) and off (a radial
 * distance pass first). Each case's rate is the median of its runs after the JIT's warm-up.
 * Figures, not a test: nothing is asserted.
 */
import { existsSync, readFileSync } from "node:fs";
import { fileURLToPath } from "node:url";
import simplify from "simplify-js";
import { AngleSimplifier } from "../src/simplify/angle";
import { DEFAULT_ANGLE_PARAMS, type AngleParams } from "../src/simplify/params";
import type { Sample } from "../src/simplify/segment";
import { WindowSimplifier } from "../src/simplify/window";
import { DEFAULT_WINDOW_PARAMS, type WindowParams } from "../src/simplify/window-params";

/**
 * Runs of every case, interleaved; the first WARM_UP of each are not counted: the JIT compiles
 * the simplifiers over the first runs (the least-squares core's rate rises for about ten), and a
 * page that has drawn for a few seconds runs the compiled code. The figure is the median of the
 * rest. About 1 s in all.
 */
const REPEATS = 25;
const WARM_UP = 8;

/** The frames file: FEELMYSIGN_LASA_FRAMES, else the one the Makefile writes beside this file. */
export const LASA_FRAMES_PATH =
  process.env["FEELMYSIGN_LASA_FRAMES"] ?? fileURLToPath(new URL("./.lasa-frames.json", import.meta.url));

interface DemoJson {
  name: string;
  canvas_width_px: number;
  canvas_height_px: number;
  tolerance_px: number;
  frames: [t_ms: number, x: number, y: number][];
}

interface FramesJson {
  fps: number;
  pressure: number;
  max_error: number;
  demos: DemoJson[];
}

interface Demo {
  frames: Sample[];
  points: { x: number; y: number }[];
  tolerancePx: number;
  angle: AngleParams;
  window: WindowParams;
  /** The same with the chord core (`least_squares` off). */
  chord: WindowParams;
}

export interface LasaRate {
  name: string;
  pointsPerSecond: number;
  /** What it made of all the points: strokes, dropped ones too (simplifiers), or segments (simplify-js). */
  strokes: number | null;
}

export interface LasaFigures {
  path: string;
  demos: number;
  points: number;
  fps: number;
  maxError: number;
  baseline: LasaRate;
  rates: LasaRate[];
  simplifyJs: { highQuality: LasaRate; fast: LasaRate };
}

function median(values: number[]): number {
  const sorted = [...values].sort((a, b) => a - b);
  return sorted[Math.floor(sorted.length / 2)]!;
}

function load(path: string): { file: FramesJson; demos: Demo[] } {
  const file = JSON.parse(readFileSync(path, "utf8")) as FramesJson;
  if (!Array.isArray(file.demos) || typeof file.max_error !== "number") {
    throw new Error(`${path} is not a LASA frames file; delete it and run make bench again`);
  }
  const demos = file.demos.map((demo) => {
    const canvas = { canvas_width_px: demo.canvas_width_px, canvas_height_px: demo.canvas_height_px };
    return {
      frames: demo.frames.map(([t_ms, x, y]) => ({ t_ms, x, y, pressure: file.pressure })),
      points: demo.frames.map(([, x, y]) => ({ x, y })),
      tolerancePx: demo.tolerance_px,
      angle: { ...DEFAULT_ANGLE_PARAMS, ...canvas, fps: file.fps },
      window: { ...DEFAULT_WINDOW_PARAMS, ...canvas, fps: file.fps, max_error: file.max_error },
      chord: {
        ...DEFAULT_WINDOW_PARAMS,
        ...canvas,
        fps: file.fps,
        max_error: file.max_error,
        least_squares: false,
      },
    };
  });
  return { file, demos };
}

/** The figures, or null (with a line saying why) when the frames file has not been written. */
export function benchLasa(path: string = LASA_FRAMES_PATH): LasaFigures | null {
  if (!existsSync(path)) {
    console.log(
      `web: simplifiers on LASA skipped: ${path} is missing; run \`make bench\` (or` +
        ` \`.venv/bin/python -m feelmysign.bench.lasa_points\` from the repository) first`,
    );
    return null;
  }
  const { file, demos } = load(path);
  const points = demos.reduce((sum, demo) => sum + demo.frames.length, 0);
  let sink = 0;

  // Each case runs over every demonstration and returns what it made (strokes or segments).
  const cases: { name: string; run: () => number | null }[] = [
    {
      name: "baseline: one distance per point",
      run: () => {
        for (const demo of demos) {
          let previous = demo.frames[0]!;
          for (const frame of demo.frames) {
            const dx = frame.x - previous.x;
            const dy = frame.y - previous.y;
            sink += Math.sqrt(dx * dx + dy * dy);
            previous = frame;
          }
        }
        return null;
      },
    },
    {
      name: "angle simplifier (paper's defaults)",
      run: () => {
        let strokes = 0;
        for (const demo of demos) {
          const simplifier = new AngleSimplifier(demo.angle);
          for (const frame of demo.frames) strokes += simplifier.push(frame).length;
          strokes += simplifier.end().length;
        }
        return strokes;
      },
    },
    ...(
      [
        ["least squares: the defaults", (demo: Demo) => demo.window],
        ["chord", (demo: Demo) => demo.chord],
      ] as const
    ).map(([core, params]) => ({
      name: `window simplifier (max_error ${file.max_error}, ${core})`,
      run: () => {
        let strokes = 0;
        for (const demo of demos) {
          const simplifier = new WindowSimplifier(params(demo));
          for (const frame of demo.frames) strokes += simplifier.push(frame).length;
          strokes += simplifier.end().length;
        }
        return strokes;
      },
    })),
    ...[true, false].map((highQuality) => ({
      name: `simplify-js (highQuality ${highQuality})`,
      run: () => {
        let segments = 0;
        for (const demo of demos) segments += simplify(demo.points, demo.tolerancePx, highQuality).length - 1;
        return segments;
      },
    })),
  ];

  // Repeats interleave the cases, so every one sees the machine in the same states.
  const times = cases.map(() => [] as number[]);
  const made = cases.map(() => null as number | null);
  for (let repeat = 0; repeat < REPEATS; repeat++) {
    cases.forEach((item, index) => {
      const started = performance.now();
      made[index] = item.run();
      if (repeat >= WARM_UP) times[index]!.push(performance.now() - started);
    });
  }
  if (Number.isNaN(sink)) throw new Error("unreachable: keeps the baseline loop from being optimised away");
  const rates = cases.map((item, index) => ({
    name: item.name,
    pointsPerSecond: points / (median(times[index]!) / 1000),
    strokes: made[index]!,
  }));
  const [baseline, angle, window, chord, highQuality, fast] = rates as [
    LasaRate,
    LasaRate,
    LasaRate,
    LasaRate,
    LasaRate,
    LasaRate,
  ];
  return {
    path,
    demos: demos.length,
    points,
    fps: file.fps,
    maxError: file.max_error,
    baseline,
    rates: [baseline, angle, window, chord],
    simplifyJs: { highQuality, fast },
  };
}
