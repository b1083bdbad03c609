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
import { chordDistanceSq } from "./distance";
import { CanvasMapping } from "./mapping";
import { finishSegment, type Point, type Sample, type Segment } from "./segment";
import { restRadius } from "./rest";
import { checkWindowParams, type WindowParams } from "./window-params";

const NO_SEGMENTS: readonly Segment[] = Object.freeze([]);

/**
 * What a reach (`FitCore`'s `#keeps`, as `WindowCore`'s) adds for rounding, and the room it keeps
 * below max_error: far more than any rounding error of a distance on the grid, far less than the
 * least max_error.
 */
const ROUNDING_SLACK = 1e-9;

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
 *
 * Its samples are kept in arrays reused from one stroke and path to the next (written by index,
 * `#count` of them in use): letting a stroke go moves the samples after its end to the front in
 * place, where the reference slices them anew, and the running sums and best polylines are then
 * computed again relative to the new anchor, with the same operations as the reference.
 */
export class FitCore {
  readonly params: WindowParams;
  readonly #maxErrorSq: number;
  /** The sleeve's floor: the larger of floor_ms and min_duration_ms. */
  readonly #floorMs: number;
  readonly #restSq: number;
  readonly #mapping: CanvasMapping;
  readonly #limits: { readonly min_length: number; readonly min_duration_ms: number };
  // The parameters the inner loops read, read out of `params` once.
  readonly #maxWindow: number;
  readonly #capMs: number;
  readonly #lookaheadMs: number;
  readonly #restMs: number;
  /** How many samples are held since the anchor, the anchor included (0 between paths). */
  #count = 0;
  // The samples since the anchor, the anchor first: grid points, times, samples (`#count` in use).
  readonly #xs: number[] = [];
  readonly #ys: number[] = [];
  readonly #ts: number[] = [];
  readonly #samples: Sample[] = [];
  /** Each sample's grid point relative to the anchor's (x - ax, y - ay), as the sums take them. */
  readonly #rxs: number[] = [];
  readonly #rys: number[] = [];
  // Running sums of x, y, x^2, y^2 and xy over the samples, relative to the anchor's point
  // (`#count` + 1 in use, from 0).
  readonly #sx: number[] = [0];
  readonly #sy: number[] = [0];
  readonly #sxx: number[] = [0];
  readonly #syy: number[] = [0];
  readonly #sxy: number[] = [0];
  // Each sample's best polyline from the anchor (every piece at the floor, where the bound lets it
  // be): its squared error, its count of pieces briefer than the floor and its last vertex.
  readonly #best: number[] = [];
  readonly #brief: number[] = [];
  readonly #before: number[] = [];
  /**
   * A piece's error per start (from `#errorsLow`), for the sample placed last (reused), and the
   * best start of its last piece when that piece is open (not counted as briefer than the floor:
   * `#letGo` asks for the newest sample's), found with the closed one.
   */
  readonly #errors: number[] = [];
  #errorsLow = 0;
  #openChosen = -1;
  /** Whether the piece from `#openChosen` to the sample placed last is known to keep the bound. */
  #openKeeps = false;
  // Scratch for the starts tried after the best one (`#chooseAgain`): counts and totals per start.
  readonly #counts: number[] = [];
  readonly #totals: number[] = [];
  /** The starts `#chooseAgain` tries, in order (reused). */
  readonly #order: number[] = [];
  /** Per sample, the sample that last broke the bound of a piece from it (-1: none yet). */
  readonly #broke: number[] = [];
  /**
   * Per sample, the last end to which a piece from it kept the bound (-1: none yet), and that
   * piece's reach (`#keeps`). Both written for every sample taken, so that they hold no hole (a
   * hole read and copied would make every number stored there an object).
   */
  readonly #reachEnd: number[] = [];
  readonly #reachOf: number[] = [];
  /** Reach + what a step adds at most this: every sample keeps the bound (`#keeps`). */
  readonly #reachLimit: number;
  /** The end of the last piece let go, and the sample it is (-1: none held now). */
  #end: Point | null = null;
  #endAt = -1;
  /** The vertices of a polyline let go, last first (`#polyline`, reused). */
  readonly #vertices: number[] = [];
  #emittedInPath = false;
  /** The pieces let go by the sample being pushed (null: none yet, no array made). */
  #out: Segment[] | null = null;
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
    this.#reachLimit = params.max_error - ROUNDING_SLACK;
    this.#floorMs = Math.max(params.floor_ms, params.min_duration_ms);
    this.#mapping = CanvasMapping.fromParams(params);
    const rest = restRadius(params, this.#mapping);
    this.#restSq = rest * rest;
    this.#limits = { min_length: params.min_length, min_duration_ms: params.min_duration_ms };
    this.#maxWindow = params.max_window;
    this.#capMs = params.max_stroke_ms;
    this.#lookaheadMs = params.lookahead_ms;
    this.#restMs = params.rest_ms;
  }

