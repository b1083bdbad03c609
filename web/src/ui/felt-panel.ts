/**
 * The felt drawing, kept in step with the sleeve: the current drawing's
 * strokes placed in time (felt.ts) from the sleeve's `played` and `cancelled`
 * events (its own estimate until they come), without the strokes it refused
 * and with nothing felt of those its duty-cycle cap kept from playing, the timeline with a cursor
 * moving at the moment being felt, a marker on the canvas where the brush is,
 * and an A/B comparison with the same paths simplified under other settings.
 * Strokes never sent are not on the timeline. Its caption counts from the card's tally
 * (sleeve-says.ts, the rule of fates.ts), so the two never say different things.
 * A new stroke or a sleeve event costs the same however long the drawing is:
 * the placement is kept (felt-placement.ts), only the new strokes added.
 */
import type { Drawing, DrawnSegment } from "../drawing";
import type { CancelledEvent, AdjustedEvent, PlayedEvent, Unplayed } from "../events";
import { cancelledWords, cutShortWords, type Fate } from "../fates";
import { brushAt, placeStrokes, type FeltStroke, type Grid, type PlacedStroke } from "../felt";
import { FeltPlacement } from "../felt-placement";
import { simplifyPaths, type SimplifierParams } from "../simplify/registry";
import type { Point } from "../simplify/segment";
import type { DrawingView } from "./canvas";
import type { TimelineView } from "./timeline";

/** How the drawing's strokes reach the sleeve: as they were drawn, or all at once (Play again). */
export type Arrival = "as-drawn" | "at-once";

/** What became of the drawing's strokes, as the "Sleeve says" card counts them (fates.ts). */
export interface Tally {
  /** The strokes of the drawing: sent, or dropped before they left. */
  readonly sent: number;
  readonly played: number;
  readonly cut: number;
  /** Of the cut: by the wearer, and by a fault on the sleeve (the rest by Stop). */
  readonly cutByWearer?: number;
  readonly cutByFault?: number;
  readonly cancelled: number;
  /** Of the cancelled: by the wearer (their stop or block; the rest by Stop). */
  readonly cancelledByWearer?: number;
  /** Refused on arrival, or kept from playing by the duty-cycle cap. */
  readonly refused: number;
  /** Of the refused: skipped as late (the sleeve too far behind its sender), said apart. Absent: none. */
  readonly late?: number;
  /** Never sent. */
  readonly dropped: number;
  /**
   * Held on this page, not sent yet (the wearer paused the sleeve, or asked not to be disturbed):
   * counted in `sent`, not on the timeline until they go. Absent: none.
   */
  readonly held?: number;
  /** Why they are held, in the card's words (`holdReason`); absent: "the wearer paused". */
  readonly heldWhy?: string;
}

/** Where the caption reads the tally, and each stroke's fate: the card (SleeveSays). */
export interface TallySource {
  readonly counts: Tally;
  fateOf(seq: number): Fate | null;
  /** Why a stroke was refused, or who or what cut it (fates.ts); absent: never said. */
  reasonOf?(seq: number): string | null;
}

/**
 * A stroke of a path taken back with Undo: its fate (null: no answer yet), why it was refused or
 * who cut it, and whether it never left the page (dropped, or held when its path was taken back).
 */
export interface UndoneStroke {
  readonly fate: Fate | null;
  readonly reason: string | null;
  readonly unsent: "dropped" | "held" | null;
}

