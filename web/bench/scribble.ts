/**
 * The frame interval while scribbling for a minute, in real Chromium, on the
 * page as `feelmysign up` serves it with its simulated sleeve playing: the
 * broker acknowledges every stroke, the sleeve's events and actuator frames
 * come back, the felt timeline and the "Sleeve says" card follow. Path after
 * path of one drawing (clear on press off), each about 1.5 s long with a
 * pointer sample every 12 ms, in varied shapes (circles, zigzags, stars,
 * spirals, curves, scribbles). The requestAnimationFrame interval's p95 in
 * the last seconds against the first tells whether the page slows down as
 * the drawing grows (it should not: ratio near 1).
 */
import type { CDPSession, Page } from "playwright-core";
import { DIST_DIR } from "../e2e/harness";
import { drawingArea, type Area } from "../e2e/page";
import { DESKTOP, Processes } from "../e2e/processes";

/** How long the scribbling goes on: a minute, or FEELMYSIGN_SCRIBBLE_S seconds (a long call). */
export const SCRIBBLE_SECONDS = scribbleSeconds(process.env["FEELMYSIGN_SCRIBBLE_S"]);
const SCRIBBLE_MS = SCRIBBLE_SECONDS * 1000;
/** One path: about 1.5 s of pointer samples, one every 12 ms. */
const PATH_MS = 1500;
export const PATH_SECONDS = PATH_MS / 1000;
const SAMPLE_MS = 12;
/** The hand lifted between two paths. */
const PAUSE_MS = 250;
/** The windows compared: the first and the last seconds of the scribbling. */
const WINDOW_MS = 5000;

export interface ScribbleFigures {
  browser: string;
  /** Paths drawn in the measured minute (after one more, to warm up), and pointer samples in all. */
  paths: number;
  samples: number;
  /** Strokes the page sent, and those the sleeve reported played, by the end. */
  strokes: number;
  played: number;
  first: WindowFigures;
  last: WindowFigures;
}

export interface WindowFigures {
  p95Ms: number;
  frames: number;
  /** Share of the window's wall time the page's main thread was busy (CDP TaskDuration). */
  busy: number;
  /** Of which running the page's scripts (CDP ScriptDuration). */
  scripting: number;
}

type Shape = (u: number) => [number, number];

/** FEELMYSIGN_SCRIBBLE_S read: whole seconds from 15 (three windows of 5 s) to a day. */
function scribbleSeconds(given: string | undefined): number {
  if (given === undefined || given === "") return 60;
  const seconds = Number(given);
  if (!Number.isInteger(seconds) || seconds < 15 || seconds > 86_400) {
    throw new Error(`FEELMYSIGN_SCRIBBLE_S=${given}: give whole seconds from 15 to 86400 (default 60)`);
  }
  return seconds;
}

