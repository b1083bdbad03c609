/**
 * `npm run bench`: the web client's figures, printed (never asserted).
 *   - the TypeScript angle simplifier's throughput (frames/s) beside a baseline;
 *   - the TypeScript angle and window simplifiers' throughput on the LASA points
 *     (written by the Python bench) beside simplify-js (Douglas-Peucker) on the
 *     same points, as ratios;
 *   - scripting time per frame while drawing in Chromium, after 10, 1,000 and
 *     10,000 drawn strokes, and the ratios to the first (budget <= 1.2: every
 *     per-frame cost is independent of what has been drawn);
 *   - the requestAnimationFrame interval (p95) while scribbling path after path
 *     for a minute on the page `feelmysign up` serves, its simulated sleeve
 *     playing: the last seconds against the first (budget <= 1.2).
 * Needs `vite build` (dist/), the Python venv (feelmysign) and Debian's chromium.
 * FEELMYSIGN_BENCH_WEB_DIR measures the scribble on another build of the page;
 * FEELMYSIGN_SCRIBBLE_S scribbles that many seconds instead of a minute (a long call).
 */
import type { FramePhase } from "./frame-cost";
import { benchLasa, type LasaRate } from "./lasa";
import { benchSimplifier } from "./simplifier";
// The browser parts (playwright-core) are loaded after the simplifiers are timed, not before:
// with playwright-core loaded, simplify-js (the LASA baseline) ran at 40 to 50% of its speed
// in the same process while the simplifiers did not change, which doubled every ratio to it
// (docs/research.md, "What is left of the window's budget").

/** Each part's wall time, printed after its figures: make bench is meant to take minutes. */
let partStarted = performance.now();
function partTime(): void {
  const now = performance.now();
  console.log(`  (${((now - partStarted) / 1000).toFixed(1)} s)`);
  partStarted = now;
}
const benchStarted = partStarted;

function millions(value: number): string {
  return `${(value / 1e6).toFixed(2)} M`;
}

function phase(label: string, figures: FramePhase): string {
  return (
    `  ${label.padEnd(22)} ${figures.scriptMsPerFrame.toFixed(3)} ms/frame scripting` +
    ` (the page's own frame work: mean ${figures.pageWorkMeanMs.toFixed(3)} ms, p95 ${figures.pageWorkP95Ms.toFixed(3)} ms;` +
    ` ${figures.frames} frames, least of ${figures.drawings} drawings, ${figures.strokes} strokes on the canvas)` +
    (figures.capped ? ` [more frames than the page keeps (${figures.frames}): per frame overstated]` : "")
  );
}

const simplifier = benchSimplifier();
console.log("web: angle simplifier (TypeScript, Node " + process.versions.node + ")");
console.log(
  `  ${millions(simplifier.framesPerSecond)} frames/s` +
    ` (baseline, one distance per frame: ${millions(simplifier.baselineFramesPerSecond)} frames/s;` +
    ` ratio ${(simplifier.baselineFramesPerSecond / simplifier.framesPerSecond).toFixed(1)}x;` +
    ` ${simplifier.strokes} strokes from 200000 frames)`,
);
partTime();

const lasa = benchLasa();
if (lasa !== null) {
  const { highQuality, fast } = lasa.simplifyJs;
  console.log(
    `web: simplifiers on LASA (TypeScript, Node ${process.versions.node}): ${lasa.demos} demonstrations,` +
      ` ${lasa.points.toLocaleString("en")} points (frames at ${lasa.fps} fps, canvas px) from ${lasa.path}`,
  );
  console.log(
    `  ratios are points/s over simplify-js's on the same points (above 1: faster); simplify-js runs` +
      ` on each whole path, tolerance max_error ${lasa.maxError} grid units in each canvas's px`,
  );
  const line = (rate: LasaRate, label: string) =>
    `  ${rate.name.padEnd(36)} ${millions(rate.pointsPerSecond).padStart(9)} points/s` +
    `  ${(rate.pointsPerSecond / highQuality.pointsPerSecond).toFixed(2).padStart(6)}x simplify-js (hq)` +
    `  ${(rate.pointsPerSecond / fast.pointsPerSecond).toFixed(2).padStart(6)}x simplify-js (fast)` +
    `  ${(lasa.baseline.pointsPerSecond / rate.pointsPerSecond).toFixed(1).padStart(6)}x baseline's time` +
    (rate.strokes === null ? "" : `  ${rate.strokes} ${label}`);
  for (const rate of lasa.rates) console.log(line(rate, "strokes (dropped ones too)"));
  for (const rate of [highQuality, fast]) console.log(line(rate, "segments"));
  partTime();
}