export class FeltPanel {
  readonly #timeline: TimelineView;
  readonly #view: DrawingView;
  readonly #told: TallySource;
  #drawing: Drawing | null = null;
  #arrival: Arrival = "as-drawn";
  #grid: Grid = { rows: 3, columns: 4 };
  /** seq -> when the sleeve started it, on the sleeve's wall clock. */
  readonly #startedAt = new Map<number, number>();
  #b: { params: SimplifierParams; placed: PlacedStroke[]; segments: [Point, Point][] } | null = null;
  /** The drawing's strokes in time, with the sleeve's reports and cuts. */
  #placement = new FeltPlacement();
  /** How many of the drawing's segments the placement has seen, and the last of them. */
  #segmentsSeen = 0;
  #lastSeen: object | null = null;
  /** The cursor runs from `t_ms` at `at` (performance.now()). */
  #anchor: { t_ms: number; at: number } | null = null;
  #running = false;
  /** Stop was pressed: what the sleeve has not played yet never will be. */
  #stopped = false;
  /**
   * seq -> when a stroke held on the page (the wearer paused) was sent after all, ms on the
   * drawing's clock: it reaches the sleeve then, not when it was drawn.
   */
  readonly #sentLateMs = new Map<number, number>();

  constructor(timeline: TimelineView, view: DrawingView, told: TallySource) {
    this.#timeline = timeline;
    this.#view = view;
    this.#told = told;
  }

  /** A new current drawing (or none): the cursor stops, the sleeve's reports are forgotten. */
  setDrawing(drawing: Drawing | null, grid: Grid, arrival: Arrival = "as-drawn"): void {
    this.#drawing = drawing;
    this.#grid = grid;
    this.#arrival = arrival;
    this.#startedAt.clear();
    this.#sentLateMs.clear();
    this.#stopped = false;
    this.#placement = new FeltPlacement();
    this.#segmentsSeen = 0;
    this.#lastSeen = null;
    this.#anchor = null;
    this.#b = null;
    this.#view.setCompare(null);
    this.refresh();
  }

  /** The drawing gained or lost strokes: placed again. */
  refresh(): void {
    this.#sync();
    const placement = this.#placement;
    this.#timeline.show(this.#grid, placement, this.#b?.placed ?? null);
    const count = placement.placed.length;
    const seconds = (placement.totalMs / 1000).toFixed(1);
    // The card counts every stroke the drawing sent; the timeline shows the drawing as it stands,
    // so the caption leaves out the strokes of paths taken back with Undo, and says so.
    const undone = this.#undone();
    const tally = standingTally(this.#told.counts, undone);
    const caption =
      count === 0 && tally.dropped === 0 && (tally.held ?? 0) === 0
        ? "Each lane is one actuator (row, column); draw to see where and when the touch is felt."
        : timelineCaption(
            { count, seconds, reported: placement.reportedCount, capped: placement.cappedCount },
            tally,
            this.#stopped,
          );
    const left = undoneWords(undone);
    this.#timeline.setCaption(left === null ? caption : `${caption} ${left}`);
  }

  /** What became of the strokes of the paths taken back with Undo, as the card counted them. */
  #undone(): UndoneStroke[] {
    const drawing = this.#drawing;
    if (drawing === null) return [];
    return drawing.undoneSeqs.map((seq) => ({
      fate: this.#told.fateOf(seq),
      reason: this.#told.reasonOf?.(seq) ?? null,
      unsent: drawing.unsent(seq),
    }));
  }

  /** When the felt drawing ends, ms from its first stroke (as the timeline shows it). */
  get totalMs(): number {
    return this.#placement.totalMs;
  }

  /** The sleeve played a stroke of this drawing: its real start, and the cursor from there. */
  played(event: PlayedEvent | AdjustedEvent): void {
    if (event.seq === null) return;
    this.#startedAt.set(event.seq, event.start_at_ms);
    this.#sync();
    this.#placement.report(event.seq, event.start_at_ms);
    this.refresh();
    const stroke = this.#placement.bySeq(event.seq);
    if (stroke === undefined) return;
    // Time since the sleeve started it: its report took a moment to arrive.
    const lag = Math.max(0, Math.min(event.latency_ms, stroke.duration_ms));
    this.#anchor = { t_ms: stroke.start_ms + lag, at: performance.now() };
    this.#run();
  }