/** A small deterministic generator: the same scribble every run. */
function random(seed: number): () => number {
  let state = seed >>> 0;
  return () => {
    state = (state + 0x6d2b79f5) >>> 0;
    let t = state;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

/** Along a polyline of `points` (unit square), by arc length. */
function polyline(points: readonly [number, number][]): Shape {
  const lengths = [0];
  for (let i = 1; i < points.length; i++) {
    const [ax, ay] = points[i - 1]!;
    const [bx, by] = points[i]!;
    lengths.push(lengths[i - 1]! + Math.hypot(bx - ax, by - ay));
  }
  const total = lengths[lengths.length - 1]! || 1;
  return (u) => {
    const at = u * total;
    let i = 1;
    while (i < points.length - 1 && lengths[i]! < at) i++;
    const [ax, ay] = points[i - 1]!;
    const [bx, by] = points[i]!;
    const span = lengths[i]! - lengths[i - 1]! || 1;
    const k = Math.min(Math.max((at - lengths[i - 1]!) / span, 0), 1);
    return [ax + (bx - ax) * k, ay + (by - ay) * k];
  };
}

/** The shapes a person scribbles, one after the other, placed and sized at random. */
function shapes(rand: () => number): Shape[] {
  const cx = 0.3 + 0.4 * rand();
  const cy = 0.3 + 0.4 * rand();
  const r = 0.15 + 0.15 * rand();
  const turns = 3 + Math.floor(rand() * 4);
  return [
    // A circle, a little over once round.
    (u) => [cx + r * Math.cos(2.2 * Math.PI * u), cy + r * Math.sin(2.2 * Math.PI * u)],
    // A zigzag across.
    polyline(
      Array.from({ length: 2 * turns + 1 }, (_, i): [number, number] => [
        0.1 + (0.8 * i) / (2 * turns),
        i % 2 === 0 ? cy - r : cy + r,
      ]),
    ),
    // A star.
    polyline(
      Array.from({ length: 11 }, (_, i): [number, number] => {
        const angle = (i * 4 * Math.PI) / 5 - Math.PI / 2;
        return [cx + r * Math.cos(angle), cy + r * Math.sin(angle)];
      }),
    ),
    // A square spiral inwards.
    polyline(
      Array.from({ length: 9 }, (_, i): [number, number] => {
        const size = r * (1 - i / 10);
        const corner = [
          [-1, -1],
          [1, -1],
          [1, 1],
          [-1, 1],
        ][i % 4]!;
        return [cx + size * corner[0]!, cy + size * corner[1]!];
      }),
    ),
    // A Lissajous curve.
    (u) => [cx + r * Math.sin(2 * Math.PI * 3 * u), cy + r * Math.sin(2 * Math.PI * 2 * u + 0.5)],
    // A scribble: straight dashes from point to point.
    polyline(Array.from({ length: 8 }, (): [number, number] => [0.1 + 0.8 * rand(), 0.1 + 0.8 * rand()])),
  ];
}

const sleep = (ms: number) => new Promise((done) => setTimeout(done, Math.max(0, ms)));

/**
 * One path of `shape`, a sample every SAMPLE_MS on the wall clock. The moves are dispatched
 * through the DevTools protocol without waiting for each to be handled, as a real mouse's come:
 * the browser queues them and hands them to the page batched per frame (coalesced events).
 */
async function drawPath(page: Page, cdp: CDPSession, area: Area, shape: Shape): Promise<number> {
  const at = (u: number): { x: number; y: number } => {
    const [x, y] = shape(u);
    return { x: area.left + area.width * x, y: area.top + area.height * y };
  };
  const mouse = (type: "mousePressed" | "mouseMoved" | "mouseReleased", u: number, buttons: number) =>
    cdp.send("Input.dispatchMouseEvent", { type, ...at(u), button: "left", buttons, clickCount: 1 });
  await page.mouse.move(at(0).x, at(0).y);
  const started = performance.now();
  await mouse("mousePressed", 0, 1);
  // Each move's failure is kept and thrown after the path, never left unhandled meanwhile.
  const moves: Promise<unknown>[] = [];
  const kept = (sent: Promise<unknown>) =>
    sent.then(
      () => null,
      (error: unknown) => error,
    );
  for (let k = 1; ; k++) {
    await sleep(started + k * SAMPLE_MS - performance.now());
    const elapsed = performance.now() - started;
    if (elapsed >= PATH_MS) break;
    moves.push(kept(mouse("mouseMoved", elapsed / PATH_MS, 1)));
  }
  moves.push(kept(mouse("mouseMoved", 1, 1)));
  const failed = (await Promise.all(moves)).find((error) => error !== null);
  if (failed !== undefined) throw failed;
  await mouse("mouseReleased", 1, 0);
  return moves.length;
}

function p95(values: readonly number[]): number {
  const sorted = [...values].sort((a, b) => a - b);
  return sorted[Math.min(sorted.length - 1, Math.floor(sorted.length * 0.95))] ?? Number.NaN;
}

export async function benchScribble(
  webDir = process.env["FEELMYSIGN_BENCH_WEB_DIR"] ?? DIST_DIR,
): Promise<ScribbleFigures> {
  const processes = new Processes();
  try {
    const up = await processes.up("bench-scribble", { args: ["--web-dir", webDir] });
    const context = await processes.browser({ ...DESKTOP, deviceScaleFactor: 1 });
    // Every path adds to one drawing, as the user who saw the page slow down drew.
    await context.addInitScript(() => {
      localStorage.setItem("feelmysign.settings.v1", JSON.stringify({ clear_on_press: false }));
    });
    const page = await context.newPage();
    await page.goto(up.url);
    await page.waitForFunction(
      () => document.getElementById("sleeve-status")?.dataset["state"] === "online",
      null,
      {
        timeout: 30_000,
      },
    );
    const cdp = await context.newCDPSession(page);
    const browser = (await cdp.send("Browser.getVersion")).product;
    const area = await drawingArea(page);
    const rand = random(20_240_917);
    // One path first, not measured: the page's code compiled and its canvases sized, as after
    // the first seconds of any use. It is part of the drawing all the same.
    const warmUp = shapes(rand);
    let samples = await drawPath(page, cdp, area, warmUp[warmUp.length - 1]!);
    await sleep(PAUSE_MS);
    // Every animation frame's time, from now on. A string: the bundler would name the function.
    const origin = await page.evaluate<number>(`(() => {
      const frames = [];
      window.benchFrames = frames;
      const loop = (t) => { frames.push(t); requestAnimationFrame(loop); };
      requestAnimationFrame(loop);
      return performance.now();
    })()`);
    // The main thread's busy and scripting time, read at the edges of both windows.
    await cdp.send("Performance.enable");
    const metrics = async () => {
      const { metrics: all } = await cdp.send("Performance.getMetrics");
      const value = (name: string) => all.find((m) => m.name === name)?.value ?? Number.NaN;
      return { at: value("Timestamp"), task: value("TaskDuration"), script: value("ScriptDuration") };
    };
    type Reading = Awaited<ReturnType<typeof metrics>>;
    const start = performance.now();
    const readings: Promise<Reading>[] = [metrics()];
    for (const atMs of [WINDOW_MS, SCRIBBLE_MS - WINDOW_MS]) {
      readings.push(new Promise((read) => setTimeout(() => read(metrics()), atMs)));
    }
    let paths = 0;
    while (performance.now() - start < SCRIBBLE_MS - PATH_MS) {
      const choices = shapes(rand);
      samples += await drawPath(page, cdp, area, choices[paths % choices.length]!);
      paths++;
      await sleep(PAUSE_MS);
    }
    await sleep(start + SCRIBBLE_MS - performance.now());
    readings.push(metrics());
    const [r0, r1, r2, r3] = (await Promise.all(readings)) as [Reading, Reading, Reading, Reading];
    const share = (a: Reading, b: Reading) => ({
      busy: (b.task - a.task) / (b.at - a.at),
      scripting: (b.script - a.script) / (b.at - a.at),
    });
    const { frames, strokes, played } = await page.evaluate(() => ({
      frames: (window as unknown as { benchFrames: number[] }).benchFrames.slice(),
      strokes: Number(document.getElementById("played-summary")?.dataset["sent"] ?? 0),
      played: Number(document.getElementById("played-summary")?.dataset["played"] ?? 0),
    }));
    const end = frames[frames.length - 1] ?? origin;
    const intervals = (from: number, to: number) => {
      const out: number[] = [];
      for (let i = 1; i < frames.length; i++) {
        if (frames[i - 1]! >= from && frames[i]! <= to) out.push(frames[i]! - frames[i - 1]!);
      }
      return out;
    };
    const first = intervals(origin, origin + WINDOW_MS);
    const last = intervals(end - WINDOW_MS, end);
    return {
      browser,
      paths,
      samples,
      strokes,
      played,
      first: { p95Ms: p95(first), frames: first.length, ...share(r0, r1) },
      last: { p95Ms: p95(last), frames: last.length, ...share(r2, r3) },
    };
  } finally {
    await processes.stop();
  }
}
