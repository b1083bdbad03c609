/** What the sleeve said about the strokes: a running count of played ones and the latest problems. */
import type { NoteKind } from "../events";

const MAX_ENTRIES = 6;

/** A line's kind (its colour): the notes `interpretEvent` gives, and the page's own. */
export type LogKind = NoteKind;

export class EventLog {
  readonly #list: HTMLOListElement;
  readonly #summary: HTMLElement;

  constructor(list: HTMLOListElement, summary: HTMLElement) {
    this.#list = list;
    this.#summary = summary;
  }

  add(kind: LogKind, text: string): void {
    const item = document.createElement("li");
    item.dataset["kind"] = kind;
    item.textContent = text;
    this.#list.prepend(item);
    while (this.#list.children.length > MAX_ENTRIES) this.#list.lastElementChild?.remove();
  }

  summarize(sent: number, played: number, refused: number): void {
    if (sent === 0) {
      this.#summary.textContent = "No strokes sent yet.";
      return;
    }
    const parts = [`${played} of ${sent} stroke${sent === 1 ? "" : "s"} played`];
    if (refused > 0) parts.push(`${refused} refused`);
    this.#summary.textContent = `${parts.join(", ")}.`;
    this.#summary.dataset["played"] = String(played);
    this.#summary.dataset["sent"] = String(sent);
  }
}
