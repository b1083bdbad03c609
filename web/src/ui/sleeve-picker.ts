/**
 * The sleeve picker: several sleeves may share one broker, and the sender
 * chooses which one to draw on. It lists the sleeves the server names in
 * /config.json, every sleeve whose retained status the broker holds, and the
 * chosen one, each with its state from that status. It is the sleeve chip's
 * own control (a native select over the chip: a phone opens its own list), shown
 * once there is more than one sleeve to choose from.
 */
import { parseStatus } from "../events";

export type PickerState = "online" | "offline" | "not seen";

export class SleevePicker {
  readonly #select: HTMLSelectElement;
  readonly #states = new Map<string, PickerState>();
  #known: readonly string[] = [];
  #current: string;

  constructor(select: HTMLSelectElement, current: string, onPick: (sleeveId: string) => void) {
    this.#select = select;
    this.#current = current;
    select.addEventListener("change", () => {
      if (select.value !== this.#current) onPick(select.value);
    });
    this.#render();
  }

  /** The sleeves the server says share its broker. */
  setKnown(sleeveIds: readonly string[]): void {
    this.#known = sleeveIds;
    this.#render();
  }

  setCurrent(sleeveId: string): void {
    this.#current = sleeveId;
    this.#render();
  }

  /** A sleeve's retained status ("" when cleared: nothing listens there any more). */
  setStatus(sleeveId: string, payload: string): void {
    const status = payload.trim() === "" ? null : parseStatus(payload);
    if (status === null) this.#states.delete(sleeveId);
    else this.#states.set(sleeveId, status.online ? "online" : "offline");
    this.#render();
  }

  /** The broker is gone: nothing is known about any sleeve now. */
  forget(): void {
    this.#states.clear();
    this.#render();
  }

  #render(): void {
    const ids = [...new Set([...this.#known, ...this.#states.keys(), this.#current])].sort((a, b) =>
      a.localeCompare(b, undefined, { numeric: true }),
    );
    const select = this.#select;
    const labels = ids.map((id) => `${id} · ${this.#states.get(id) ?? "not seen"}`);
    const same =
      select.options.length === ids.length &&
      ids.every((id, i) => select.options[i]!.value === id && select.options[i]!.text === labels[i]);
    if (!same) {
      select.replaceChildren(
        ...ids.map((id, i) => {
          const option = document.createElement("option");
          option.value = id;
          option.text = labels[i]!;
          option.dataset["state"] = this.#states.get(id) ?? "not seen";
          return option;
        }),
      );
    }
    select.value = this.#current;
    select.hidden = ids.length < 2;
  }
}
