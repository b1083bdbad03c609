/**
 * The window simplifier's least-squares core (`least_squares` on), ported from the Python
 * reference `feelmysign/simplify/fit.py`, which it reproduces exactly on the shared vectors in
 * `testdata/window/` (the method and its sources are described there and in docs/research.md).
 *
 * At each sample it keeps, over the samples since the last stroke it let go (the anchor), the
 * polyline through drawn samples with the least integral square error among those whose strokes
 * all keep every sample within `max_error` and last at least the sleeve's floor (`floor_ms`, or
 * `min_duration_ms` if longer); where no stroke lasting the floor keeps the bound, the fewest
 * briefer ones. Each sample's best polyline from the anchor is found once, from those of the
 * samples before it, and each piece's error comes from running sums. A stroke is let go, its first
 * vertex after the anchor final, once the pen has drawn `lookahead_ms` past that vertex or that
 * stroke lasts more than `max_stroke_ms`; at release the polyline to the last sample is let go
 * whole. Kept from the window: the mapping, times that never run backwards, the rest rule and the
 * work cap (`max_window`).
 *
 * The float operations are the reference's, in its order (left to right), so every result is the
 * same to the last bit; ties break as there (the fewest pieces briefer than the floor, then the
 * least error, then the earliest start).
 */
import { distanceSq } from "./distance";
import { CanvasMapping } from "./mapping";
import { finishSegment, type Point, type Sample, type Segment } from "./segment";
import { restRadius } from "./rest";
import { checkWindowParams, type WindowParams } from "./window-params";

const NO_SEGMENTS: readonly Segment[] = Object.freeze([]);

/** Running sums of x, y, x^2, y^2 and xy over samples (each of length n + 1, from 0). */
export interface RunningSums {
  readonly sx: readonly number[];
  readonly sy: readonly number[];
  readonly sxx: readonly number[];
  readonly syy: readonly number[];
  readonly sxy: readonly number[];
}

/**
 * The integral square error of the piece xs[start] -> xs[end]: the sum of the squared distances
 * of samples start..end to the line through its ends (to its start where they coincide), from the
 * running sums of the coordinates relative to the anchor (ax, ay). Never below 0 (rounding); a NaN
 * gives 0. Python `fit.piece_error`.
 */
export function pieceError(
  xs: readonly number[],
  ys: readonly number[],
  ax: number,
  ay: number,
  sums: RunningSums,
  start: number,
  end: number,
): number {
  const { sx: sx_, sy: sy_, sxx: sxx_, syy: syy_, sxy: sxy_ } = sums;
  const count = end + 1 - start;
  const px = xs[start]! - ax;
  const py = ys[start]! - ay;
  const dx = xs[end]! - ax - px;
  const dy = ys[end]! - ay - py;
  const sx = sx_[end + 1]! - sx_[start]!;
  const sy = sy_[end + 1]! - sy_[start]!;
  // Sums of (x - px)^2, (y - py)^2 and (x - px)(y - py) over the piece's samples.
  const cxx = sxx_[end + 1]! - sxx_[start]! - 2 * px * sx + count * px * px;
  const cyy = syy_[end + 1]! - syy_[start]! - 2 * py * sy + count * py * py;
  const cxy = sxy_[end + 1]! - sxy_[start]! - px * sy - py * sx + count * px * py;
  const lengthSq = dx * dx + dy * dy;
  const error = lengthSq > 0 ? (dx * dx * cyy + dy * dy * cxx - 2 * dx * dy * cxy) / lengthSq : cxx + cyy;
  return error > 0 ? error : 0;
}

/**
 * The least-squares core: the pieces to merge (`WindowSimplifier` merges them), as `WindowCore`
 * gives its own.
 */