const { benchWidest } = await import("./widest");
const widest = benchWidest();
console.log(
  `web: window simplifier at the widest settings (window 10,000, no latency cap, lookahead 1,000 ms,` +
    ` floor 10,000 ms; a slow arc, ${widest.samples.toLocaleString("en")} samples at 1,000 Hz; least of 3 runs)`,
);
for (const core of widest.cores) {
  console.log(
    `  ${core.name.padEnd(28)} mean ${core.meanUs.toFixed(1).padStart(7)} us a sample` +
      `   worst push ${core.worstMs.toFixed(1).padStart(6)} ms`,
  );
}
partTime();

/** Budget of the two growth ratios below: the page's cost must not grow with the drawing. */
const GROWTH_BUDGET = 1.2;

const { benchFrameCost } = await import("./frame-cost");
const { benchScribble, PATH_SECONDS, SCRIBBLE_SECONDS } = await import("./scribble");
const frames = await benchFrameCost();
console.log(`web: scripting time per frame while drawing (${frames.browser}, headless)`);
console.log(phase("after 10 strokes:", frames.few));
console.log(phase(`after ${frames.more.strokes.toLocaleString("en")} strokes:`, frames.more));
console.log(phase(`after ${frames.many.strokes.toLocaleString("en")} strokes:`, frames.many));
for (const [label, figures] of [
  ["1,000 / 10", frames.more],
  ["10,000 / 10", frames.many],
] as const) {
  console.log(
    `  ratio (${label}): ${(figures.scriptMsPerFrame / frames.few.scriptMsPerFrame).toFixed(2)}` +
      ` (scripting; budget <= ${GROWTH_BUDGET}), ${(figures.pageWorkMeanMs / frames.few.pageWorkMeanMs).toFixed(2)} (page frame work)`,
  );
}

partTime();

const scribble = await benchScribble();
console.log(
  `web: ${SCRIBBLE_SECONDS === 60 ? "a minute" : `${SCRIBBLE_SECONDS} s`} of scribbling on 'feelmysign up' with its simulated sleeve (${scribble.browser}, headless):` +
    ` ${scribble.paths} paths of ${PATH_SECONDS} s in one drawing, ${scribble.samples.toLocaleString("en")} pointer samples,` +
    ` ${scribble.strokes} strokes sent, ${scribble.played} reported played`,
);
console.log(
  `  frame interval p95: first 5 s ${scribble.first.p95Ms.toFixed(1)} ms, last 5 s ${scribble.last.p95Ms.toFixed(1)} ms,` +
    ` ratio ${(scribble.last.p95Ms / scribble.first.p95Ms).toFixed(2)} (budget <= ${GROWTH_BUDGET};` +
    ` ${scribble.first.frames} and ${scribble.last.frames} frames)`,
);
const percent = (share: number) => `${(share * 100).toFixed(1)}%`;
console.log(
  `  main thread busy: first 5 s ${percent(scribble.first.busy)} (scripts ${percent(scribble.first.scripting)}),` +
    ` last 5 s ${percent(scribble.last.busy)} (scripts ${percent(scribble.last.scripting)}),` +
    ` ratio ${(scribble.last.busy / scribble.first.busy).toFixed(2)}`,
);
partTime();
console.log(`web bench: ${((performance.now() - benchStarted) / 1000).toFixed(1)} s`);
