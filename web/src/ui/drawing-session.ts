/**
 * One drawing in progress: pointer samples in, animation frames (angle) or every
 * pointer sample (window) to the chosen simplifier, finished segments to the drawing and its strokes to the sender,
 * ink to the canvas. The animation loop runs only while a pointer is down, and
 * each frame costs the same however much has been drawn.
 */
import { Drawing, type PointerKind, type Unfelt } from "../drawing";
import { newDrawingId } from "../drawing-id";
import { FrameSampler } from "../frame-sampler";
import type { Stroke } from "../protocol";
import { simplifierParams, type Settings } from "../settings";
import { ALGORITHMS, makeSimplifier, simplifyPaths, type Simplifier } from "../simplify/registry";
import type { Sample, Segment } from "../simplify/segment";
import type { DrawingView } from "./canvas";
import type { GridSize } from "./geometry";

/** Frame work times kept for the benchmark (about ten seconds at 60 fps). */
const FRAME_STATS_SIZE = 600;
/** Intensities are sent with this many decimals: finer steps cannot be felt. */
const INTENSITY_DECIMALS = 3;

/** What the session draws on: the canvas (ui/canvas.ts), or a stand-in in the unit tests. */
export type SessionView = Pick<
  DrawingView,
  "area" | "setDrawing" | "flush" | "clearLive" | "drawLive" | "markSent" | "markRejected"
>;

/** What the session needs from the page around it. */
export interface SessionHost {
  settings(): Settings;
  grid(): GridSize;
  send(stroke: Stroke): void;
  /** A drawing started, gained a stroke, or was cleared (null). */
  changed(drawing: Drawing | null): void;
  /** A path ended: what waited for the pointer to lift can run. */
  released(): void;
}

export class DrawingSession {
  readonly #view: SessionView;
  readonly #host: SessionHost;
  #drawing: Drawing | null = null;
  #simplifier: Simplifier | null = null;
  #sampler = new FrameSampler(60);
  #pointerKind: PointerKind = "mouse";
  #pointer: Sample | null = null;
  /** A finished drawing stays on the canvas, but the next press starts a new one (after Stop). */
  #closed = false;
  #loopRunning = false;
  #flushScheduled = false;
  readonly #frameWorkMs: number[] = [];

  constructor(view: SessionView, host: SessionHost) {
    this.#view = view;
    this.#host = host;
  }

