/**
 * The window simplifier as first written: every sample tested at every new one, no shortcuts.
 * A reference for the property test that `src/simplify/window.ts`, which keeps its samples in
 * flat arrays and skips tests a bound proves needless, gives the same strokes to the last bit.
 * It is the simplifier as of its straight-line rule (a line's end kept on the grid), with the
 * canvas-to-grid mapping computed as first written (`toGrid`). Kept in the tests, not in the page.
 */
import type { CanvasMappingOptions } from "../src/simplify/mapping";
import { finishSegment, type Point, type Sample, type Segment } from "../src/simplify/segment";
import { checkWindowParams, type WindowParams } from "../src/simplify/window-params";

/**
 * The latency cap cuts at a feature drawn at least this share of max_stroke_ms after the
 * stroke's start, so that the stroke it ends is not too brief to be felt in its drawn time.
 */
const CAP_FEATURE_SHARE = 0.5;
/**
 * A stroke whose samples all lie within this share of max_error of its chord is straight
 * (rounding, not a feature): the cap cuts it at its last sample, as late as it can.
 */
const STRAIGHT = 1e-6;
/**
 * A stroke the latency cap ends is a line when all its samples lie within this share of
 * max_error of it; the stroke after it then goes on along that line where the bound allows, by
 * moving its end at most this share of max_error off its drawn sample (no drift along a bend).
 */
const LINE_SHARE = 0.25;
/**
 * A pen rests while its samples stay within this share of min_length of one point (never farther
 * than half of max_error).
 */
const REST_SHARE = 0.25;
/** ... and never farther than a pen this slow covers in rest_ms (canvas pixels per ms). */
const REST_SPEED_PX_PER_MS = 0.015;

interface Drawn {
  readonly sample: Sample;
  /** The sample in grid units. */
  readonly point: Point;
}

export class ReferenceWindowSimplifier {
  readonly params: WindowParams;
  readonly #maxErrorSq: number;
  readonly #mapping: CanvasMappingOptions;
  /** The samples of the stroke being drawn: its anchor first, then every sample since. */
  #window: Drawn[] = [];
  #pointer: Sample | null = null;
  #emittedInPath = false;
  /**
   * The direction of the stroke the latency cap ended last, while the next one may go on along
   * it (null at a path's start and after any other cut).
   */
  #line: Point | null = null;
  /** While the pen rests at the anchor: each sample near it moves the anchor's time. */
  #resting = false;
  /** Whether the last push found the pen resting. */
  rested = false;
  /** The last sample pushed, as taken (its time never before the one before, its grid point). */
  taken: { readonly t_ms: number; readonly point: Point } = { t_ms: 0, point: [0, 0] };
  readonly #restSq: number;

