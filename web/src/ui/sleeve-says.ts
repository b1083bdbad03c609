/**
 * The "Sleeve says" card for the current drawing: its name, what became of
 * its strokes, and the latest notes. What became of each stroke is the rule of
 * fates.ts (the one `up`'s terminal line and the study report from): played,
 * cut short, cancelled or refused, each stroke once, and never sent for those
 * dropped before they left; so the counts add up to the strokes drawn once the
 * sleeve has answered them all. Of the played, it says how many the sleeve played
 * faster to catch up with the pen (and how much shorter in all) and how many it
 * slowed to its floor; of the refused, how many it skipped as late, apart from the
 * other refusals (fates.ts `CatchUp`, the words `up` and `send --wait` use too).
 * A drawing sent all at once (Play again) has no pen to catch up with: the sleeve plays its strokes
 * back to back, and the card says so, and how much shorter than drawn that was (the pauses between
 * strokes left out, and the strokes played faster). A drawing shown but not sent (loaded, or
 * re-simplified) is said to be not sent yet, not as strokes the sleeve failed to play.
 * Reset with every new drawing, so nothing of an old drawing lingers.
 */
import { seconds, type SleeveEvent } from "../events";
import {
  cancelledWords,
  catchUpWords,
  cutShortWords,
  durationWords,
  DrawingFates,
  type Fate,
} from "../fates";
import { EventLog, type LogKind } from "./event-log";

export interface Counts {
  /** The drawing's strokes: sent, or dropped before they left. */
  sent: number;
  /** Played whole. */
  played: number;
  /** Of the played: faster to catch up (and how much shorter in all, ms), and slowed to the floor. */
  compressed: number;
  compressedMs: number;
  slowed: number;
  /** Of the sent: drawn briefer than the sleeve's floor and sent to last it (the page's own). */
  lengthened: number;
  /** Refused, `late` among them. */
  refused: number;
  /** Of the refused: skipped as `late` (the sleeve too far behind its sender). */
  late: number;
  /** Dropped by Stop before they started (on the sleeve). */
  cancelled: number;
  /** Of the cancelled: by the wearer (their stop or block), not the sender's Stop. */
  cancelledByWearer: number;
  /** Cut short while playing (by Stop, the wearer or a fault): felt in part, not under played. */
  cut: number;
  /** Of the cut: by the wearer, and by a fault on the sleeve (fates.ts `cutCauses`). */
  cutByWearer: number;
  cutByFault: number;
  /** Never sent: dropped before they left, by Stop or by the timing policy. */
  dropped: number;
  /** Played, but held on the way (events.ts `isDelayed`): not the sleeve's `late` refusal. */
  delayed: number;
  latestDelayMs: number;
  /** Held on this page, not sent yet (the wearer paused), and why (`holdReason`). */
  held: number;
  heldWhy: string;
  /** Shown on the page but not sent (loaded, or re-simplified): Play again sends them. */
  notSent: number;
}

/**
 * How a drawing reached the sleeve, when not as it was drawn: shown but not sent (`notSent`: how,
 * "loaded" or "re-simplified"), or sent all at once by Play again (`replay`: how long the drawing
 * took to draw, ms, and the span the sleeve played its strokes over, first start to last end, null
 * before any played).
 */
export interface Delivery {
  readonly notSentWhy?: string;
  readonly replay?: { readonly drawnMs: number; readonly spanMs: number | null };
}

export class SleeveSays {
  readonly #title: HTMLElement;
  readonly #log: EventLog;
  readonly #list: HTMLOListElement;
  readonly #summary: HTMLElement;
  #fates = new DrawingFates();
  #dropped = 0;
  #delayed = 0;
  #latestDelayMs = 0;
  #sent = 0;
  #lengthened = 0;
  /** Kept on the page, not sent, while the wearer paused the sleeve (wearer-hold.ts). */
  #held = 0;
  #heldWhy = "the wearer paused";
  #drawing: string | null = null;
  /** Strokes shown, not sent (loaded or re-simplified), and how they came. */
  #notSent = 0;
  #notSentWhy = "loaded";
  /** Sent all at once by Play again: how long the drawing took to draw (ms); null: not a replay. */
  #replayOfMs: number | null = null;
  /** The sleeve's own times of the strokes it played: the first start and the last end (ms). */
  #firstStartMs = Infinity;
  #lastEndMs = -Infinity;

  constructor(title: HTMLElement, list: HTMLOListElement, summary: HTMLElement) {
    this.#title = title;
    this.#list = list;
    this.#summary = summary;
    this.#log = new EventLog(list, summary);
  }