  /** The drawing's simplifier takes every pointer sample (coalesced ones included), not frames. */
  get #feedsSamples(): boolean {
    const drawing = this.#drawing;
    return drawing !== null && ALGORITHMS[drawing.params.algorithm].input === "samples";
  }

  get drawing(): Drawing | null {
    return this.#drawing;
  }

  /** True while a pointer is down. */
  get pressed(): boolean {
    return this.#sampler.pressed;
  }

  /** `readSample` is called once the drawing is chosen: its canvas converts the position. */
  press(readSample: () => Sample, kind: PointerKind): void {
    const settings = this.#host.settings();
    if (this.#drawing === null || this.#closed || settings.clear_on_press) this.#newDrawing(settings);
    const drawing = this.#drawing!;
    const sample = readSample();
    this.#pointerKind = kind;
    this.#sampler = new FrameSampler(settings.fps);
    drawing.beginPath(kind);
    drawing.addSample(sample);
    this.#pointer = sample;
    this.#pushFrame(this.#sampler.press(sample));
    this.#startLoop();
  }

  move(samples: readonly Sample[]): void {
    const drawing = this.#drawing;
    if (drawing === null || !this.#sampler.pressed) return;
    for (const sample of samples) {
      drawing.addSample(sample);
      this.#sampler.hold(sample);
      if (this.#feedsSamples) this.#pushFrame(sample);
    }
    this.#pointer = samples[samples.length - 1] ?? this.#pointer;
  }

  release(sample: Sample): void {
    const drawing = this.#drawing;
    const simplifier = this.#simplifier;
    if (drawing === null || simplifier === null || !this.#sampler.pressed) return;
    drawing.addSample(sample);
    const last = this.#sampler.release(sample);
    this.#pushFrame(this.#feedsSamples ? sample : last);
    for (const segment of simplifier.end()) this.#handleSegment(segment);
    this.#pointer = null;
    this.#view.flush();
    this.#view.clearLive();
    this.#host.released();
  }

  /**
   * Ends the path being drawn where the pointer is now (Stop, or Esc with the pen down): the
   * stroke under way is not sent, and the pointer draws nothing more until it is lifted and
   * pressed again. The samples drawn so far stay in the drawing.
   */
  endPath(): void {
    const drawing = this.#drawing;
    const pointer = this.#pointer;
    if (drawing === null || pointer === null || !this.#sampler.pressed) return;
    this.#sampler.release(pointer);
    // The stroke under way dies with its simplifier: a new one for the next path.
    this.#simplifier = makeSimplifier(drawing.params);
    this.#pointer = null;
    this.#view.flush();
    this.#view.clearLive();
    this.#host.released();
  }

  /** Empties the canvas; the next press starts a new drawing. Not while drawing. */
  clear(): void {
    if (this.#sampler.pressed) return;
    this.#drawing = null;
    this.#simplifier = null;
    this.#closed = false;
    this.#view.setDrawing(null);
    this.#host.changed(null);
  }

  /** Keeps the drawing on the canvas but starts a new one at the next press. */
  close(): void {
    this.#closed = true;
  }

  /** Takes back the last path; false when there is none (or while drawing). */
  undo(): boolean {
    const drawing = this.#drawing;
    if (this.#sampler.pressed || drawing === null || !drawing.removeLastPath()) return false;
    if (drawing.paths.length === 0) {
      this.clear();
      return true;
    }
    this.#view.setDrawing(drawing);
    this.#host.changed(drawing);
    return true;
  }

  /** Shows `drawing` (loaded, re-simplified or played again) as the current one; drawing on adds to it. */
  adopt(drawing: Drawing): void {
    if (this.#sampler.pressed) return;
    this.#drawing = drawing;
    this.#simplifier = makeSimplifier(drawing.params);
    this.#closed = false;
    this.#view.setDrawing(drawing);
    this.#host.changed(drawing);
  }

  /** The broker acknowledged `stroke`: drawn solid. */
  acked(stroke: Stroke): void {
    const drawing = this.#drawing;
    if (drawing === null || stroke.drawing !== drawing.id || stroke.seq == null) return;
    const drawn = drawing.markAcked(stroke.seq);
    if (drawn === undefined) return;
    this.#view.markSent(drawn);
    this.#scheduleFlush();
  }

  /** Stroke `seq` of this drawing was not felt (`why`, fates.ts): marked on the canvas. */
  refused(seq: number, why: Unfelt = "refused"): void {
    const drawn = this.#drawing?.markRefused(seq, why);
    if (drawn === undefined) return;
    this.#view.markRejected(drawn);
    this.#scheduleFlush();
  }

  /**
   * The drawing's paths cut again under the settings now, as a new drawing shown at once (not
   * sent: Play again sends it); null when there is nothing to cut, or while drawing.
   */
  recut(): Drawing | null {
    const drawing = this.#drawing;
    if (this.#sampler.pressed || drawing === null || drawing.paths.length === 0) return null;
    const settings = this.#host.settings();
    const params = simplifierParams(settings, this.#host.grid(), {
      width_px: drawing.params.canvas_width_px,
      height_px: drawing.params.canvas_height_px,
    });
    const again = new Drawing(newDrawingId(), params);
    const pieces = simplifyPaths(params, drawing.paths);
    drawing.paths.forEach((samples, path) => {
      again.beginPath(drawing.pointerKinds[path] ?? "mouse");
      again.paths[path]!.push(...samples);
      for (const piece of pieces) {
        if (piece.path === path) again.addSegment(piece.segment, settings.intensity);
      }
    });
    this.adopt(again);
    return again;
  }

  #pushFrame(frame: Sample): void {
    this.#drawing!.addFrame(frame);
    for (const segment of this.#simplifier!.push(frame)) this.#handleSegment(segment);
  }

  #handleSegment(segment: Segment): void {
    const drawing = this.#drawing!;
    const drawn = drawing.addSegment(segment, this.#intensity(segment));
    if (drawn.stroke !== null) {
      this.#host.send(drawn.stroke);
      this.#host.changed(drawing);
    }
  }

  #intensity(segment: Segment): number {
    const { intensity, pressure_sets_intensity } = this.#host.settings();
    if (!pressure_sets_intensity || this.#pointerKind !== "pen") return intensity;
    const pressure = this.#drawing!.meanPressure(segment.start_ms, segment.end_ms);
    const scale = 10 ** INTENSITY_DECIMALS;
    return Math.round(intensity * pressure * scale) / scale;
  }

  #newDrawing(settings: Settings): void {
    const params = simplifierParams(settings, this.#host.grid(), this.#view.area);
    this.#simplifier = makeSimplifier(params);
    this.#drawing = new Drawing(newDrawingId(), params);
    this.#view.setDrawing(this.#drawing);
    this.#host.changed(this.#drawing);
  }

  /** The animation loop runs only while a pointer is down: an idle page costs nothing. */
  #startLoop(): void {
    if (this.#loopRunning) return;
    this.#loopRunning = true;
    const step = (tMs: number): void => {
      const started = performance.now();
      const frame = this.#sampler.tick(tMs);
      if (frame !== null && !this.#feedsSamples) this.#pushFrame(frame);
      this.#view.flush();
      this.#view.drawLive(this.#simplifier?.lineStart ?? null, this.#pointer);
      this.#frameWorkMs.push(performance.now() - started);
      if (this.#frameWorkMs.length > FRAME_STATS_SIZE) this.#frameWorkMs.shift();
      if (this.#sampler.pressed) requestAnimationFrame(step);
      else this.#loopRunning = false;
    };
    requestAnimationFrame(step);
  }

  /** Ink outside a path (acknowledgements, refusals): drawn at the next frame, once. */
  #scheduleFlush(): void {
    if (this.#loopRunning || this.#flushScheduled) return;
    this.#flushScheduled = true;
    requestAnimationFrame(() => {
      this.#flushScheduled = false;
      this.#view.flush();
    });
  }

  // ---- for the benchmark -------------------------------------------------------------------

  /** Work done in each recent animation frame, in ms. */
  frameWorkMs(): number[] {
    return [...this.#frameWorkMs];
  }

  resetFrameStats(): void {
    this.#frameWorkMs.length = 0;
  }

  /**
   * Draws `strokes` strokes at once through the same pipeline as a pointer (a
   * zigzag, fed frame by frame with synthetic times), into the current drawing.
   * For the benchmark: a drawing of 10,000 strokes without drawing for minutes.
   */
  drawSynthetic(strokes: number): number {
    if (this.#sampler.pressed || strokes <= 0) return this.#drawing?.strokeCount ?? 0;
    const settings = this.#host.settings();
    const { width_px: width, height_px: height } = this.#view.area;
    // A zigzag between the top and bottom of the area: every corner turns far more than the
    // angle rule's max angle (and strays far beyond max_error), so every leg becomes one stroke.
    const vertex = (i: number): [number, number] => [
      width * (0.05 + 0.9 * ((i * 0.1373) % 1)),
      height * (i % 2 === 0 ? 0.1 : 0.9),
    ];
    const legFrames = Math.max(2, settings.check_frames) * 3;
    const periodMs = 1000 / settings.fps;
    let t = performance.now();
    const [x0, y0] = vertex(0);
    this.press(() => ({ t_ms: t, x: x0, y: y0, pressure: 0.5 }), "mouse");
    const drawing = this.#drawing!;
    const target = drawing.strokeCount + strokes;
    let last: Sample = { t_ms: t, x: x0, y: y0, pressure: 0.5 };
    for (let leg = 0; drawing.strokeCount < target - 1; leg++) {
      const [ax, ay] = vertex(leg);
      const [bx, by] = vertex(leg + 1);
      for (let k = 1; k <= legFrames; k++) {
        t += periodMs;
        last = {
          t_ms: t,
          x: ax + ((bx - ax) * k) / legFrames,
          y: ay + ((by - ay) * k) / legFrames,
          pressure: 0.5,
        };
        drawing.addSample(last);
        this.#pushFrame(last);
      }
    }
    this.release({ ...last, t_ms: t + periodMs });
    return drawing.strokeCount;
  }
}