  constructor(params: WindowParams) {
    checkWindowParams(params);
    this.params = params;
    this.#maxErrorSq = params.max_error * params.max_error;
    // The canvas's tighter scale (grid units per pixel), from the axes that have an extent.
    const scales = [
      [params.columns - 1, params.canvas_width_px],
      [params.rows - 1, params.canvas_height_px],
    ]
      .filter(([extent]) => extent! > 0)
      .map(([extent, size]) => extent! / size!);
    const scale = scales.length > 0 ? Math.min(...scales) : 0;
    const rest = Math.min(
      REST_SHARE * params.min_length,
      0.5 * params.max_error,
      REST_SPEED_PX_PER_MS * params.rest_ms * scale,
    );
    this.#restSq = rest * rest;
    this.#mapping = {
      width_px: params.canvas_width_px,
      height_px: params.canvas_height_px,
      columns: params.columns,
      rows: params.rows,
      stretch: params.stretch,
    };
  }

  /** True between the first sample of a path and `end`. */
  get drawing(): boolean {
    return this.#window.length > 0;
  }

  /** Where the stroke being drawn starts (canvas pixels), for showing it; null between paths. */
  get lineStart(): Sample | null {
    return this.#window[0]?.sample ?? null;
  }

  /** One pointer sample while the pointer is down; the first of a path is the press. */
  push(input: Sample): Segment[] {
    const previous = this.#window[this.#window.length - 1];
    // Times never run backwards (two event sources' clocks): an earlier sample takes the last time.
    const sample =
      previous !== undefined && input.t_ms < previous.sample.t_ms
        ? { ...input, t_ms: previous.sample.t_ms }
        : input;
    this.#pointer = sample;
    const current: Drawn = { sample, point: toGrid(this.#mapping, sample.x, sample.y) };
    this.taken = { t_ms: sample.t_ms, point: current.point };
    this.rested = false;
    if (this.#window.length === 0) {
      this.#window = [current];
      this.#emittedInPath = false;
      this.#line = null;
      this.#resting = false;
      return [];
    }
    const out: Segment[] = [];
    this.#add(current, out);
    return out;
  }

  /** Release: the rest of the path as one stroke (a tap gives one, dropped, of length 0). */
  end(): Segment[] {
    const window = this.#window;
    this.#window = [];
    this.#resting = false;
    const first = window[0];
    const last = window[window.length - 1];
    if (first === undefined || last === undefined) return [];
    // The last sample already ends a stroke (a cut at the work cap).
    if (window.length === 1 && this.#emittedInPath) return [];
    return [this.#finish(first, this.#continued(window, window.length - 1))];
  }

  /** `current` joins the stroke being drawn, cutting it first where it must. */
  #add(current: Drawn, out: Segment[]): void {
    // A stack: the next sample to take is last. A cut gives back the samples after it.
    const pending: Drawn[] = [current];
    for (let item = pending.pop(); item !== undefined; item = pending.pop()) {
      let window = this.#window;
      let anchor = window[0]!;
      const capMs = this.params.max_stroke_ms;
      if (this.#resting) {
        if (window.length === 1 && squaredDistance(item.point, anchor.point) <= this.#restSq) {
          this.#window = [retimed(anchor, item.sample.t_ms)];
          continue;
        }
        this.#resting = false;
      }
      if (
        capMs > 0 &&
        window.length > 1 &&
        item.sample.t_ms - anchor.sample.t_ms > capMs &&
        !this.#sendable(anchor, window[window.length - 1]!)
      ) {
        anchor = window[0] = retimed(anchor, item.sample.t_ms - capMs);
      }
      if (
        capMs > 0 &&
        window.length > 1 &&
        item.sample.t_ms - anchor.sample.t_ms > capMs &&
        this.#sendable(anchor, window[window.length - 1]!)
      ) {
        const cut = this.#capCut(window);
        const vertex = this.#continued(window, cut);
        out.push(this.#finish(anchor, vertex));
        this.#line = this.#lineOf(window, cut, vertex);
        if (cut < window.length - 1) {
          pending.push(item);
          pending.push(...window.slice(cut + 1).reverse());
          this.#window = [vertex];
          continue;
        }
        window = this.#window = [vertex];
      }
      if (!this.#fits(window, 1, window.length, item.point, this.#bendSq(window, item.point))) {
        let cut = this.#feature(window, item.point);
        // A piece briefer than the floor, where the window holds a longer one: the feature among
        // the samples drawn at least the floor after the anchor.
        const floorMs = Math.max(this.params.floor_ms, this.params.min_duration_ms);
        const floorEndMs = window[0]!.sample.t_ms + floorMs;
        if (window[cut]!.sample.t_ms < floorEndMs && floorEndMs <= window[window.length - 1]!.sample.t_ms) {
          const later = window.findIndex((drawn, i) => i > 0 && drawn.sample.t_ms >= floorEndMs);
          cut = this.#feature(window, item.point, later);
        }
        out.push(this.#finish(window[0]!, window[cut]!));
        this.#line = null;
        pending.push(item);
        pending.push(...window.slice(cut + 1).reverse());
        this.#window = [window[cut]!];
        continue;
      }
      window.push(item);
      if (this.#rests(window, out)) continue;
      if (window.length - 1 >= this.params.max_window) {
        out.push(this.#finish(window[0]!, item));
        this.#line = null;
        this.#window = [item];
      }
    }
  }

  /**
   * Where the latency cap cuts: at a feature in the stroke's later part, else at
   * its end. The feature is the sample farthest from the chord anchor -> last
   * sample among those drawn at least `CAP_FEATURE_SHARE` x max_stroke_ms after
   * the anchor whose own stroke keeps the bound and is long enough to send; if it
   * lies on the chord (a straight stroke, to `STRAIGHT`), at the last sample.
   */
  #capCut(window: readonly Drawn[]): number {
    const anchor = window[0]!;
    const last = window[window.length - 1]!;
    const earliest = anchor.sample.t_ms + CAP_FEATURE_SHARE * this.params.max_stroke_ms;
    let first = 1;
    while (first < window.length - 1 && window[first]!.sample.t_ms < earliest) first++;
    const cut = this.#feature(window, last.point, first);
    const straight = STRAIGHT * this.params.max_error;
    const farSq = distanceSq(window[cut]!.point, anchor.point, last.point);
    const bends = farSq > straight * straight;
    return bends && this.#sendable(anchor, window[cut]!) ? cut : window.length - 1;
  }

  /**
   * Where a stroke that the latency cap or the release ends, ending at window[cut], ends.
   * After a stroke the latency cap ended, the stroke that follows it goes on along the same
   * line when it can: its end is window[cut] projected onto that line, if it lies on the grid,
   * every sample up to window[cut] keeps the bound to the projected end and the stroke is still
   * long enough to send; else window[cut] itself. The cap cuts a drawn line, not a drawn corner, so a
   * straight line cut into strokes stays one straight line.
   */
  #continued(window: readonly Drawn[], cut: number): Drawn {
    const at = window[cut]!;
    if (this.#line === null) return at;
    const [ux, uy] = this.#line;
    const [ax, ay] = window[0]!.point;
    const along = (at.point[0] - ax) * ux + (at.point[1] - ay) * uy;
    if (along <= 0) return at;
    const end: Drawn = { sample: at.sample, point: [ax + along * ux, ay + along * uy] };
    const xExtent = this.params.columns - 1;
    const yExtent = this.params.rows - 1;
    const [endX, endY] = end.point;
    // Off the grid: the sleeve would refuse it.
    if (!(0 <= endX && endX <= xExtent && 0 <= endY && endY <= yExtent)) return at;
    const limit = LINE_SHARE * this.params.max_error;
    if (distanceSq(at.point, end.point, end.point) > limit * limit) return at; // a bend, not noise
    if (!this.#sendable(window[0]!, end) || !this.#fits(window, 1, cut + 1, end.point)) return at;
    return end;
  }

  /**
   * The direction of the stroke window[0] -> end if it is a line (every sample up to
   * window[cut] within `LINE_SHARE` x max_error of it), else null.
   */
  #lineOf(window: readonly Drawn[], cut: number, end: Drawn): Point | null {
    const limit = LINE_SHARE * this.params.max_error;
    const anchor = window[0]!.point;
    for (let i = 1; i <= cut; i++) {
      if (distanceSq(window[i]!.point, anchor, end.point) > limit * limit) return null;
    }
    return direction(anchor, end.point);
  }

  /** Whether start -> end is long enough to send (the cap never cuts off a dropped stroke). */
  #sendable(start: Drawn, end: Drawn): boolean {
    const dx = end.point[0] - start.point[0];
    const dy = end.point[1] - start.point[1];
    return dx * dx + dy * dy >= this.params.min_length * this.params.min_length;
  }

  /**
   * Where to cut: the sample farthest from anchor -> end whose own stroke keeps
   * the bound (the last sample always does). Ties go to the later sample.
   */
  #feature(window: readonly Drawn[], end: Point, first = 1): number {
    const anchor = window[0]!.point;
    const ranked: { index: number; distanceSq: number }[] = [];
    for (let i = first; i < window.length; i++) {
      ranked.push({ index: i, distanceSq: distanceSq(window[i]!.point, anchor, end) });
    }
    ranked.sort((a, b) => b.distanceSq - a.distanceSq || b.index - a.index);
    for (const { index } of ranked) {
      if (this.#fits(window, 1, index, window[index]!.point)) return index;
    }
    return window.length - 1; // unreachable: the last sample fits by construction
  }

  /**
   * The squared bound a stroke window[0] -> end grows under: max_error's, or the bend rule's
   * (max_bend x its length, never under bend_floor) when that is less.
   */
  #bendSq(window: readonly Drawn[], end: Point): number {
    const bend = this.params.max_bend;
    if (bend <= 0 || window.length === 1) return this.#maxErrorSq;
    const anchor = window[0]!.point;
    const cx = end[0] - anchor[0];
    const cy = end[1] - anchor[1];
    const limit = Math.max(bend * Math.sqrt(cx * cx + cy * cy), this.params.bend_floor);
    return limit < this.params.max_error ? limit * limit : this.#maxErrorSq;
  }

  /** Whether window[first..stop) all lie within max_error (or sqrt(limitSq)) of window[0] -> end. */
  #fits(window: readonly Drawn[], first: number, stop: number, end: Point, limitSq?: number): boolean {
    const anchor = window[0]!.point;
    const boundSq = limitSq ?? this.#maxErrorSq;
    for (let i = first; i < stop; i++) {
      if (distanceSq(window[i]!.point, anchor, end) > boundSq) return false;
    }
    return true;
  }

  /** Whether the pen has rested rest_ms at the window's last sample (then as the page's). */
  #rests(window: readonly Drawn[], out: Segment[]): boolean {
    const restMs = this.params.rest_ms;
    const last = window[window.length - 1]!;
    const t = last.sample.t_ms;
    if (restMs <= 0 || t - window[0]!.sample.t_ms < restMs) return false;
    let start = window.length - 1;
    while (start > 0 && squaredDistance(window[start - 1]!.point, last.point) <= this.#restSq) start--;
    if (t - window[start]!.sample.t_ms < restMs) return false;
    if (start === 0) {
      this.#window = [retimed(window[0]!, t)];
    } else {
      out.push(this.#finish(window[0]!, { sample: window[start]!.sample, point: last.point }));
      this.#window = [last];
    }
    this.#line = null;
    this.#resting = true;
    this.rested = true;
    return true;
  }

  #finish(start: Drawn, end: Drawn): Segment {
    this.#emittedInPath = true;
    return finishSegment(
      start.point,
      end.point,
      start.sample.t_ms,
      end.sample.t_ms,
      this.#pointer ? this.#pointer.t_ms : end.sample.t_ms,
      this.params,
    );
  }
}

/** `drawn` at another time (the anchor's, while the pen rests or crawls). */
function retimed(drawn: Drawn, tMs: number): Drawn {
  return { sample: { ...drawn.sample, t_ms: tMs }, point: drawn.point };
}

function squaredDistance(a: Point, b: Point): number {
  const dx = a[0] - b[0];
  const dy = a[1] - b[1];
  return dx * dx + dy * dy;
}

/** The unit vector from `start` to `end` (null if they coincide). */
function direction(start: Point, end: Point): Point | null {
  const dx = end[0] - start[0];
  const dy = end[1] - start[1];
  const length = Math.sqrt(dx * dx + dy * dy);
  return length > 0 ? [dx / length, dy / length] : null;
}

/** Squared distance from `point` to the segment start -> end (its nearest point). */
function distanceSq(point: Point, start: Point, end: Point): number {
  const [ax, ay] = start;
  const dx = end[0] - ax;
  const dy = end[1] - ay;
  let qx = point[0] - ax;
  let qy = point[1] - ay;
  const lengthSq = dx * dx + dy * dy;
  if (lengthSq > 0) {
    // The nearest point of the segment: the projection, clamped onto it.
    const t = Math.min(Math.max((qx * dx + qy * dy) / lengthSq, 0), 1);
    qx = qx - t * dx;
    qy = qy - t * dy;
  }
  return qx * qx + qy * qy;
}

/** `CanvasMapping.toGrid` as first written: every term computed for every sample. */
function toGrid(options: CanvasMappingOptions, xPx: number, yPx: number): Point {
  const { width_px, height_px, columns, rows, stretch } = options;
  const scales: number[] = [];
  if (columns - 1 > 0) scales.push((columns - 1) / width_px);
  if (rows - 1 > 0) scales.push((rows - 1) / height_px);
  const scale = scales.length > 0 ? Math.min(...scales) : 0;
  const xExtent = columns - 1;
  const yExtent = rows - 1;
  let x: number;
  let y: number;
  if (stretch) {
    x = (xPx * xExtent) / width_px;
    y = (yPx * yExtent) / height_px;
  } else {
    x = (xExtent - width_px * scale) / 2 + xPx * scale;
    y = (yExtent - height_px * scale) / 2 + yPx * scale;
  }
  return [Math.min(Math.max(x, 0), xExtent), Math.min(Math.max(y, 0), yExtent)];
}