  cancelled(event: CancelledEvent): void {
    if (event.seq === null) return;
    const started = this.#startedAt.get(event.seq);
    this.#sync();
    this.#placement.cut(
      event.seq,
      event.started && started !== undefined ? event.cancelled_at_ms - started : 0,
    );
    this.refresh();
  }

  /** The sleeve will never play a stroke of this drawing: refused, it leaves the timeline; capped, nothing of it is felt. */
  unplayed({ seq, why }: Unplayed): void {
    this.#sync();
    if (why === "refused") this.#placement.refuse(seq);
    else this.#placement.cap(seq);
    this.refresh();
  }

  /**
   * Strokes never sent (dropped before they left, by Stop or the late limit): off the timeline,
   * as nothing of them can be felt.
   */
  unsent(seqs: readonly number[]): void {
    this.#sync();
    for (const seq of seqs) this.#placement.refuse(seq);
    this.refresh();
  }

  /**
   * Strokes held on the page while the wearer paused were sent after all, at `atMs`
   * (performance.now(), the clock the drawing's samples are on): they join the timeline, arriving
   * then. Placed again from scratch: it happens once per resume, not once per stroke.
   */
  heldSent(seqs: readonly number[], atMs: number): void {
    if (seqs.length === 0) return;
    const origin = this.#drawing?.paths[0]?.[0]?.t_ms ?? 0;
    for (const seq of seqs) this.#sentLateMs.set(seq, atMs - origin);
    this.#segmentsSeen = 0;
    this.#lastSeen = HELD_CHANGED;
    this.refresh();
  }

  /**
   * The card's tally changed without a report the timeline places (a copy's refusal told the
   * fate): a stroke that now has a fate of not felt, and no report of its own, leaves the timeline.
   */
  told(seq: number | null): void {
    if (seq !== null && this.#told.fateOf(seq) === "refused" && !this.#placement.isCapped(seq)) {
      this.#sync();
      this.#placement.refuse(seq);
    }
    this.refresh();
  }

  /** Stop pressed: the cursor stops where it is. */
  stopCursor(): void {
    this.#anchor = null;
    this.#stopped = true;
    this.refresh();
  }

  /** Compares with the same paths under `params` (null: no comparison). */
  compare(params: SimplifierParams | null): number {
    const drawing = this.#drawing;
    if (params === null || drawing === null) {
      this.#b = null;
      this.#view.setCompare(null);
      this.refresh();
      return 0;
    }
    const pieces = simplifyPaths(params, drawing.paths).filter((p) => p.segment.dropped === null);
    const origin = drawing.paths[0]?.[0]?.t_ms ?? 0;
    const strokes: FeltStroke[] = pieces.map(({ segment }, seq) => ({
      seq,
      start: segment.start,
      end: segment.end,
      duration_ms: segment.duration_ms,
      intensity: drawing.strokes[0]?.intensity ?? 0.8,
      arrives_ms: this.#arrival === "at-once" ? 0 : segment.end_ms - origin,
    }));
    const segments = pieces.map(({ segment }) => [segment.start, segment.end] as [Point, Point]);
    this.#b = { params, placed: placeStrokes(strokes), segments };
    this.#view.setCompare(segments);
    this.refresh();
    return pieces.length;
  }

  /**
   * The placement follows the drawing: its new strokes appended (the usual case, one at a time);
   * anything else (an undo) places them all again.
   */
  #sync(): void {
    const drawing = this.#drawing;
    const segments = drawing?.segments ?? [];
    const seen = this.#segmentsSeen;
    const kept = seen === 0 ? this.#lastSeen === null : segments[seen - 1] === this.#lastSeen;
    if (seen <= segments.length && kept) {
      for (let i = seen; i < segments.length; i++) {
        const stroke = this.#feltStroke(segments[i]!);
        if (stroke !== null) this.#placement.append(stroke);
      }
    } else {
      const strokes: FeltStroke[] = [];
      for (const drawn of segments) {
        const stroke = this.#feltStroke(drawn);
        if (stroke !== null) strokes.push(stroke);
      }
      this.#placement.reset(strokes);
    }
    this.#segmentsSeen = segments.length;
    this.#lastSeen = segments[segments.length - 1] ?? null;
  }

  /**
   * A drawn segment as felt: arriving when it was drawn, at once, or when it was sent after being
   * held. Null for a dropped one, and for one held on the page now (the wearer paused): it is not
   * sent, so nothing of it can be felt yet (`heldSent` brings it in when it goes).
   */
  #feltStroke(drawn: DrawnSegment): FeltStroke | null {
    const { segment, stroke } = drawn;
    if (stroke === null || stroke.seq == null) return null;
    if (this.#drawing?.isHeld(drawn) === true) return null;
    const origin = this.#drawing?.paths[0]?.[0]?.t_ms ?? 0;
    const sentLateMs = this.#sentLateMs.get(stroke.seq);
    return {
      seq: stroke.seq,
      start: stroke.start,
      end: stroke.end,
      duration_ms: stroke.duration_ms,
      intensity: stroke.intensity ?? 0.8,
      arrives_ms: sentLateMs ?? (this.#arrival === "at-once" ? 0 : segment.end_ms - origin),
    };
  }

  #run(): void {
    if (this.#running) return;
    this.#running = true;
    const step = () => {
      const anchor = this.#anchor;
      const total = this.#placement.totalMs;
      const t = anchor === null ? null : anchor.t_ms + (performance.now() - anchor.at);
      if (t === null || t > total + 300) {
        this.#running = false;
        this.#timeline.setCursor(null);
        this.#view.drawMarker(null);
        return;
      }
      this.#timeline.setCursor(t);
      const now = this.#placement.playingAt(t);
      this.#view.drawMarker(now === null ? null : brushAt(now.stroke, now.into_ms));
      requestAnimationFrame(step);
    };
    requestAnimationFrame(step);
  }
}