export class FitCore {
  readonly params: WindowParams;
  readonly #maxErrorSq: number;
  /** The sleeve's floor: the larger of floor_ms and min_duration_ms. */
  readonly #floorMs: number;
  readonly #restSq: number;
  readonly #mapping: CanvasMapping;
  readonly #limits: { readonly min_length: number; readonly min_duration_ms: number };
  // The samples since the anchor, the anchor first: grid points, times, samples.
  #xs: number[] = [];
  #ys: number[] = [];
  #ts: number[] = [];
  #samples: Sample[] = [];
  // Running sums of x, y, x^2, y^2 and xy over the samples, relative to the anchor's point.
  readonly #sx: number[] = [0];
  readonly #sy: number[] = [0];
  readonly #sxx: number[] = [0];
  readonly #syy: number[] = [0];
  readonly #sxy: number[] = [0];
  readonly #sums: RunningSums;
  // Each sample's best polyline from the anchor (every piece at the floor, where the bound lets it
  // be): its squared error, its count of pieces briefer than the floor and its last vertex.
  readonly #best: number[] = [];
  readonly #brief: number[] = [];
  readonly #before: number[] = [];
  /** A piece's error per start, for the sample being placed (reused), and that sample. */
  readonly #errors: number[] = [];
  #errorsEnd = -1;
  /** Per sample, the sample that last broke the bound of a piece from it (-1: none yet). */
  #broke: number[] = [];
  #emittedInPath = false;
  /** While the pen rests (`rest_ms`): the point it rests at; each sample near it retimes the anchor. */
  #resting = false;
  #restX = 0;
  #restY = 0;
  /** Whether the last push found the pen resting (the strokes before the rest are final). */
  rested = false;
  /** The last sample pushed, as taken: its time (never before the one before) and grid point. */
  takenMs = 0;
  takenX = 0;
  takenY = 0;

