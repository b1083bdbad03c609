/**
 * The wearer's choice above the drawing area: paused or "do not disturb" (the drawing is held on
 * the page), back again (with the offer to send what was held), and the wearer's intensity
 * ceiling. The words come from wearer-status.ts; this only puts them on the page.
 */
import type { WearerView } from "../wearer-hold";
import {
  endedHeadline,
  holdDetail,
  holdHeadline,
  holdReason,
  wearerStoppedDetail,
  wearerStoppedHeadline,
} from "../wearer-status";
import { byId } from "./status";

export interface WearerNoticeActions {
  sendHeld(): void;
  dropHeld(): void;
}

export class WearerNotice {
  readonly #box: HTMLElement;
  readonly #headline: HTMLElement;
  readonly #detail: HTMLElement;
  readonly #ceiling: HTMLElement;
  readonly #actions: HTMLElement;
  readonly #legend: HTMLElement;
  readonly #legendWhy: HTMLElement;

  constructor(doc: Document, actions: WearerNoticeActions) {
    this.#box = byId(doc, "wearer-notice");
    this.#headline = byId(doc, "wearer-headline");
    this.#detail = byId(doc, "wearer-detail");
    this.#ceiling = byId(doc, "wearer-ceiling");
    this.#actions = byId(doc, "wearer-actions");
    this.#legend = byId(doc, "legend-held");
    this.#legendWhy = byId(doc, "legend-held-why");
    byId(doc, "send-held-button").addEventListener("click", () => actions.sendHeld());
    byId(doc, "drop-held-button").addEventListener("click", () => actions.dropHeld());
  }

  /**
   * `ceiling`: the line about the wearer's ceiling (ceilingNote), or null; `nowMs`: for the day of
   * a time; `stopped`: the wearer stopped this drawing (said unless a pause or its end is).
   */
  show(view: WearerView, ceiling: string | null, nowMs: number, stopped = false): void {
    const state =
      view.state !== "none" ? view.state : stopped ? "stopped" : ceiling === null ? "none" : "ceiling";
    this.#box.dataset["state"] = state;
    this.#box.dataset["held"] = String(view.state === "none" ? 0 : view.held);
    this.#box.hidden = state === "none";
    this.#legend.hidden = view.state === "none" || view.held === 0;
    this.#actions.hidden = view.state !== "resumed" || view.held === 0;
    if (view.state === "held") {
      this.#legendWhy.textContent = holdReason(view.hold);
      this.#set(holdHeadline(view.hold, nowMs), holdDetail(view.hold, view.held, nowMs), ceiling);
    } else if (view.state === "resumed") {
      const detail =
        view.held === 0
          ? "What you draw now is sent again."
          : `${plural(view.held, "stroke")} drawn meanwhile ${view.held === 1 ? "is" : "are"} held here. ` +
            "Send them to play them now, back to back, or drop them; what you draw now is sent.";
      this.#set(endedHeadline(view.ended, nowMs), detail, ceiling);
    } else if (stopped) {
      this.#set(wearerStoppedHeadline, wearerStoppedDetail, ceiling);
    } else if (ceiling !== null) {
      this.#set(ceiling, null, null);
    }
  }

  #set(headline: string, detail: string | null, ceiling: string | null): void {
    this.#headline.textContent = headline;
    this.#detail.textContent = detail ?? "";
    this.#detail.hidden = detail === null;
    this.#ceiling.textContent = ceiling ?? "";
    this.#ceiling.hidden = ceiling === null;
  }
}

function plural(count: number, noun: string): string {
  return `${count} ${noun}${count === 1 ? "" : "s"}`;
}
