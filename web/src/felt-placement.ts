/**
 * The current drawing's strokes placed in time (felt.ts's rule), kept up to
 * date stroke by stroke instead of placed again from scratch: a new stroke,
 * a report from the sleeve or a cut re-places only the strokes from the one
 * it touches to the first that stays where it was, so the page's cost per
 * stroke and per sleeve event does not grow with the drawing. Gives the same
 * placement as the full computation (felt-panel's former `#place`):
 *
 *   - times start at the first stroke's arrival (the shift);
 *   - the page's estimate is placeStrokes with the cuts;
 *   - once the sleeve reported a stroke, its clock is anchored on the first
 *     stroke (in seq order) it reported: every reported start, less that
 *     offset, replaces the estimate.
 *
 * Pure: no DOM, no clock.
 */
import type { FeltStroke, PlacedStroke } from "./felt";
import { EMPTY_TAIL_MS, queueCatchUpMs, queueStartMs, SLEEVE_FLOOR_MS } from "./sleeve-queue";

export class FeltPlacement {
  /** Shifted strokes (arrival relative to the first stroke's), in seq order. */
  readonly #strokes: FeltStroke[] = [];
  readonly #placed: PlacedStroke[] = [];
  /** The largest end (start + played) of strokes 0..i: what is over by then. */
  readonly #prefixEndMs: number[] = [];
  readonly #indexBySeq = new Map<number, number>();
  /** seq -> start reported by the sleeve, on the sleeve's clock. */
  readonly #startedAt = new Map<number, number>();
  /** seq -> ms into the stroke at which a cancel cut it. */
  readonly #cut = new Map<number, number>();
  /** Arrival (unshifted) of the first stroke: the timeline's zero. */
  #shiftMs = 0;
  /** Index of the first stroke the sleeve reported, and its clock's offset; null before any. */
  #anchor: { index: number; offsetMs: number } | null = null;
  #reported = 0;
  /** Pairs (i - 1, i) whose start goes back in time: the fast search needs none. */
  #descents = 0;
  /** The earliest time (ms) whose picture changed since `takeDirty`; "all" after a rebuild. */
  #dirty: number | "all" | null = "all";

  /** `floorMs`: the sleeve's floor, down to which a stroke that waits catches up. */
  constructor(readonly floorMs: number = SLEEVE_FLOOR_MS) {}

  /** Every stroke again (a new drawing, an undo, another arrival): placed from scratch. */
  reset(strokes: readonly FeltStroke[] = []): void {
    this.#strokes.length = 0;
    this.#indexBySeq.clear();
    const sorted = [...strokes].sort((a, b) => a.seq - b.seq);
    this.#shiftMs =
      sorted.length === 0
        ? 0
        : sorted.reduce((low, s) => Math.min(low, s.arrives_ms), Number.POSITIVE_INFINITY);
    for (const stroke of sorted) this.#push(stroke);
    this.#reanchor();
    this.#placeFrom(0, true);
    this.#dirty = "all";
  }