  /** True between the first sample of a path and `end`. */
  get drawing(): boolean {
    return this.#count > 0;
  }

  /** Where the stroke being drawn starts (canvas pixels), for showing it; null between paths. */
  get lineStart(): Sample | null {
    return this.#count > 0 ? this.#samples[0]! : null;
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
    const count = this.#count;
    let sample = input;
    // Times never run backwards (two event sources' clocks): an earlier sample takes the last time.
    if (count > 0 && input.t_ms < ts[count - 1]!) {
      sample = { t_ms: ts[count - 1]!, x: input.x, y: input.y, pressure: input.pressure };
    }
    const x = this.#mapping.gridX(sample.x);
    const y = this.#mapping.gridY(sample.y);
    const t = sample.t_ms;
    this.takenMs = t;
    this.takenX = x;
    this.takenY = y;
    this.rested = false;
    if (count === 0) {
      this.#emittedInPath = false;
      this.#resting = false;
      this.#restartWith(x, y, t, sample);
      return NO_SEGMENTS;
    }
    if (this.#resting) {
      const dx = x - this.#restX;
      const dy = y - this.#restY;
      if (count === 1 && dx * dx + dy * dy <= this.#restSq) {
        this.#retime(t);
        return NO_SEGMENTS;
      }
      this.#resting = false;
    }
    this.#out = null;
    this.#append(x, y, t, sample);
    if (!this.#rests()) this.#letGo();
    const out = this.#out;
    this.#out = null;
    return out ?? NO_SEGMENTS;
  }

  /**
   * Release: the best polyline to the last sample, every stroke at the floor (a tap gives one
   * stroke, dropped, of length 0).
   */
  end(): Segment[] {
    const count = this.#count;
    this.#resting = false;
    if (count === 0) return [];
    this.#out = null;
    if (count === 1) {
      if (!this.#emittedInPath) this.#emit(this.#piece(0, 0));
    } else {
      this.#polyline(count - 1);
    }
    this.#count = 0;
    // The samples are not needed again (the arrays are reused, not their objects).
    this.#samples.length = 0;
    const out = this.#out;
    this.#out = null;
    return out ?? [];
  }

  #emit(segment: Segment): void {
    const out = this.#out;
    if (out === null) this.#out = [segment];
    else out.push(segment);
  }

  // --- the polyline ----------------------------------------------------------------------------

  /** One sample, the anchor of the next stroke, and nothing after it (a press, a rest). */
  #restartWith(x: number, y: number, t: number, sample: Sample): void {
    this.#xs[0] = x;
    this.#ys[0] = y;
    this.#ts[0] = t;
    this.#samples[0] = sample;
    this.#broke[0] = -1;
    this.#reachEnd[0] = -1;
    this.#reachOf[0] = 0;
    this.#endAt = -1;
    this.#count = 1;
    this.#restart();
  }

