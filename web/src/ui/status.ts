/** The connection indicator: broker, sleeve, unsent strokes, and one notice line for problems. */
import type { BrokerState } from "../mqtt/sender";

/** unknown: not heard of yet; absent: the broker holds no status for this id (nothing listens). */
export type SleeveState = "online" | "offline" | "unknown" | "absent";

export class StatusBar {
  readonly #broker: HTMLElement;
  readonly #sleeve: HTMLElement;
  readonly #unsent: HTMLElement;
  readonly #notice: HTMLElement;

  constructor(root: Document) {
    this.#broker = byId(root, "broker-status");
    this.#sleeve = byId(root, "sleeve-status");
    this.#unsent = byId(root, "unsent");
    this.#notice = byId(root, "notice");
  }

  setBroker(state: BrokerState, detail: string | null): void {
    const text = {
      connected: "Broker: connected",
      connecting: "Broker: connecting…",
      offline: "Broker: offline",
    }[state];
    setChip(this.#broker, state, text, detail ?? text);
  }

  /** `brokerConnected`: unknown then means not heard from yet; without the broker it cannot be known. */
  setSleeve(
    state: SleeveState,
    sleeveId: string,
    detail: string | null = null,
    brokerConnected = true,
  ): void {
    const text = {
      online: `Sleeve ${sleeveId}: online`,
      offline: `Sleeve ${sleeveId}: offline`,
      unknown: brokerConnected ? `Sleeve ${sleeveId}: not seen yet` : `Sleeve ${sleeveId}: unknown`,
      absent: `Sleeve ${sleeveId}: none listening`,
    }[state];
    setChip(this.#sleeve, state, text, detail ?? text);
  }

  setUnsent(count: number): void {
    this.#unsent.hidden = count === 0;
    this.#unsent.dataset["count"] = String(count);
    this.#unsent.textContent = count === 1 ? "1 stroke unsent" : `${count} strokes unsent`;
    this.#unsent.title =
      "Strokes not yet acknowledged by the broker: they are sent as soon as it is reachable.";
  }

  /** One line above the canvas; null hides it. Errors are shown until resolved. */
  setNotice(text: string | null, kind: "info" | "warn" | "error" = "info"): void {
    // Only real changes touch the DOM: a notice rewritten on every reconnection attempt would flicker.
    const hidden = text === null;
    if (this.#notice.hidden !== hidden) this.#notice.hidden = hidden;
    if (this.#notice.textContent !== (text ?? "")) this.#notice.textContent = text ?? "";
    if (this.#notice.dataset["kind"] !== kind) this.#notice.dataset["kind"] = kind;
  }
}

function setChip(chip: HTMLElement, state: string, text: string, title: string): void {
  chip.dataset["state"] = state;
  const label = chip.querySelector(".chip-text");
  if (label !== null) label.textContent = text;
  chip.title = title;
}

export function byId<T extends HTMLElement = HTMLElement>(root: Document, id: string): T {
  const element = root.getElementById(id);
  if (element === null) throw new Error(`The page has no #${id}: index.html and the script disagree.`);
  return element as T;
}