  /** A new stroke at the end (seq after every one placed, arrival unshifted). */
  append(stroke: FeltStroke): void {
    const last = this.#strokes[this.#strokes.length - 1];
    const first = this.#strokes.length === 0;
    if (!first && (stroke.seq <= last!.seq || stroke.arrives_ms < this.#shiftMs)) {
      // Out of order or before the zero: the cheap path's assumptions fail, place all again.
      this.reset([...this.#unshifted(), stroke]);
      return;
    }
    if (first) this.#shiftMs = stroke.arrives_ms;
    this.#push(stroke);
    this.#placeFrom(this.#strokes.length - 1, false);
  }

  /** The sleeve started stroke `seq` at `startMs` on its clock. */
  report(seq: number, startMs: number): void {
    this.#startedAt.set(seq, startMs);
    const index = this.#indexBySeq.get(seq);
    if (index === undefined) return;
    if (this.#anchor === null || index <= this.#anchor.index) {
      // A new anchor (or the anchor's own start again) moves every reported stroke.
      this.#reanchor();
      this.#placeFrom(0, true);
    } else {
      this.#placeFrom(index, false);
    }
  }

  /** A cancel cut stroke `seq` `cutMs` into it (0: dropped before it started). */
  cut(seq: number, cutMs: number): void {
    this.#cut.set(seq, cutMs);
    const index = this.#indexBySeq.get(seq);
    if (index === undefined) return;
    if (this.#anchor !== null && index <= this.#anchor.index) {
      // The anchor's own estimate depends on the cuts before it.
      this.#reanchor();
      this.#placeFrom(0, true);
    } else {
      this.#placeFrom(index, false);
    }
  }

  get placed(): readonly PlacedStroke[] {
    return this.#placed;
  }

  get reportedCount(): number {
    return this.#reported;
  }

  /** When the last stroke ends (0 for none), as felt.ts's totalMs. */
  get totalMs(): number {
    return Math.max(0, this.#prefixEndMs[this.#prefixEndMs.length - 1] ?? 0);
  }

  /** The placed stroke `seq`, if it is in the drawing. */
  bySeq(seq: number): PlacedStroke | undefined {
    const index = this.#indexBySeq.get(seq);
    return index === undefined ? undefined : this.#placed[index];
  }

  /** The index of the first stroke that ends after `tMs` (placed.length if none). */
  firstEndingAfter(tMs: number): number {
    return this.#firstPrefixEnd((end) => end > tMs);
  }

  /**
   * As felt.ts's playingAt: the first stroke (seq order) playing at `tMs`. Strokes before the first
   * whose prefix end reaches `tMs` are all over by then; with starts in order, the search stops at
   * the first stroke that starts later.
   */
  playingAt(tMs: number): { stroke: PlacedStroke; into_ms: number } | null {
    for (let i = this.#firstPrefixEnd((end) => end >= tMs); i < this.#placed.length; i++) {
      const stroke = this.#placed[i]!;
      const into_ms = tMs - stroke.start_ms;
      if (into_ms >= 0 && into_ms <= stroke.played_ms) return { stroke, into_ms };
      if (into_ms < 0 && this.#descents === 0) return null;
    }
    return null;
  }

  /** The earliest time whose picture changed since the last call ("all": draw everything again). */
  takeDirty(): number | "all" | null {
    const dirty = this.#dirty;
    this.#dirty = null;
    return dirty;
  }

  #firstPrefixEnd(test: (endMs: number) => boolean): number {
    // Prefix ends never decrease: binary search.
    let low = 0;
    let high = this.#prefixEndMs.length;
    while (low < high) {
      const mid = (low + high) >>> 1;
      if (test(this.#prefixEndMs[mid]!)) high = mid;
      else low = mid + 1;
    }
    return low;
  }

  #unshifted(): FeltStroke[] {
    return this.#strokes.map((s) => ({ ...s, arrives_ms: s.arrives_ms + this.#shiftMs }));
  }

  #push(stroke: FeltStroke): void {
    this.#indexBySeq.set(stroke.seq, this.#strokes.length);
    this.#strokes.push({ ...stroke, arrives_ms: stroke.arrives_ms - this.#shiftMs });
  }

  /** The first reported stroke and the sleeve's clock offset against the page's estimate of it. */
  #reanchor(): void {
    this.#anchor = null;
    let tail = EMPTY_TAIL_MS;
    for (let index = 0; index < this.#strokes.length; index++) {
      const stroke = this.#strokes[index]!;
      const estimateMs = queueStartMs(stroke.arrives_ms, tail);
      const reported = this.#startedAt.get(stroke.seq);
      if (reported !== undefined) {
        this.#anchor = { index, offsetMs: reported - estimateMs };
        return;
      }
      tail = estimateMs + this.#playedMs(stroke, this.#durationMs(stroke, tail));
    }
  }

  /** How long the sleeve plays the stroke behind a queue ending at `tailMs` (it catches up). */
  #durationMs(stroke: FeltStroke, tailMs: number): number {
    return queueCatchUpMs(stroke.arrives_ms, tailMs, stroke.duration_ms, this.floorMs);
  }

  #playedMs(stroke: FeltStroke, durationMs: number): number {
    return Math.min(durationMs, Math.max(0, this.#cut.get(stroke.seq) ?? durationMs));
  }

  /**
   * Places strokes from `from` on; unless `all`, stops at the first one after `from` that stays
   * where it was (every later one depends only on the one before it, so stays too).
   */
  #placeFrom(from: number, all: boolean): void {
    if (all) {
      this.#placed.length = 0;
      this.#prefixEndMs.length = 0;
      this.#reported = 0;
      this.#descents = 0;
    }
    const previous = this.#placed[from - 1];
    let tail = previous === undefined ? EMPTY_TAIL_MS : previous.start_ms + previous.played_ms;
    let dirtyMs = Number.POSITIVE_INFINITY;
    const offset = this.#anchor?.offsetMs;
    let stop = this.#strokes.length;
    for (let i = from; i < this.#strokes.length; i++) {
      const stroke = this.#strokes[i]!;
      const reportedAt = offset === undefined ? undefined : this.#startedAt.get(stroke.seq);
      const known = reportedAt === undefined ? undefined : reportedAt - offset!;
      const start_ms = known ?? queueStartMs(stroke.arrives_ms, tail);
      const duration_ms = this.#durationMs(stroke, tail);
      const played_ms = this.#playedMs(stroke, duration_ms);
      tail = start_ms + played_ms;
      const old = this.#placed[i];
      const placed: PlacedStroke = {
        ...stroke,
        duration_ms,
        start_ms,
        reported: known !== undefined,
        played_ms,
      };
      if (
        i > from &&
        old !== undefined &&
        old.start_ms === start_ms &&
        old.duration_ms === duration_ms &&
        old.played_ms === played_ms &&
        old.reported === placed.reported
      ) {
        stop = i;
        break;
      }
      // Descents are counted over the array as it stands: the two pairs this stroke is in.
      this.#descents -= this.#descends(i) + this.#descends(i + 1);
      if (old !== undefined) {
        if (old.reported) this.#reported--;
        dirtyMs = Math.min(dirtyMs, old.start_ms);
      }
      this.#placed[i] = placed;
      this.#descents += this.#descends(i) + this.#descends(i + 1);
      if (placed.reported) this.#reported++;
      dirtyMs = Math.min(dirtyMs, start_ms);
      this.#prefixEndMs[i] = Math.max(this.#prefixEndMs[i - 1] ?? Number.NEGATIVE_INFINITY, tail);
    }
    // Strokes kept after the last re-placed one: their prefix ends follow, until one stays.
    for (let i = Math.max(stop, 1); i < this.#placed.length; i++) {
      const placed = this.#placed[i]!;
      const value = Math.max(this.#prefixEndMs[i - 1]!, placed.start_ms + placed.played_ms);
      if (value === this.#prefixEndMs[i]) break;
      this.#prefixEndMs[i] = value;
    }
    if (dirtyMs !== Number.POSITIVE_INFINITY && this.#dirty !== "all") {
      this.#dirty = this.#dirty === null ? dirtyMs : Math.min(this.#dirty, dirtyMs);
    }
  }

  /** 1 when stroke `i` starts before the stroke before it, else 0. */
  #descends(i: number): number {
    const before = this.#placed[i - 1];
    const stroke = this.#placed[i];
    return before !== undefined && stroke !== undefined && stroke.start_ms < before.start_ms ? 1 : 0;
  }
}
