/**
 * The "Sleeve says" card for the current drawing: its name, what became of
 * its strokes, and the latest notes. What became of each stroke is the rule of
 * fates.ts (the one `up`'s terminal line and the study report from): played,
 * cut short, cancelled or refused, each stroke once, and never sent for those
 * dropped before they left; so the counts add up to the strokes drawn once the
 * sleeve has answered them all. Reset with every new drawing, so nothing of an
 * old drawing lingers.
 */
import { seconds, type SleeveEvent } from "../events";
import { cutShortWords, DrawingFates, type Fate } from "../fates";
import { EventLog, type LogKind } from "./event-log";

export interface Counts {
  /** The drawing's strokes: sent, or dropped before they left. */
  sent: number;
  /** Played whole. */
  played: number;
  refused: number;
  /** Dropped by Stop before they started (on the sleeve). */
  cancelled: number;
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
  /** Kept on the page, not sent, while the wearer paused the sleeve (wearer-hold.ts). */
  #held = 0;
  #heldWhy = "the wearer paused";
  #drawing: string | null = null;

  constructor(title: HTMLElement, list: HTMLOListElement, summary: HTMLElement) {
    this.#title = title;
    this.#list = list;
    this.#summary = summary;
    this.#log = new EventLog(list, summary);
  }

  get counts(): Readonly<Counts> {
    const causes = this.#fates.cutCauses();
    return {
      sent: this.#sent,
      ...this.#fates.counts(),
      cutByWearer: causes.byWearer,
      cutByFault: causes.byFault,
      dropped: this.#dropped,
      held: this.#held,
      heldWhy: this.#heldWhy,
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
    this.#held = 0;
    this.#list.replaceChildren();
    this.#title.textContent =
      drawing === null ? "Sleeve says" : `Sleeve says · drawing ${drawing.slice(0, 8)}`;
    this.#title.title = drawing ?? "";
    this.#render();
  }

  /** An event about a stroke of this drawing: the stroke's fate now (fates.ts). */
  fate(event: SleeveEvent): Fate | null {
    const fate = this.#fates.add(event);
    this.#render();
    return fate;
  }

  /** Stroke `seq`'s fate so far (fates.ts); null before the sleeve answered it. */
  fateOf(seq: number): Fate | null {
    return this.#fates.fate(seq);
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

  setSent(sent: number): void {
    this.#sent = sent;
    this.#render();
  }

  add(kind: LogKind, text: string): void {
    this.#log.add(kind, text);
  }

  #render(): void {
    const { played, refused, cancelled, cut, cutByWearer, cutByFault, dropped, delayed, latestDelayMs } =
      this.counts;
    const summary = this.#summary;
    summary.dataset["played"] = String(played);
    summary.dataset["sent"] = String(this.#sent);
    summary.dataset["refused"] = String(refused);
    summary.dataset["cut"] = String(cut);
    summary.dataset["cancelled"] = String(cancelled);
    summary.dataset["dropped"] = String(dropped);
    summary.dataset["delayed"] = String(delayed);
    summary.dataset["held"] = String(this.#held);
    // Of the refused: by the wearer's pause or "do not disturb" (the page heard of it late).
    const refusals = this.#fates.refusals();
    const paused = refusals.get("paused") ?? 0;
    const quiet = refusals.get("do_not_disturb") ?? 0;
    summary.dataset["wearerRefused"] = String(paused + quiet);
    if (this.#sent === 0 && dropped === 0) {
      summary.textContent = "No strokes sent yet.";
      return;
    }
    // Each stroke under one fate: the parts add up to the strokes drawn once all are answered.
    const parts = [`${played} of ${plural(this.#sent, "stroke")} played`];
    parts.push(...cutShortWords(cut, { byWearer: cutByWearer, byFault: cutByFault }));
    if (cancelled > 0) parts.push(`${cancelled} cancelled by Stop`);
    if (refused > 0) {
      const wearer: string[] = [];
      if (paused > 0)
        wearer.push(paused === refused ? "the wearer paused" : `${paused} as the wearer paused`);
      if (quiet > 0) {
        wearer.push(
          quiet === refused
            ? "the wearer asked not to be disturbed"
            : `${quiet} as the wearer asked not to be disturbed`,
        );
      }
      parts.push(`${refused} refused${wearer.length === 0 ? "" : ` (${wearer.join(", ")})`}`);
    }
    if (this.#held > 0) parts.push(`${this.#held} held on this page, not sent (${this.#heldWhy})`);
    if (dropped > 0) parts.push(`${dropped} never sent`);
    const waiting = this.#sent - played - cut - cancelled - refused - dropped - this.#held;
    if (waiting > 0 && (cut > 0 || cancelled > 0)) parts.push(`${waiting} not answered yet`);
    if (delayed > 0) parts.push(`${delayed} delayed on the way (last by ${seconds(latestDelayMs)})`);
    summary.textContent = `${parts.join(", ")}.`;
  }
}

function plural(count: number, noun: string): string {
  return `${count} ${noun}${count === 1 ? "" : "s"}`;
}
