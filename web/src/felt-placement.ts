/**
 * The current drawing's strokes placed in time (felt.ts's rule), kept up to
 * date stroke by stroke instead of placed again from scratch: a new stroke,
 * a report from the sleeve or a cut re-places only the strokes from the one
 * it touches to the first that stays where it was, so the page's cost per
 * stroke and per sleeve event does not grow with the drawing. Gives the same
 * placement as the full computation (felt-panel's former `#place`):
 *
 *   - a stroke the sleeve refused on arrival is left out: it never entered the
 *     sleeve's queue, so it is not felt and holds no later stroke back;
 *   - times start at the first stroke's arrival (the shift);
 *   - the page's estimate is placeStrokes with the cuts and the strokes the
 *     duty-cycle cap kept from playing;
 *   - once the sleeve reported a stroke, its clock is anchored on the first
 *     stroke (in seq order) it reported: every reported start, less that
 *     offset, replaces the estimate.
 *
 * Pure: no DOM, no clock.
 */
import { caughtUp, feltEndMs, turnOf, type FeltStroke, type PlacedStroke } from "./felt";
import { QueueTail, SLEEVE_FLOOR_MS } from "./sleeve-queue";

export class FeltPlacement {
  /** Shifted strokes (arrival relative to the first stroke's), in seq order. */
  readonly #strokes: FeltStroke[] = [];
  readonly #placed: PlacedStroke[] = [];
  /** The largest end (start + played) of strokes 0..i: what is over by then. */
  readonly #prefixEndMs: number[] = [];
  /** The sleeve's queue tail after stroke i: where stroke i + 1 is placed from. */
  readonly #tailMs: number[] = [];
  readonly #indexBySeq = new Map<number, number>();
  /** seq -> start reported by the sleeve, on the sleeve's clock. */
  readonly #startedAt = new Map<number, number>();
  /** seq -> ms into the stroke at which a cancel cut it. */
  readonly #cut = new Map<number, number>();
  /** Seqs the duty-cycle cap kept from playing. */
  readonly #capped = new Set<number>();
  /** Seqs the sleeve refused on arrival: never placed. */
  readonly #refused = new Set<number>();
  /** Arrival (unshifted) of the first stroke: the timeline's zero. */
  #shiftMs = 0;
  /** Index of the first stroke the sleeve reported, and its clock's offset; null before any. */
  #anchor: { index: number; offsetMs: number } | null = null;
  /** Strokes whose start the sleeve reported, and strokes its duty-cycle cap kept from playing. */
  #reported = 0;
  #cappedCount = 0;
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
    const sorted = strokes.filter((s) => !this.#refused.has(s.seq)).sort((a, b) => a.seq - b.seq);
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
    if (this.#refused.has(stroke.seq)) return;
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

  /** The sleeve's duty-cycle cap kept stroke `seq` from playing: nothing felt, its turn kept. */
  cap(seq: number): void {
    if (this.#capped.has(seq)) return;
    this.#capped.add(seq);
    const index = this.#indexBySeq.get(seq);
    // Its turn holds the queue as if it played: no estimate moves, the anchor's neither.
    if (index !== undefined) this.#placeFrom(index, false);
  }

  /** The sleeve refused stroke `seq` on arrival: never felt, it gives its place to the strokes after it. */
  refuse(seq: number): void {
    if (this.#refused.has(seq)) return;
    this.#refused.add(seq);
    const index = this.#indexBySeq.get(seq);
    if (index === undefined) return;
    if (index === 0 || (this.#anchor !== null && index <= this.#anchor.index)) {
      // The timeline's zero, or the estimate the sleeve's clock is anchored on, moves.
      this.reset(this.#unshifted());
      return;
    }
    const removed = this.#placed[index]!;
    this.#descents -= this.#descends(index) + this.#descends(index + 1);
    for (const list of [this.#strokes, this.#placed, this.#prefixEndMs, this.#tailMs]) list.splice(index, 1);
    this.#descents += this.#descends(index);
    this.#indexBySeq.delete(seq);
    for (let i = index; i < this.#strokes.length; i++) this.#indexBySeq.set(this.#strokes[i]!.seq, i);
    if (this.#anchor !== null && this.#anchor.index > index) {
      this.#anchor = { ...this.#anchor, index: this.#anchor.index - 1 };
    }
    this.#count(removed, -1);
    this.#markDirty(removed.start_ms);
    if (index < this.#strokes.length) {
      this.#placeFrom(index, false);
    }
  }

  get placed(): readonly PlacedStroke[] {
    return this.#placed;
  }

  /** How many strokes the sleeve reported it played (with their start). */
  get reportedCount(): number {
    return this.#reported;
  }

  /** How many strokes the sleeve's duty-cycle cap kept from playing. */
  get cappedCount(): number {
    return this.#cappedCount;
  }

  /** Whether the sleeve's duty-cycle cap kept stroke `seq` from playing. */
  isCapped(seq: number): boolean {
    return this.#capped.has(seq);
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
    const queue = new QueueTail();
    for (let index = 0; index < this.#strokes.length; index++) {
      const stroke = this.#strokes[index]!;
      const played = caughtUp(stroke, queue.tailMs, this.floorMs);
      const estimateMs = queue.place(stroke.arrives_ms, turnOf(played, this.#cut, this.#capped).held_ms);
      const reported = this.#startedAt.get(stroke.seq);
      if (reported !== undefined) {
        this.#anchor = { index, offsetMs: reported - estimateMs };
        return;
      }
    }
  }

  /**
   * Places strokes from `from` on; unless `all`, stops at the first one after `from` that stays
   * where it was (every later one depends only on the one before it, so stays too).
   */
  #placeFrom(from: number, all: boolean): void {
    if (all) {
      this.#placed.length = 0;
      this.#prefixEndMs.length = 0;
      this.#tailMs.length = 0;
      this.#reported = 0;
      this.#cappedCount = 0;
      this.#descents = 0;
    }
    const queue = new QueueTail(this.#tailMs[from - 1]);
    let dirtyMs = Number.POSITIVE_INFINITY;
    const offset = this.#anchor?.offsetMs;
    let stop = this.#strokes.length;
    for (let i = from; i < this.#strokes.length; i++) {
      const stroke = this.#strokes[i]!;
      const reportedAt = offset === undefined ? undefined : this.#startedAt.get(stroke.seq);
      const known = reportedAt === undefined ? undefined : reportedAt - offset!;
      const played = caughtUp(stroke, queue.tailMs, this.floorMs);
      const turn = turnOf(played, this.#cut, this.#capped);
      const start_ms = queue.place(stroke.arrives_ms, turn.held_ms, known);
      const old = this.#placed[i];
      const placed: PlacedStroke = { ...played, start_ms, reported: known !== undefined, ...turn.felt };
      if (
        i > from &&
        old !== undefined &&
        old.start_ms === start_ms &&
        old.duration_ms === placed.duration_ms &&
        old.played_ms === placed.played_ms &&
        old.reported === placed.reported &&
        old.capped === placed.capped
      ) {
        stop = i;
        break;
      }
      // Descents are counted over the array as it stands: the two pairs this stroke is in.
      this.#descents -= this.#descends(i) + this.#descends(i + 1);
      if (old !== undefined) {
        this.#count(old, -1);
        dirtyMs = Math.min(dirtyMs, old.start_ms);
      }
      this.#placed[i] = placed;
      this.#descents += this.#descends(i) + this.#descends(i + 1);
      this.#count(placed, 1);
      dirtyMs = Math.min(dirtyMs, start_ms);
      this.#tailMs[i] = queue.tailMs;
      this.#prefixEndMs[i] = Math.max(
        this.#prefixEndMs[i - 1] ?? Number.NEGATIVE_INFINITY,
        feltEndMs(placed),
      );
    }
    // Strokes kept after the last re-placed one: their prefix ends follow, until one stays.
    for (let i = Math.max(stop, 1); i < this.#placed.length; i++) {
      const placed = this.#placed[i]!;
      const value = Math.max(this.#prefixEndMs[i - 1]!, feltEndMs(placed));
      if (value === this.#prefixEndMs[i]) break;
      this.#prefixEndMs[i] = value;
    }
    this.#markDirty(dirtyMs);
  }

  /** Counts a placed stroke in (+1) or out (-1). */
  #count(stroke: PlacedStroke, sign: 1 | -1): void {
    if (stroke.reported) this.#reported += sign;
    if (stroke.capped) this.#cappedCount += sign;
  }

  /** The picture changed from `fromMs` on. */
  #markDirty(fromMs: number): void {
    if (fromMs !== Number.POSITIVE_INFINITY && this.#dirty !== "all") {
      this.#dirty = this.#dirty === null ? fromMs : Math.min(this.#dirty, fromMs);
    }
  }

  /** 1 when stroke `i` starts before the stroke before it, else 0. */
  #descends(i: number): number {
    const before = this.#placed[i - 1];
    const stroke = this.#placed[i];
    return before !== undefined && stroke !== undefined && stroke.start_ms < before.start_ms ? 1 : 0;
  }
}