  get counts(): Readonly<Counts> {
    const causes = this.#fates.cutCauses();
    const catchUp = this.#fates.catchUp();
    return {
      sent: this.#sent,
      ...this.#fates.counts(),
      compressed: catchUp.compressed,
      compressedMs: catchUp.compressed_ms,
      slowed: catchUp.slowed,
      lengthened: this.#lengthened,
      late: catchUp.late,
      cutByWearer: causes.byWearer,
      cutByFault: causes.byFault,
      cancelledByWearer: this.#fates.cancelledByWearer(),
      dropped: this.#dropped,
      held: this.#held,
      heldWhy: this.#heldWhy,
      notSent: this.#notSent,
      delayed: this.#delayed,
      latestDelayMs: this.#latestDelayMs,
    };
  }

  /** The drawing the card is about (null: none). */
  get drawingId(): string | null {
    return this.#drawing;
  }

  /** A new drawing (or none): counts and notes start again. */
  reset(drawing: string | null): void {
    if (drawing === this.#drawing) return;
    this.#drawing = drawing;
    this.#fates = new DrawingFates();
    this.#dropped = 0;
    this.#delayed = 0;
    this.#latestDelayMs = 0;
    this.#sent = 0;
    this.#lengthened = 0;
    this.#held = 0;
    this.#notSent = 0;
    this.#replayOfMs = null;
    this.#firstStartMs = Infinity;
    this.#lastEndMs = -Infinity;
    this.#list.replaceChildren();
    this.#title.textContent =
      drawing === null ? "Sleeve says" : `Sleeve says · drawing ${drawing.slice(0, 8)}`;
    this.#title.title = drawing ?? "";
    this.#render();
  }

  /** An event about a stroke of this drawing: the stroke's fate now (fates.ts). */
  fate(event: SleeveEvent): Fate | null {
    const fate = this.#fates.add(event);
    if (event.type === "played" || event.type === "adjusted") {
      this.#firstStartMs = Math.min(this.#firstStartMs, event.start_at_ms);
      this.#lastEndMs = Math.max(this.#lastEndMs, event.start_at_ms + event.duration_ms);
    }
    this.#render();
    return fate;
  }

  /** Stroke `seq`'s fate so far (fates.ts); null before the sleeve answered it. */
  fateOf(seq: number): Fate | null {
    return this.#fates.fate(seq);
  }

  /** Why stroke `seq` was refused (or who cut it): fates.ts; null when neither. */
  reasonOf(seq: number): string | null {
    return this.#fates.reason(seq);
  }

  /** A played stroke held on the way for `delayMs`. */
  delayed(delayMs: number): void {
    this.#delayed++;
    this.#latestDelayMs = delayMs;
    this.#render();
  }

  addDropped(count: number): void {
    this.#dropped += count;
    this.#render();
  }

  /** How many of the drawing's strokes are held on the page now, not sent, and why (`holdReason`). */
  setHeld(held: number, why: string | null = null): void {
    this.#held = held;
    if (why !== null) this.#heldWhy = why;
    this.#render();
  }

  /**
   * `count` strokes of this drawing are shown on the page, not sent (`why`: "loaded" or
   * "re-simplified"): Play again sends them.
   */
  notSent(count: number, why: string): void {
    this.#notSent = count;
    this.#notSentWhy = why;
    this.#render();
  }

  /** This drawing was sent all at once (Play again) of one that took `drawnMs` to draw. */
  replayed(drawnMs: number): void {
    this.#replayOfMs = drawnMs;
    this.#render();
  }

  /** The drawing's strokes, and of them those sent lasting the sleeve's floor (`lengthened`). */
  setSent(sent: number, lengthened = 0): void {
    this.#sent = sent;
    this.#lengthened = lengthened;
    this.#render();
  }

  add(kind: LogKind, text: string): void {
    this.#log.add(kind, text);
  }

  #render(): void {
    const counts = this.counts;
    const summary = this.#summary;
    for (const key of [
      "played",
      "compressed",
      "slowed",
      "lengthened",
      "late",
      "sent",
      "refused",
      "cut",
      "cancelled",
      "dropped",
      "delayed",
      "held",
      "notSent",
    ] as const)
      summary.dataset[key] = String(counts[key]);
    summary.dataset["compressedMs"] = String(Math.round(counts.compressedMs));
    // Of the refused: by the wearer's pause or "do not disturb" (the page heard of it late).
    const refusals = this.#fates.refusals();
    const paused = refusals.get("paused") ?? 0;
    const quiet = refusals.get("do_not_disturb") ?? 0;
    summary.dataset["wearerRefused"] = String(paused + quiet);
    const spanMs = this.#lastEndMs > this.#firstStartMs ? this.#lastEndMs - this.#firstStartMs : null;
    const replay = this.#replayOfMs === null ? undefined : { drawnMs: this.#replayOfMs, spanMs };
    summary.dataset["replay"] = replay === undefined ? "no" : "yes";
    summary.dataset["drawnMs"] = replay === undefined ? "" : String(Math.round(replay.drawnMs));
    summary.dataset["spanMs"] = spanMs === null ? "" : String(Math.round(spanMs));
    summary.textContent = summaryText(
      counts,
      { paused, quiet },
      { notSentWhy: this.#notSentWhy, ...(replay === undefined ? {} : { replay }) },
    );
  }
}

/**
 * The card's sentence: each stroke under one fate, so the parts add up to the strokes drawn once
 * all are answered. Of the played, those the sleeve played faster to catch up or slowed to its
 * floor (in brackets: they are played too); of the refused, those it skipped as late, apart.
 * `wearer`: of the refused, those refused as the wearer paused or asked not to be disturbed.
 */
export function summaryText(
  counts: Readonly<Counts>,
  wearer: { paused: number; quiet: number },
  delivery: Delivery = {},
): string {
  const { sent, played, refused, late, cancelled, cut, dropped, held, delayed } = counts;
  const notSent = Math.min(counts.notSent, sent);
  const notSentWords = `${plural(notSent, "stroke")} ${delivery.notSentWhy ?? "loaded"}, not sent yet: Play again sends them`;
  if (notSent > 0 && notSent === sent && dropped === 0) return `${notSentWords}.`;
  if (sent === 0 && dropped === 0) return "No strokes sent yet.";
  const waiting = sent - notSent - played - cut - cancelled - refused - dropped - held;
  const pace =
    delivery.replay === undefined
      ? catchUpWords({
          compressed: counts.compressed,
          compressed_ms: counts.compressedMs,
          slowed: counts.slowed,
          late,
        })
      : replayWords(counts, delivery.replay, waiting === 0);
  // The strokes drawn faster than the sleeve plays, sent at its floor: felt longer than drawn.
  const lengthened =
    counts.lengthened > 0 && notSent < sent
      ? `${counts.lengthened} drawn faster than the sleeve can play, sent at its floor`
      : "";
  const playedWords = [pace, lengthened].filter((words) => words !== "").join("; ");
  // Of the strokes sent: those shown but not sent yet are said apart.
  const parts = [
    `${played} of ${plural(sent - notSent, "stroke")} played${playedWords === "" ? "" : ` (${playedWords})`}`,
  ];
  parts.push(...cutShortWords(cut, { byWearer: counts.cutByWearer, byFault: counts.cutByFault }));
  parts.push(...cancelledWords(cancelled, counts.cancelledByWearer));
  if (late > 0) parts.push(`${late} skipped as late`);
  const otherwise = refused - late;
  if (otherwise > 0) {
    const { paused, quiet } = wearer;
    const why: string[] = [];
    if (paused > 0) why.push(paused === otherwise ? "the wearer paused" : `${paused} as the wearer paused`);
    if (quiet > 0) {
      why.push(
        quiet === otherwise
          ? "the wearer asked not to be disturbed"
          : `${quiet} as the wearer asked not to be disturbed`,
      );
    }
    parts.push(`${otherwise} refused${why.length === 0 ? "" : ` (${why.join(", ")})`}`);
  }
  if (held > 0) parts.push(`${held} held on this page, not sent (${counts.heldWhy})`);
  if (dropped > 0) parts.push(`${dropped} never sent`);
  if (notSent > 0) parts.push(notSentWords);
  if (waiting > 0 && (cut > 0 || cancelled > 0)) parts.push(`${waiting} not answered yet`);
  if (delayed > 0) parts.push(`${delayed} delayed on the way (last by ${seconds(counts.latestDelayMs)})`);
  return `${parts.join(", ")}.`;
}

/**
 * What to say of the strokes of a drawing sent all at once (Play again), played: back to back, as
 * the sleeve plays what it has in hand; once all are answered, how long that took and how much
 * shorter than drawn (the pauses between strokes left out, and the strokes played faster, down to
 * the sleeve's floor); and the strokes slowed to its floor.
 */
function replayWords(
  counts: Readonly<Counts>,
  replay: NonNullable<Delivery["replay"]>,
  answered: boolean,
): string {
  const words = ["back to back"];
  const { drawnMs, spanMs } = replay;
  if (answered && spanMs !== null) {
    const shorterMs = drawnMs - spanMs;
    const faster = counts.compressed === 0 ? "" : ` and ${plural(counts.compressed, "stroke")} played faster`;
    words[0] +=
      shorterMs >= 100
        ? ` in ${durationWords(spanMs)}, ${durationWords(shorterMs)} shorter than drawn: the pauses left out${faster}`
        : ` in ${durationWords(spanMs)}`;
  }
  if (counts.slowed > 0) words.push(`${counts.slowed} slowed to the sleeve's floor`);
  return words.join("; ");
}

function plural(count: number, noun: string): string {
  return `${count} ${noun}${count === 1 ? "" : "s"}`;
}