/**
 * The caption: how many strokes over how long, then what became of them, in the card's counts
 * (`tally`, fates.ts) so the two always agree, and whose times the timeline shows: the sleeve's
 * for the strokes it reported, the page's estimate for the rest. A stroke with no answer yet is
 * "as it would" be felt only while it still may be: never once Stop was pressed. `timeline`: the
 * strokes on it, their length (s), how many the sleeve reported and how many its duty-cycle cap
 * kept from playing (on the timeline, silent). Strokes refused on arrival and never sent are not
 * on it, and are said apart.
 */
export function timelineCaption(
  timeline: {
    readonly count: number;
    readonly seconds: string;
    readonly reported: number;
    readonly capped: number;
  },
  tally: Tally,
  stopped: boolean,
): string {
  const { count, seconds, reported, capped } = timeline;
  const { played, cut, cancelled, refused, dropped } = tally;
  const held = tally.held ?? 0;
  const head = `${plural(count, "stroke")}, ${seconds} s`;
  // Held strokes are not sent yet: neither felt nor "what would be felt", said apart (as the card does).
  const heldPart = `${held} held on this page, not sent yet (${tally.heldWhy ?? "the wearer paused"}; not on the timeline)`;
  const waiting = Math.max(0, tally.sent - played - cut - cancelled - refused - dropped - held);
  if (held > 0 && held === tally.sent) return `${heldPart[0]!.toUpperCase()}${heldPart.slice(1)}.`;
  if (waiting === tally.sent - held && !stopped)
    return held === 0
      ? `${head}: what would be felt, played back to back as the sleeve does.`
      : `${head}: what would be felt, played back to back as the sleeve does; ${heldPart}.`;
  // Played strokes whose report never came (a copy's refusal told they were felt): the page places them.
  const placedByPage = Math.max(0, played - Math.max(0, reported - cut));
  if (played === tally.sent && played === count && placedByPage === 0 && held === 0)
    return `${head}, as the sleeve played them.`;
  const said: string[] = [];
  if (played > 0) {
    said.push(
      placedByPage === 0
        ? `${played} as the sleeve played them`
        : `${played} played (the times of ${placedByPage} are the page's: the sleeve's report of ${placedByPage === 1 ? "it" : "them"} never came)`,
    );
  }
  said.push(...cutShortWords(cut, { byWearer: tally.cutByWearer ?? 0, byFault: tally.cutByFault ?? 0 }));
  if (capped > 0) {
    said.push(
      `${capped} not felt (the sleeve's duty-cycle cap kept ${capped === 1 ? "it" : "them"} from playing)`,
    );
  }
  said.push(...cancelledWords(cancelled, tally.cancelledByWearer ?? 0, "before {it} played"));
  const refusedOff = refused - capped;
  // Skipped as late, as the card says them: refused on arrival too, apart from the others.
  const late = Math.min(tally.late ?? 0, refusedOff);
  if (late > 0) said.push(`${late} skipped as late (not on the timeline)`);
  if (refusedOff - late > 0) said.push(`${refusedOff - late} refused by the sleeve (not on the timeline)`);
  if (dropped > 0) said.push(`${dropped} never sent (not on the timeline)`);
  if (held > 0) said.push(heldPart);
  if (waiting > 0) said.push(stopped ? "the rest stopped: not felt" : "the rest as it would");
  return `${head}; ${said.join(", ")}.`;
}