  /**
   * The samples since a new anchor (xs[0], the first `#count`): running sums and best polylines
   * again, relative to it.
   */
  #restart(): void {
    const xs = this.#xs;
    const ys = this.#ys;
    const count = this.#count;
    this.#best[0] = 0;
    this.#brief[0] = 0;
    this.#before[0] = -1;
    const ax = xs[0]!;
    const ay = ys[0]!;
    this.#rxs[0] = ax - ax;
    this.#rys[0] = ay - ay;
    this.#addSums(0, 0, 0);
    for (let k = 1; k < count; k++) {
      const rx = xs[k]! - ax;
      const ry = ys[k]! - ay;
      this.#rxs[k] = rx;
      this.#rys[k] = ry;
      this.#addSums(k, rx, ry);
      this.#place(k);
    }
  }

  /** The running sums to sample k (at k + 1), with its coordinates relative to the anchor. */
  #addSums(k: number, rx: number, ry: number): void {
    const sx = this.#sx;
    const sy = this.#sy;
    const sxx = this.#sxx;
    const syy = this.#syy;
    const sxy = this.#sxy;
    sx[k + 1] = sx[k]! + rx;
    sy[k + 1] = sy[k]! + ry;
    sxx[k + 1] = sxx[k]! + rx * rx;
    syy[k + 1] = syy[k]! + ry * ry;
    sxy[k + 1] = sxy[k]! + rx * ry;
  }

  #append(x: number, y: number, t: number, sample: Sample): void {
    const k = this.#count;
    const xs = this.#xs;
    const ys = this.#ys;
    xs[k] = x;
    ys[k] = y;
    this.#ts[k] = t;
    this.#samples[k] = sample;
    this.#broke[k] = -1;
    this.#reachEnd[k] = -1;
    this.#reachOf[k] = 0;
    this.#count = k + 1;
    const rx = x - xs[0]!;
    const ry = y - ys[0]!;
    this.#rxs[k] = rx;
    this.#rys[k] = ry;
    this.#addSums(k, rx, ry);
    this.#place(k);
  }

  /** The first start a piece to sample k may have: none outlasts the caps. */
  #lowTo(k: number): number {
    let low = k - this.#maxWindow;
    if (low < 0) low = 0;
    // No piece outlasts the latency cap, but one between two samples drawn further apart.
    const capMs = this.#capMs;
    if (capMs > 0) {
      const ts = this.#ts;
      const tK = ts[k]!;
      while (low < k - 1 && tK - ts[low]! > capMs) low++;
    }
    return low;
  }

  /**
   * The error of the piece from sample i to sample k: `pieceError`, from the coordinates relative
   * to the anchor as the sums took them (the same values).
   */
  #errorOf(i: number, k: number): number {
    const rxs = this.#rxs;
    const rys = this.#rys;
    const sx = this.#sx;
    const sy = this.#sy;
    const count = k + 1 - i;
    const px = rxs[i]!;
    const py = rys[i]!;
    const dx = rxs[k]! - px;
    const dy = rys[k]! - py;
    const sxI = sx[k + 1]! - sx[i]!;
    const syI = sy[k + 1]! - sy[i]!;
    const cxx = this.#sxx[k + 1]! - this.#sxx[i]! - 2 * px * sxI + count * px * px;
    const cyy = this.#syy[k + 1]! - this.#syy[i]! - 2 * py * syI + count * py * py;
    const cxy = this.#sxy[k + 1]! - this.#sxy[i]! - px * syI - py * sxI + count * px * py;
    const lengthSq = dx * dx + dy * dy;
    const error = lengthSq > 0 ? (dx * dx * cyy + dy * dy * cxx - 2 * dx * dy * cxy) / lengthSq : cxx + cyy;
    return error > 0 ? error : 0;
  }

  /**
   * The best start of the last piece to sample k where the first choice's bound breaks (the fewest
   * pieces briefer than the floor, the last counted only when `closed`, then the least squared
   * error, then the earliest start; Python `FitCore._choose`): the other starts tested in the order of a sort
   * by the same keys (the reference takes them from a heap; the totals are never NaN, so the order
   * is total and the same), the first that keeps the bound.
   */
  #chooseAgain(k: number, low: number, closed: boolean, chosen: number): number {
    const best = this.#best;
    const brief = this.#brief;
    const errors = this.#errors;
    const ts = this.#ts;
    const floorMs = this.#floorMs;
    const tK = ts[k]!;
    const counts = this.#counts;
    const totals = this.#totals;
    for (let i = low; i < k; i++) {
      // A piece's error `#place` left out (-1: its start could not be the first choice).
      if (errors[i - low]! < 0) errors[i - low] = this.#errorOf(i, k);
      counts[i - low] = brief[i]! + (closed && tK - ts[i]! < floorMs ? 1 : 0);
      totals[i - low] = best[i]! + errors[i - low]!;
    }
    // The other starts, sorted once by the same keys (the fewest brief pieces, the least error,
    // the earliest start): O(n log n) where a scan per start rejected would be O(n^2) at the
    // widest settings.
    const order = this.#order;
    order.length = 0;
    for (let i = low; i < k; i++) if (i !== chosen) order.push(i);
    order.sort((a, b) => {
      const countA = counts[a - low]!;
      const countB = counts[b - low]!;
      if (countA !== countB) return countA - countB;
      const totalA = totals[a - low]!;
      const totalB = totals[b - low]!;
      if (totalA < totalB) return -1;
      if (totalB < totalA) return 1;
      return a - b;
    });
    for (const start of order) {
      if (start === k - 1 || this.#keeps(start, k)) return start;
    }
    return k - 1; // (never: the piece from k - 1 is among the starts)
  }

  /**
   * Sample k's best polyline from the anchor, every piece closed (at the floor): each piece's error
   * and the first choice in one pass, which also finds the best start with the last piece open,
   * for `#letGo`.
   * A start with more brief pieces than the one chosen so far (closed and open) cannot be chosen
   * in its place, whatever its error: its error is left out (-1), computed only if a first choice
   * breaks the bound.
   */
  #place(k: number): void {
    const low = this.#lowTo(k);
    const best = this.#best;
    const brief = this.#brief;
    const errors = this.#errors;
    const ts = this.#ts;
    const floorMs = this.#floorMs;
    const tK = ts[k]!;
    // `#errorOf`, its terms of the end read once.
    const rxs = this.#rxs;
    const rys = this.#rys;
    const sx = this.#sx;
    const sy = this.#sy;
    const sxx = this.#sxx;
    const syy = this.#syy;
    const sxy = this.#sxy;
    const ex = rxs[k]!;
    const ey = rys[k]!;
    const sxEnd = sx[k + 1]!;
    const syEnd = sy[k + 1]!;
    const sxxEnd = sxx[k + 1]!;
    const syyEnd = syy[k + 1]!;
    const sxyEnd = sxy[k + 1]!;
    // The first choice's scan, closed and open at once (no count is infinite: the first start is
    // chosen).
    let closed = -1;
    let closedCount = Infinity;
    let closedTotal = 0;
    let open = -1;
    let openCount = Infinity;
    let openTotal = 0;
    for (let i = low; i < k; i++) {
      const count = brief[i]!;
      const closedI = tK - ts[i]! < floorMs ? count + 1 : count;
      if (count > openCount && closedI > closedCount) {
        errors[i - low] = -1;
        continue;
      }
      const pieceCount = k + 1 - i;
      const px = rxs[i]!;
      const py = rys[i]!;
      const dx = ex - px;
      const dy = ey - py;
      const sxI = sxEnd - sx[i]!;
      const syI = syEnd - sy[i]!;
      const cxx = sxxEnd - sxx[i]! - 2 * px * sxI + pieceCount * px * px;
      const cyy = syyEnd - syy[i]! - 2 * py * syI + pieceCount * py * py;
      const cxy = sxyEnd - sxy[i]! - px * syI - py * sxI + pieceCount * px * py;
      const lengthSq = dx * dx + dy * dy;
      const raw = lengthSq > 0 ? (dx * dx * cyy + dy * dy * cxx - 2 * dx * dy * cxy) / lengthSq : cxx + cyy;
      const error = raw > 0 ? raw : 0;
      errors[i - low] = error;
      const total = best[i]! + error;
      if (count < openCount || (count === openCount && total < openTotal)) {
        open = i;
        openCount = count;
        openTotal = total;
      }
      if (closedI < closedCount || (closedI === closedCount && total < closedTotal)) {
        closed = i;
        closedCount = closedI;
        closedTotal = total;
      }
    }
    this.#errorsLow = low;
    const i = closed === k - 1 || this.#keeps(closed, k) ? closed : this.#chooseAgain(k, low, true, closed);
    // Most often the open choice is the closed one, whose piece keeps the bound: not tested again.
    this.#openChosen = open;
    this.#openKeeps = open === i;
    best[k] = best[i]! + errors[i - low]!;
    brief[k] = brief[i]! + (tK - ts[i]! < floorMs ? 1 : 0);
    this.#before[k] = i;
  }

  /**
   * The best start of the last piece, open, to the newest sample k: its first choice found by
   * `#place` (which placed k last: `#letGo` runs after it), else the next that keeps the bound.
   */
  #chooseOpen(k: number): number {
    const open = this.#openChosen;
    return open === k - 1 || this.#openKeeps || this.#keeps(open, k)
      ? open
      : this.#chooseAgain(k, this.#errorsLow, false, open);
  }

  /**
   * Whether every sample between xs[start] and xs[end] lies within max_error of the segment between
   * them: the sample that broke the last piece tested from `start` first, then the samples coarse
   * to fine (the answer is the same in any order). Python `FitCore._keeps`. `distanceSq` with the
   * segment's terms computed once (the same operations).
   *
   * Where the piece from `start` to the sample before `end` kept the bound, its reach (as
   * `WindowCore`'s: no sample between lies farther from it, rounding allowed for) plus how far the
   * sample before `end` lies from the piece to `end` bounds every distance to it (the distance to
   * a segment is convex along it, 0 at its start): under max_error by ROUNDING_SLACK, the piece
   * keeps the bound without testing each sample, as testing each would find.
   */
  #keeps(start: number, end: number): boolean {
    const xs = this.#xs;
    const ys = this.#ys;
    const ax = xs[start]!;
    const ay = ys[start]!;
    const dx = xs[end]! - ax;
    const dy = ys[end]! - ay;
    const lengthSq = dx * dx + dy * dy;
    const limitSq = this.#maxErrorSq;
    const reachEnd = this.#reachEnd;
    const reachOf = this.#reachOf;
    if (reachEnd[start] === end - 1) {
      const qx = xs[end - 1]! - ax;
      const qy = ys[end - 1]! - ay;
      const step = lengthSq > 0 ? chordDistanceSq(qx, qy, dx, dy, lengthSq) : qx * qx + qy * qy;
      const reach = reachOf[start]! + Math.sqrt(step) + ROUNDING_SLACK;
      if (reach <= this.#reachLimit) {
        reachOf[start] = reach;
        reachEnd[start] = end;
        return true;
      }
    }
    const broke = this.#broke[start]!;
    if (start < broke && broke < end) {
      const qx = xs[broke]! - ax;
      const qy = ys[broke]! - ay;
      const d = lengthSq > 0 ? chordDistanceSq(qx, qy, dx, dy, lengthSq) : qx * qx + qy * qy;
      if (d > limitSq) return false;
    }
    const span = end - start;
    let step = 1;
    while (step * 2 < span) step *= 2;
    // The farthest distance found (a NaN counts as none: it breaks no bound).
    let farthest = 0;
    for (; step > 0; step = Math.floor(step / 2)) {
      for (let m = start + step; m < end; m += 2 * step) {
        const qx = xs[m]! - ax;
        const qy = ys[m]! - ay;
        const d = lengthSq > 0 ? chordDistanceSq(qx, qy, dx, dy, lengthSq) : qx * qx + qy * qy;
        if (d > limitSq) {
          this.#broke[start] = m;
          return false;
        }
        if (d > farthest) farthest = d;
      }
    }
    reachOf[start] = Math.sqrt(farthest) + ROUNDING_SLACK;
    reachEnd[start] = end;
    return true;
  }

  /** Lets go the best polyline (every piece closed) to sample `last`. */
  #polyline(last: number): void {
    const before = this.#before;
    // Its vertices, found back from the last (into an array reused), let go from the first.
    const vertices = this.#vertices;
    let n = 0;
    for (let v = last; v !== 0; v = before[v]!) vertices[n++] = v;
    let start = 0;
    while (n > 0) {
      const end = vertices[--n]!;
      this.#emit(this.#piece(start, end));
      start = end;
    }
  }

  #piece(a: number, b: number): Segment {
    this.#emittedInPath = true;
    const xs = this.#xs;
    const ys = this.#ys;
    const ts = this.#ts;
    // A piece starting where the one before ended starts at that same point, a readonly pair.
    const start: Point = this.#endAt === a ? this.#end! : [xs[a]!, ys[a]!];
    const end: Point = [xs[b]!, ys[b]!];
    this.#end = end;
    this.#endAt = b;
    // The pointer's time: the last sample taken (the reference's `_pointer`, always set here).
    return finishSegment(start, end, ts[a]!, ts[b]!, this.takenMs, this.#limits);
  }

  /** Sample k anchors the next stroke; the samples after it are taken again, moved to the front. */
  #from(k: number): void {
    const xs = this.#xs;
    const ys = this.#ys;
    const ts = this.#ts;
    const samples = this.#samples;
    const broke = this.#broke;
    const reachEnd = this.#reachEnd;
    const reachOf = this.#reachOf;
    const count = this.#count;
    for (let from = k, to = 0; from < count; from++, to++) {
      xs[to] = xs[from]!;
      ys[to] = ys[from]!;
      ts[to] = ts[from]!;
      samples[to] = samples[from]!;
      const m = broke[from]!;
      broke[to] = m > k ? m - k : -1;
      // A piece's reach is its samples', wherever they are held.
      const end = reachEnd[from]!;
      reachEnd[to] = end >= 0 ? end - k : -1;
      reachOf[to] = reachOf[from]!;
    }
    this.#count = count - k;
    this.#endAt = this.#endAt === k ? 0 : -1;
    this.#restart();
  }

  /**
   * Lets go each stroke that is final: its end drawn `lookahead_ms` ago, or the stroke longer than
   * the latency cap.
   */
  #letGo(): void {
    const capMs = this.#capMs;
    const lookaheadMs = this.#lookaheadMs;
    const floorMs = this.#floorMs;
    const ts = this.#ts;
    const before = this.#before;
    for (;;) {
      const j = this.#count - 1;
      const still = this.#stillFrom(j);
      if (ts[j]! - ts[0]! < floorMs || still === 0) return;
      const last = this.#chooseOpen(j);
      if (last === 0) {
        // One stroke from the anchor: cut by the latency cap at the sample before.
        if (
          capMs > 0 &&
          ts[j]! - ts[0]! > capMs &&
          j >= 2 &&
          ts[j - 1]! - ts[0]! >= floorMs &&
          j - 1 <= still &&
          this.#keeps(0, j - 1)
        ) {
          this.#emit(this.#piece(0, j - 1));
          this.#from(j - 1);
          continue;
        }
        return;
      }
      let vertex = last;
      while (before[vertex] !== 0) vertex = before[vertex]!;
      if (
        vertex > still ||
        (ts[j]! - ts[vertex]! < lookaheadMs && !(capMs > 0 && ts[vertex]! - ts[0]! > capMs))
      ) {
        return;
      }
      this.#emit(this.#piece(0, vertex));
      this.#from(vertex);
    }
  }

  // --- rests -----------------------------------------------------------------------------------

  /**
   * Where the pen may have been resting since: the first of the samples up to j that all lie
   * within the rest radius of sample j (with `rest_ms` on; j + 1 without). No stroke is let go
   * that ends after it: its end would lie inside a stop that may yet turn out a rest, and the
   * stroke would play the stop. The rest rule ends the stop once it has lasted `rest_ms`, or the
   * pen moves on. Python `FitCore._still_from`.
   */
  #stillFrom(j: number): number {
    if (this.#restMs <= 0) return j + 1;
    const xs = this.#xs;
    const ys = this.#ys;
    const x = xs[j]!;
    const y = ys[j]!;
    const restSq = this.#restSq;
    let k = j;
    while (k > 0) {
      const dx = xs[k - 1]! - x;
      const dy = ys[k - 1]! - y;
      if (!(dx * dx + dy * dy <= restSq)) break; // (not ">": a NaN is a move, and ends a rest)
      k -= 1;
    }
    return k;
  }

  #retime(tMs: number): void {
    this.#ts[0] = tMs;
    const anchor = this.#samples[0]!;
    this.#samples[0] = { t_ms: tMs, x: anchor.x, y: anchor.y, pressure: anchor.pressure };
  }

  /**
   * Whether the pen has rested `rest_ms` at the newest sample: its samples of the last `rest_ms` or
   * more all lie within the rest radius of it. The best polyline to the rest's first sample is let
   * go; the rest is not played; the anchor waits at that sample for the pen to move on.
   */
  #rests(): boolean {
    const restMs = this.#restMs;
    const xs = this.#xs;
    const ys = this.#ys;
    const ts = this.#ts;
    const j = this.#count - 1;
    const t = ts[j]!;
    if (restMs <= 0 || t - ts[0]! < restMs) return false;
    const x = xs[j]!;
    const y = ys[j]!;
    const start = this.#stillFrom(j);
    if (start === j || t - ts[start]! < restMs) return false;
    if (start > 0) this.#polyline(start);
    this.#restartWith(xs[start]!, ys[start]!, ts[start]!, this.#samples[start]!);
    this.#retime(t);
    this.#restX = x;
    this.#restY = y;
    this.#resting = true;
    this.rested = true;
    return true;
  }
}
