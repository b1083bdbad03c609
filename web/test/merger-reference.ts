/**
 * The merger as first written, for the property test that the window simplifier, whose window
 * and merger share one store of the drawn samples, merges as it did (`window.merger.test.ts`):
 * its own copy of every drawn sample, three numbers side by side in one array. Kept in the
 * tests, not in the page.
 */
import {
  NOT_ENOUGH_DISTANCE,
  NOT_ENOUGH_DURATION,
  segmentLength,
  type DropReason,
  type Point,
  type Segment,
} from "../src/simplify/segment";
import { floorEndMs } from "../src/simplify/window";

/**
 * Merges the pieces the window cuts too short to send into a neighbour, never dropping one (the
 * reference's `Merger`). A piece is too short when it is shorter than `min_length` or briefer
 * than the larger of `min_duration_ms` and `floor_ms` (the sleeve would slow it). A short piece
 * waits for the next; the two become one stroke when every drawn sample of both lies within
 * `max_error` of it (still short, it waits again), else the short one is sent as it is. A piece
 * long enough is sent at once (holding each back would delay the drawing), so the last piece of
 * a path, if short, is sent short, unless at release it is briefer than the floor and lies, with
 * every drawn sample not yet covered, within `max_error` of the stroke already sent before it:
 * then it merges into that stroke and nothing more is sent (`mergedBack`). Only a path's one and
 * only piece, too short, is dropped.
 */
/**
 * The merger drops covered samples from its arrays once this many have gathered at their start
 * (and they are at least half): few enough that the arrays stay small (few regrowths for a
 * simplifier made per path), enough that each sample is moved at most once on average.
 */
const COMPACT_AFTER = 32;
/** The numbers the merger keeps of a drawn sample: its time, x and y. */
const DRAWN = 3;

export class ReferenceMerger {
  readonly #maxError: number;
  readonly #minLength: number;
  readonly #minDurationMs: number;
  readonly #shortMs: number;
  readonly #strict: boolean;
  /**
   * The drawn samples not yet covered by a sent stroke (ms, grid units), oldest first: samples
   * [#first, #count) of one array kept from one path to the next, three numbers a sample (time, x,
   * y) side by side. One array of numbers (stored unboxed, as in `Samples`), not three: every
   * sample drawn is stored here, and one array grows and checks its bounds once where three did
   * three times. Not a typed array: its buffer lives outside the heap and is zeroed when made,
   * which cost more than its samples for a simplifier made per path (as the bench makes one per
   * demonstration).
   */
  readonly #drawn: number[] = [];
  #count = 0;
  /**
   * The first sample not yet covered: those before it are, and are dropped from the array only
   * now and then (`#send`), not at every stroke sent (three splices, each an array made).
   */
  #first = 0;
  #held: Segment | null = null;
  #sentInPath = false;
  /**
   * The path's last sent stroke (null before its first): a piece briefer than the sleeve's floor
   * left at release merges into it when every drawn sample it has not covered lies within
   * max_error of it (`end`).
   */
  #last: Segment | null = null;
  /** Pieces merged at release into a stroke already sent (nothing more is sent for them), in all. */
  mergedBack = 0;

  constructor(maxError: number, minLength: number, minDurationMs: number, floorMs: number, strict = false) {
    this.#maxError = maxError;
    this.#minLength = minLength;
    this.#minDurationMs = minDurationMs;
    this.#shortMs = Math.max(minDurationMs, floorMs);
    this.#strict = strict;
  }

  /** A drawn sample, in order (its time as the window took it). */
  sample(tMs: number, x: number, y: number): void {
    const at = this.#count;
    const drawn = this.#drawn;
    drawn[DRAWN * at] = tMs;
    drawn[DRAWN * at + 1] = x;
    drawn[DRAWN * at + 2] = y;
    this.#count = at + 1;
  }