/**
 * The card's tally of the drawing as it stands: `tally` (every stroke the drawing sent) less the
 * strokes of paths taken back with Undo (`undone`), each under the fate the card counted it.
 */
export function standingTally(tally: Tally, undone: readonly UndoneStroke[]): Tally {
  if (undone.length === 0) return tally;
  let { sent, played, cut, cancelled, refused, dropped } = tally;
  let late = tally.late ?? 0;
  let cutByWearer = tally.cutByWearer ?? 0;
  let cutByFault = tally.cutByFault ?? 0;
  let cancelledByWearer = tally.cancelledByWearer ?? 0;
  for (const { fate, reason, unsent } of undone) {
    sent--;
    if (fate === "played") played--;
    else if (fate === "cancelled") {
      cancelled--;
      if (reason === "wearer") cancelledByWearer--;
    } else if (fate === "cut") {
      cut--;
      if (reason === "wearer") cutByWearer--;
      else if (reason !== null) cutByFault--;
    } else if (fate === "refused") {
      refused--;
      if (reason === "late") late--;
    } else if (unsent === "dropped") dropped--;
  }
  const atLeast0 = (n: number) => Math.max(0, n);
  return {
    ...tally,
    sent: atLeast0(sent),
    played: atLeast0(played),
    cut: atLeast0(cut),
    cancelled: atLeast0(cancelled),
    refused: atLeast0(refused),
    dropped: atLeast0(dropped),
    late: atLeast0(late),
    cutByWearer: atLeast0(cutByWearer),
    cutByFault: atLeast0(cutByFault),
    cancelledByWearer: atLeast0(cancelledByWearer),
  };
}

/** What the caption adds of the strokes taken back with Undo (null: none), each under its fate. */
export function undoneWords(undone: readonly UndoneStroke[]): string | null {
  if (undone.length === 0) return null;
  const by = (test: (stroke: UndoneStroke) => boolean) => undone.filter(test).length;
  const parts: [number, string][] = [
    [by((s) => s.fate === "played"), "played"],
    [by((s) => s.fate === "cut"), "cut short"],
    [by((s) => s.fate === "cancelled" && s.reason !== "wearer"), "cancelled by Stop"],
    [by((s) => s.fate === "cancelled" && s.reason === "wearer"), "cancelled by the wearer"],
    [by((s) => s.fate === "refused" && s.reason === "late"), "skipped as late"],
    [by((s) => s.fate === "refused" && s.reason !== "late"), "not felt (refused by the sleeve)"],
    [by((s) => s.fate === null && s.unsent !== null), "never sent"],
    [by((s) => s.fate === null && s.unsent === null), "not answered yet"],
  ];
  const said = parts.filter(([n]) => n > 0).map(([n, words]) => `${n} ${words}`);
  return `Not counted: ${plural(undone.length, "stroke")} taken back with Undo (${said.join(", ")}).`;
}

/** Forces the next sync to place every stroke again (a held stroke went out). */
const HELD_CHANGED = {};

function plural(count: number, noun: string): string {
  return `${count} ${noun}${count === 1 ? "" : "s"}`;
}