  constructor(params: WindowParams) {
    checkWindowParams(params);
    this.params = params;
    this.#maxErrorSq = params.max_error * params.max_error;
    this.#floorMs = Math.max(params.floor_ms, params.min_duration_ms);
    this.#mapping = CanvasMapping.fromParams(params);
    const rest = restRadius(params, this.#mapping);
    this.#restSq = rest * rest;
    this.#limits = { min_length: params.min_length, min_duration_ms: params.min_duration_ms };
    this.#sums = { sx: this.#sx, sy: this.#sy, sxx: this.#sxx, syy: this.#syy, sxy: this.#sxy };
  }

  /** True between the first sample of a path and `end`. */
  get drawing(): boolean {
    return this.#xs.length > 0;
  }

  /** Where the stroke being drawn starts (canvas pixels), for showing it; null between paths. */
  get lineStart(): Sample | null {
    return this.#samples.length > 0 ? this.#samples[0]! : null;
  }

  /** The last sample taken, as taken: its time (never before the one before) and grid point. */
  lastSample(): { readonly t_ms: number; readonly point: Point } {
    return { t_ms: this.takenMs, point: [this.takenX, this.takenY] };
  }

  /** The time of the last sample pushed, as taken (0 before any). */
  pointerMs(): number {
    return this.takenMs;
  }

  /** One pointer sample while the pointer is down; the first of a path is the press. */
  push(input: Sample): readonly Segment[] {
    const ts = this.#ts;
    let sample = input;
    // Times never run backwards (two event sources' clocks): an earlier sample takes the last time.
    if (ts.length > 0 && input.t_ms < ts[ts.length - 1]!) {
      sample = { t_ms: ts[ts.length - 1]!, x: input.x, y: input.y, pressure: input.pressure };
    }
    const x = this.#mapping.gridX(sample.x);
    const y = this.#mapping.gridY(sample.y);
    const t = sample.t_ms;
    this.takenMs = t;
    this.takenX = x;
    this.takenY = y;
    this.rested = false;
    if (ts.length === 0) {
      this.#emittedInPath = false;
      this.#resting = false;
      this.#restartAt([x], [y], [t], [sample]);
      return NO_SEGMENTS;
    }
    if (this.#resting) {
      const dx = x - this.#restX;
      const dy = y - this.#restY;
      if (ts.length === 1 && dx * dx + dy * dy <= this.#restSq) {
        this.#retime(t);
        return NO_SEGMENTS;
      }
      this.#resting = false;
    }
    const out: Segment[] = [];
    this.#append(x, y, t, sample);
    if (this.#rests(out)) return out;
    this.#letGo(out);
    return out.length > 0 ? out : NO_SEGMENTS;
  }

  /**
   * Release: the best polyline to the last sample, every stroke at the floor (a tap gives one
   * stroke, dropped, of length 0).
   */
  end(): Segment[] {
    const out: Segment[] = [];
    const count = this.#xs.length;
    this.#resting = false;
    if (count === 0) return out;
    if (count === 1) {
      if (!this.#emittedInPath) out.push(this.#piece(0, 0));
    } else {
      this.#polyline(count - 1, out);
    }
    this.#xs = [];
    this.#ys = [];
    this.#ts = [];
    this.#samples = [];
    return out;
  }

  // --- the polyline ----------------------------------------------------------------------------

  /** The samples since a new anchor (xs[0]): running sums and best polylines again. */
  #restartAt(xs: number[], ys: number[], ts: number[], samples: Sample[], broke?: number[]): void {
    this.#broke = broke ?? xs.map(() => -1);
    this.#xs = xs;
    this.#ys = ys;
    this.#ts = ts;
    this.#samples = samples;
    for (const sums of [this.#sx, this.#sy, this.#sxx, this.#syy, this.#sxy]) sums.length = 1;
    this.#best.length = 0;
    this.#brief.length = 0;
    this.#before.length = 0;
    this.#best.push(0);
    this.#brief.push(0);
    this.#before.push(-1);
    this.#errorsEnd = -1;
    const ax = xs[0]!;
    const ay = ys[0]!;
    this.#addSums(0, 0);
    for (let k = 1; k < xs.length; k++) {
      this.#addSums(xs[k]! - ax, ys[k]! - ay);
      this.#place(k);
    }
  }

  #addSums(rx: number, ry: number): void {
    const sx = this.#sx;
    const sy = this.#sy;
    const sxx = this.#sxx;
    const syy = this.#syy;
    const sxy = this.#sxy;
    const last = sx.length - 1;
    sx.push(sx[last]! + rx);
    sy.push(sy[last]! + ry);
    sxx.push(sxx[last]! + rx * rx);
    syy.push(syy[last]! + ry * ry);
    sxy.push(sxy[last]! + rx * ry);
  }

  #append(x: number, y: number, t: number, sample: Sample): void {
    const xs = this.#xs;
    const ys = this.#ys;
    xs.push(x);
    ys.push(y);
    this.#ts.push(t);
    this.#samples.push(sample);
    this.#broke.push(-1);
    this.#addSums(x - xs[0]!, y - ys[0]!);
    this.#place(xs.length - 1);
  }

  /**
   * Each piece's error to sample k, from every start it may have (into `#errors`, kept for the
   * sample until the next): the first start.
   */
  #errorsTo(k: number): number {
    let low = Math.max(0, k - this.params.max_window);
    // No piece outlasts the latency cap, but one between two samples drawn further apart.
    const capMs = this.params.max_stroke_ms;
    if (capMs > 0) {
      const ts = this.#ts;
      const tK = ts[k]!;
      while (low < k - 1 && tK - ts[low]! > capMs) low++;
    }
    if (this.#errorsEnd === k) return low;
    const xs = this.#xs;
    const ys = this.#ys;
    const ax = xs[0]!;
    const ay = ys[0]!;
    const errors = this.#errors;
    const sums = this.#sums;
    errors.length = 0;
    for (let i = low; i < k; i++) errors.push(pieceError(xs, ys, ax, ay, sums, i, k));
    this.#errorsEnd = k;
    return low;
  }

  /**
   * The best start of the last piece to sample k: the fewest pieces briefer than the floor (the
   * last counted only when `closed`), then the least squared error, then the earliest start; among
   * the pieces that keep the bound (the piece from k - 1 always does). Where the first choice's
   * bound breaks, the other starts are tested in the same order, sorted once (the totals are never
   * NaN). Python `FitCore._choose`.
   */
  #choose(k: number, low: number, closed: boolean): number {
    const best = this.#best;
    const brief = this.#brief;
    const errors = this.#errors;
    const ts = this.#ts;
    const floorMs = this.#floorMs;
    const tK = ts[k]!;
    let chosen = -1;
    let chosenCount = 0;
    let chosenTotal = 0;
    for (let i = low; i < k; i++) {
      const total = best[i]! + errors[i - low]!;
      let count = brief[i]!;
      if (closed && tK - ts[i]! < floorMs) count += 1;
      if (chosen < 0 || count < chosenCount || (count === chosenCount && total < chosenTotal)) {
        chosen = i;
        chosenCount = count;
        chosenTotal = total;
      }
    }
    if (chosen === k - 1 || this.#keeps(chosen, k)) return chosen;
    const starts: number[] = [];
    const counts: number[] = [];
    const totals: number[] = [];
    for (let i = low; i < k; i++) {
      counts.push(brief[i]! + (closed && tK - ts[i]! < floorMs ? 1 : 0));
      totals.push(best[i]! + errors[i - low]!);
      if (i !== chosen) starts.push(i);
    }
    starts.sort((a, b) => {
      const ca = counts[a - low]!;
      const cb = counts[b - low]!;
      if (ca !== cb) return ca - cb;
      const ta = totals[a - low]!;
      const tb = totals[b - low]!;
      if (ta < tb) return -1;
      if (tb < ta) return 1;
      return a - b;
    });
    for (const start of starts) {
      if (start === k - 1 || this.#keeps(start, k)) return start;
    }
    return k - 1; // (never: the piece from k - 1 is among the starts)
  }

  /** Sample k's best polyline from the anchor, every piece closed (at the floor). */
  #place(k: number): void {
    const low = this.#errorsTo(k);
    const i = this.#choose(k, low, true);
    const total = this.#best[i]! + this.#errors[i - low]!;
    const count = this.#brief[i]! + (this.#ts[k]! - this.#ts[i]! < this.#floorMs ? 1 : 0);
    this.#best.push(total);
    this.#brief.push(count);
    this.#before.push(i);
  }

  /**
   * Whether every sample between xs[start] and xs[end] lies within max_error of the segment between
   * them: the sample that broke the last piece tested from `start` first, then the samples coarse
   * to fine (the answer is the same in any order). Python `FitCore._keeps`.
   */
  #keeps(start: number, end: number): boolean {
    const xs = this.#xs;
    const ys = this.#ys;
    const ax = xs[start]!;
    const ay = ys[start]!;
    const ex = xs[end]!;
    const ey = ys[end]!;
    const limitSq = this.#maxErrorSq;
    const broke = this.#broke[start]!;
    if (start < broke && broke < end && distanceSq(xs[broke]!, ys[broke]!, ax, ay, ex, ey) > limitSq) {
      return false;
    }
    const span = end - start;
    let step = 1;
    while (step * 2 < span) step *= 2;
    for (; step > 0; step = Math.floor(step / 2)) {
      for (let m = start + step; m < end; m += 2 * step) {
        if (distanceSq(xs[m]!, ys[m]!, ax, ay, ex, ey) > limitSq) {
          this.#broke[start] = m;
          return false;
        }
      }
    }
    return true;
  }

  /** Lets go the best polyline (every piece closed) to sample `last`, into `out`. */
  #polyline(last: number, out: Segment[]): void {
    const vertices = [last];
    while (vertices[vertices.length - 1] !== 0) vertices.push(this.#before[vertices[vertices.length - 1]!]!);
    vertices.reverse();
    for (let v = 1; v < vertices.length; v++) out.push(this.#piece(vertices[v - 1]!, vertices[v]!));
  }

  #piece(a: number, b: number): Segment {
    this.#emittedInPath = true;
    const xs = this.#xs;
    const ys = this.#ys;
    const ts = this.#ts;
    // The pointer's time: the last sample taken (the reference's `_pointer`, always set here).
    return finishSegment([xs[a]!, ys[a]!], [xs[b]!, ys[b]!], ts[a]!, ts[b]!, this.takenMs, this.#limits);
  }

  /** Sample k anchors the next stroke; the samples after it are taken again. */
  #from(k: number): void {
    const broke = this.#broke.slice(k).map((m) => (m > k ? m - k : -1));
    this.#restartAt(this.#xs.slice(k), this.#ys.slice(k), this.#ts.slice(k), this.#samples.slice(k), broke);
  }

  /**
   * Lets go each stroke that is final, into `out`: its end drawn `lookahead_ms` ago, or the stroke
   * longer than the latency cap.
   */
  #letGo(out: Segment[]): void {
    const capMs = this.params.max_stroke_ms;
    const lookaheadMs = this.params.lookahead_ms;
    const floorMs = this.#floorMs;
    for (;;) {
      const ts = this.#ts;
      const j = ts.length - 1;
      if (ts[j]! - ts[0]! < floorMs) return;
      const low = this.#errorsTo(j);
      const last = this.#choose(j, low, false);
      if (last === 0) {
        // One stroke from the anchor: cut by the latency cap at the sample before.
        if (
          capMs > 0 &&
          ts[j]! - ts[0]! > capMs &&
          j >= 2 &&
          ts[j - 1]! - ts[0]! >= floorMs &&
          this.#keeps(0, j - 1)
        ) {
          out.push(this.#piece(0, j - 1));
          this.#from(j - 1);
          continue;
        }
        return;
      }
      const before = this.#before;
      let vertex = last;
      while (before[vertex] !== 0) vertex = before[vertex]!;
      if (ts[j]! - ts[vertex]! < lookaheadMs && !(capMs > 0 && ts[vertex]! - ts[0]! > capMs)) return;
      out.push(this.#piece(0, vertex));
      this.#from(vertex);
    }
  }

  // --- rests -----------------------------------------------------------------------------------

  #retime(tMs: number): void {
    this.#ts[0] = tMs;
    const anchor = this.#samples[0]!;
    this.#samples[0] = { t_ms: tMs, x: anchor.x, y: anchor.y, pressure: anchor.pressure };
  }

  /**
   * Whether the pen has rested `rest_ms` at the newest sample: its samples of the last `rest_ms` or
   * more all lie within the rest radius of it. The best polyline to the rest's first sample is let
   * go, into `out`; the rest is not played; the anchor waits at that sample for the pen to move on.
   */
  #rests(out: Segment[]): boolean {
    const restMs = this.params.rest_ms;
    const xs = this.#xs;
    const ys = this.#ys;
    const ts = this.#ts;
    const j = ts.length - 1;
    const t = ts[j]!;
    if (restMs <= 0 || t - ts[0]! < restMs) return false;
    const x = xs[j]!;
    const y = ys[j]!;
    const restSq = this.#restSq;
    let start = j;
    while (start > 0) {
      const dx = xs[start - 1]! - x;
      const dy = ys[start - 1]! - y;
      if (!(dx * dx + dy * dy <= restSq)) break; // (not ">": a NaN ends the rest too)
      start -= 1;
    }
    if (start === j || t - ts[start]! < restMs) return false;
    if (start > 0) this.#polyline(start, out);
    this.#restartAt([xs[start]!], [ys[start]!], [ts[start]!], [this.#samples[start]!]);
    this.#retime(t);
    this.#restX = x;
    this.#restY = y;
    this.#resting = true;
    this.rested = true;
    return true;
  }
}