  #short(segment: Segment): boolean {
    return segmentLength(segment) < this.#minLength || segment.duration_ms < this.#shortMs;
  }

  #belowMinimums(segment: Segment): boolean {
    return segmentLength(segment) < this.#minLength || segment.duration_ms < this.#minDurationMs;
  }

  /**
   * Whether every sample not yet covered, drawn up to endMs, lies within max_error of
   * start -> end. All of them, not only those after the held piece's start: a stroke whose pen
   * crawled or rested starts after samples it covers.
   */
  #fits(start: Point, end: Point, endMs: number): boolean {
    const limitSq = this.#maxError * this.#maxError;
    const drawn = this.#drawn;
    const count = this.#count;
    // `distanceSq` with the chord's terms computed once (the same operations, as in `#farthestSq`).
    const ax = start[0];
    const ay = start[1];
    const dx = end[0] - ax;
    const dy = end[1] - ay;
    const lengthSq = dx * dx + dy * dy;
    for (let i = this.#first; i < count; i++) {
      const at = DRAWN * i;
      if (drawn[at]! > endMs) break;
      const qx = drawn[at + 1]! - ax;
      const qy = drawn[at + 2]! - ay;
      const d = lengthSq > 0 ? chordDistanceSq(qx, qy, dx, dy, lengthSq) : qx * qx + qy * qy;
      if (d > limitSq) return false;
    }
    return true;
  }

  #send(segment: Segment, nowMs: number, out: Segment[]): void {
    this.#sentInPath = true;
    this.#last = segment;
    // A piece made at this sample and not dropped (most: the window's and the merged ones) is sent
    // as it is; else a copy, built field by field, not spread (several times slower): the same
    // keys in the same order. Object.is: -0 and 0 are different times to the vectors.
    // A stroke drawn briefer than the sleeve's floor (one that could not merge) lasts the floor.
    const durationMs =
      segment.end_ms - segment.start_ms < this.#shortMs ? this.#shortMs : segment.duration_ms;
    const sent: Segment =
      segment.dropped === null &&
      Object.is(segment.emitted_at_ms, nowMs) &&
      durationMs === segment.duration_ms
        ? segment
        : segment.merged === undefined
          ? {
              start: segment.start,
              end: segment.end,
              start_ms: segment.start_ms,
              end_ms: segment.end_ms,
              duration_ms: durationMs,
              emitted_at_ms: nowMs,
              dropped: null,
            }
          : {
              start: segment.start,
              end: segment.end,
              start_ms: segment.start_ms,
              end_ms: segment.end_ms,
              duration_ms: durationMs,
              emitted_at_ms: nowMs,
              dropped: null,
              merged: segment.merged,
            };
    out.push(sent);
    // The samples before its end are covered now (those at its end may start the next).
    this.#cover(segment.end_ms);
  }

  /** The samples drawn before endMs are covered. */
  #cover(endMs: number): void {
    const drawn = this.#drawn;
    const count = this.#count;
    let keep = this.#first;
    while (keep < count && drawn[DRAWN * keep]! < endMs) keep++;
    this.#first = keep;
    if (keep >= COMPACT_AFTER && 2 * keep >= count) {
      // Most of the array is covered: move what is not to its start, in place.
      for (let from = DRAWN * keep, to = 0, stop = DRAWN * count; from < stop; from++, to++) {
        drawn[to] = drawn[from]!;
      }
      this.#count = count - keep;
      this.#first = 0;
    }
  }

  /** A piece the window cut: the strokes sent now, into `out` (none while a short one waits). */
  take(input: Segment, nowMs: number, out: Segment[]): void {
    let piece = input;
    const held = this.#held;
    if (held !== null) {
      this.#held = null;
      if (this.#fits(held.start, piece.end, piece.end_ms) || (this.#strict && this.#belowMinimums(held))) {
        piece = {
          start: held.start,
          end: piece.end,
          start_ms: held.start_ms,
          end_ms: piece.end_ms,
          duration_ms: piece.end_ms - held.start_ms,
          emitted_at_ms: nowMs,
          dropped: null,
          merged: (held.merged ?? 0) + (piece.merged ?? 0) + 1,
        };
      } else {
        this.#send(held, nowMs, out);
      }
    }
    if (this.#short(piece)) this.#held = piece;
    else this.#send(piece, nowMs, out);
  }

  /**
   * The pen rests (since the held piece's end, until `nowMs`): the held piece is sent now, into
   * `out`, rather than merged with what comes after the rest, which would play the rest. If it is
   * briefer than the sleeve's floor, it takes the time it needs from the rest: the pen was at its
   * end then. With strict minimums, a piece still below them is not sent: it merges back into
   * the path's last sent stroke where the bound allows, else is dropped with its reason.
   */
  rest(nowMs: number, out: Segment[]): void {
    let held = this.#held;
    if (held === null) return;
    if (held.duration_ms < this.#shortMs && nowMs > held.end_ms) {
      const endMs = Math.min(floorEndMs(held.start_ms, this.#shortMs), nowMs);
      held = { ...held, end_ms: endMs, duration_ms: endMs - held.start_ms };
    }
    this.#held = null;
    if (this.#strict && this.#belowMinimums(held)) {
      // Never sent, nor merged across the rest: merged back where the bound allows, else dropped.
      if (this.#mergesBack(held)) this.mergedBack += (held.merged ?? 0) + 1;
      else {
        const reason = segmentLength(held) < this.#minLength ? NOT_ENOUGH_DISTANCE : NOT_ENOUGH_DURATION;
        out.push({ ...held, emitted_at_ms: nowMs, dropped: reason });
      }
      this.#cover(held.end_ms);
      return;
    }
    this.#send(held, nowMs, out);
  }

  /**
   * Whether the piece held at release merges into the path's last sent stroke: it is briefer
   * than the sleeve's floor (or, with strict minimums, shorter than min_length: it would be
   * dropped), and every drawn sample not yet covered lies within max_error of that stroke.
   */
  #mergesBack(held: Segment): boolean {
    const last = this.#last;
    if (last === null) return false;
    if (!(held.duration_ms < this.#shortMs || (this.#strict && segmentLength(held) < this.#minLength))) {
      return false;
    }
    return this.#fits(last.start, last.end, Infinity);
  }

  /**
   * Release, after the window's last piece: the held piece merges into the path's last sent
   * stroke where that keeps the bound (`#mergesBack`: nothing more is sent), else it is sent (or,
   * a path's only piece too short, dropped).
   */
  end(nowMs: number, out: Segment[]): void {
    let held = this.#held;
    if (held !== null && this.#mergesBack(held)) {
      this.mergedBack += (held.merged ?? 0) + 1;
      held = null;
    }
    if (held !== null) {
      let reason: DropReason | null = null;
      if (!this.#sentInPath || this.#strict) {
        if (segmentLength(held) < this.#minLength) reason = NOT_ENOUGH_DISTANCE;
        else if (held.duration_ms < this.#minDurationMs) reason = NOT_ENOUGH_DURATION;
      }
      if (reason !== null) out.push({ ...held, emitted_at_ms: nowMs, dropped: reason });
      else this.#send(held, nowMs, out);
    }
    this.#held = null;
    this.#sentInPath = false;
    this.#last = null;
    this.#count = 0;
    this.#first = 0;
  }
}

/**
 * Squared distance from q (relative to a chord's start) to the chord d of squared length
 * `lengthSq` > 0, at its nearest point: the projection, clamped onto the chord. Its chord terms
 * computed once by the caller, for the inner loops. The clamp is written out, not with Math.max
 * and Math.min, with the same result to the last bit: t <= 0 leaves q as it is (q - 0 * d is q;
 * a zero's sign is squared away), t >= 1 subtracts d itself (1 * d is d), and a NaN t falls to
 * the projection as through Math.max and Math.min.
 */
function chordDistanceSq(qx: number, qy: number, dx: number, dy: number, lengthSq: number): number {
  const t = (qx * dx + qy * dy) / lengthSq;
  if (t >= 1) {
    qx = qx - dx;
    qy = qy - dy;
  } else if (!(t <= 0)) {
    qx = qx - t * dx;
    qy = qy - t * dy;
  }
  return qx * qx + qy * qy;
}
