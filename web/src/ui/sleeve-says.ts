/**
 * The "Sleeve says" card for the current drawing: its name, what became of
 * its strokes (played, refused, cancelled, dropped, delayed), and the latest
 * notes. Reset with every new drawing, so nothing of an old drawing lingers.
 */
import { seconds } from "../events";
import { EventLog, type LogKind } from "./event-log";

export interface Counts {
  played: number;
  refused: number;
  cancelled: number;
  /** Of the cancelled, those cut short while playing (also counted as played). */
  cut: number;
  /** Not sent: cancelled before they left, or dropped by the timing policy. */
  dropped: number;
  /** Played, but held on the way (events.ts `isDelayed`): not the sleeve's `late` refusal. */
  delayed: number;
  latestDelayMs: number;
}

const zero = (): Counts => ({
  played: 0,
  refused: 0,
  cancelled: 0,
  cut: 0,
  dropped: 0,
  delayed: 0,
  latestDelayMs: 0,
});

export class SleeveSays {
  readonly #title: HTMLElement;
  readonly #log: EventLog;
  readonly #list: HTMLOListElement;
  readonly #summary: HTMLElement;
  #counts: Counts = zero();
  #sent = 0;
  #drawing: string | null = null;

  constructor(title: HTMLElement, list: HTMLOListElement, summary: HTMLElement) {
    this.#title = title;
    this.#list = list;
    this.#summary = summary;
    this.#log = new EventLog(list, summary);
  }

  get counts(): Readonly<Counts> {
    return this.#counts;
  }

  /** A new drawing (or none): counts and notes start again. */
  reset(drawing: string | null): void {
    if (drawing === this.#drawing) return;
    this.#drawing = drawing;
    this.#counts = zero();
    this.#sent = 0;
    this.#list.replaceChildren();
    this.#title.textContent =
      drawing === null ? "Sleeve says" : `Sleeve says · drawing ${drawing.slice(0, 8)}`;
    this.#title.title = drawing ?? "";
    this.#render();
  }

  count(what: Exclude<keyof Counts, "latestDelayMs">, delayMs = 0): void {
    this.#counts[what]++;
    if (what === "delayed") this.#counts.latestDelayMs = delayMs;
    this.#render();
  }

  addDropped(count: number): void {
    this.#counts.dropped += count;
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
    const { played, refused, cancelled, cut, dropped, delayed, latestDelayMs } = this.#counts;
    const summary = this.#summary;
    summary.dataset["played"] = String(played);
    summary.dataset["sent"] = String(this.#sent);
    summary.dataset["refused"] = String(refused);
    summary.dataset["cancelled"] = String(cancelled);
    summary.dataset["dropped"] = String(dropped);
    summary.dataset["delayed"] = String(delayed);
    if (this.#sent === 0 && dropped === 0) {
      summary.textContent = "No strokes sent yet.";
      return;
    }
    const parts = [`${played} of ${this.#sent} stroke${this.#sent === 1 ? "" : "s"} played`];
    if (refused > 0) parts.push(`${refused} refused`);
    // A stroke stopped while playing was played in part: "4 of 4 played, 1 cancelled" would puzzle.
    if (cut > 0) parts.push(`${cut} cut short by Stop`);
    if (cancelled > cut) parts.push(`${cancelled - cut} cancelled before playing`);
    if (dropped > 0) parts.push(`${dropped} dropped unsent`);
    if (delayed > 0) parts.push(`${delayed} delayed on the way (last by ${seconds(latestDelayMs)})`);
    summary.textContent = `${parts.join(", ")}.`;
  }
}
