/**
 * What became of each stroke of a drawing: the page's copy of Python's `feelmysign.fates`, the
 * one rule the page, `up`'s terminal line and the study report from, so that their counts agree
 * and add up to the strokes answered. `testdata/events/fates` keeps the two equal.
 *
 * - played: its `played` (or `adjusted`) event: felt whole;
 * - cut: cut short by Stop (or the wearer's pause or stop, `by` "wearer") while it played
 *   (`cancelled`, started): felt in part, counted here only;
 * - cancelled: dropped by Stop before it started (`cancelled` not started, or refused as
 *   `cancelled` on arrival);
 * - refused: refused for any other reason (the wearer's `paused` and `do_not_disturb` too: never
 *   felt), or kept from playing by the duty-cycle cap.
 *
 * A copy the broker delivers again after a restart (or after Stop) is refused (`duplicate`, or
 * `cancelled`): that never changes a fate the stroke has. The stroke's own events rank above any
 * refusal (cut, played, then cancelled or capped), and of two refusals the first stands. A
 * `duplicate` of a stroke with no fate yet takes the fate its `original_played` says.
 * The page adds one fate no sleeve sees: never sent (dropped before it left).
 */
import type { SleeveEvent } from "./events";

export type Fate = "played" | "cut" | "cancelled" | "refused";
export const FATES: readonly Fate[] = ["played", "cut", "cancelled", "refused"];

const DUPLICATE = "duplicate";
const CANCELLED = "cancelled";
const DUTY_CYCLE = "duty_cycle";
const WEARER = "wearer";
// How much an event says about its stroke: higher replaces lower, equal never does.
const COPY = 1;
const REFUSAL = 2;
const OWN = 3;
const PLAYED = 4;
const CUT = 5;

interface Verdict {
  readonly rank: number;
  readonly fate: Fate;
  /** Why it was refused; for a cut, who or what cut it: "wearer", a safety reason, null for Stop. */
  readonly reason: string | null;
}

/** Of the strokes cut short: how many the wearer cut, and how many a fault on the sleeve did. */
export interface CutCauses {
  readonly byWearer: number;
  readonly byFault: number;
}

/** What `event` says of its stroke; null when nothing (an error, a safety off outside a stroke). */
export function verdict(event: SleeveEvent, playedBefore: boolean): Verdict | null {
  switch (event.type) {
    case "played":
    case "adjusted":
      return { rank: PLAYED, fate: "played", reason: null };
    case "cancelled":
      return event.started
        ? { rank: CUT, fate: "cut", reason: event.by === WEARER ? WEARER : null }
        : { rank: OWN, fate: "cancelled", reason: null };
    case "safety":
      if (event.received_at_ms === null) return null;
      if (event.reason !== DUTY_CYCLE && playedBefore)
        return { rank: CUT, fate: "cut", reason: event.reason };
      return { rank: OWN, fate: "refused", reason: event.reason };
    case "rejected":
      if (event.reason === DUPLICATE) {
        return event.original_played === true
          ? { rank: COPY, fate: "played", reason: null }
          : { rank: COPY, fate: "refused", reason: DUPLICATE };
      }
      if (event.reason === CANCELLED) return { rank: REFUSAL, fate: "cancelled", reason: null };
      return { rank: REFUSAL, fate: "refused", reason: event.reason };
    case "error":
      return null;
  }
}

/** The fates of one drawing's strokes: events in (each once), counts out. */
export class DrawingFates {
  readonly #bySeq = new Map<number, Verdict>();
  readonly #unnamed: Verdict[] = [];

  /** Takes `event` into account; the stroke's fate now (null: it says nothing of one). */
  add(event: SleeveEvent): Fate | null {
    const seq = "seq" in event ? event.seq : null;
    const known = seq === null ? undefined : this.#bySeq.get(seq);
    const said = verdict(event, known?.fate === "played");
    if (said === null) return known?.fate ?? null;
    if (seq === null) {
      this.#unnamed.push(said);
      return said.fate;
    }
    if (known === undefined || said.rank > known.rank) {
      this.#bySeq.set(seq, said);
      return said.fate;
    }
    return known.fate;
  }

  fate(seq: number): Fate | null {
    return this.#bySeq.get(seq)?.fate ?? null;
  }

  fates(): Map<number, Fate> {
    return new Map([...this.#bySeq.entries()].sort(([a], [b]) => a - b).map(([seq, v]) => [seq, v.fate]));
  }

  /** How many strokes have each fate, every fate named (0 included). */
  counts(): Record<Fate, number> {
    const counts: Record<Fate, number> = { played: 0, cut: 0, cancelled: 0, refused: 0 };
    for (const { fate } of [...this.#bySeq.values(), ...this.#unnamed]) counts[fate]++;
    return counts;
  }

  /** Who or what cut the strokes cut short (the rest: the sender's Stop). */
  cutCauses(): CutCauses {
    let byWearer = 0;
    let byFault = 0;
    for (const { fate, reason } of [...this.#bySeq.values(), ...this.#unnamed]) {
      if (fate !== "cut" || reason === null) continue;
      if (reason === WEARER) byWearer++;
      else byFault++;
    }
    return { byWearer, byFault };
  }

  /** The refused strokes by reason, in the order first met. */
  refusals(): Map<string, number> {
    const out = new Map<string, number>();
    for (const { fate, reason } of [...this.#bySeq.values(), ...this.#unnamed]) {
      if (fate === "refused" && reason !== null) out.set(reason, (out.get(reason) ?? 0) + 1);
    }
    return out;
  }
}

/**
 * The card's and the caption's words for `cut` strokes cut short while playing: by Stop, by the
 * wearer (their pause or stop), or by a fault on the sleeve (a chip lost mid-stroke).
 */
export function cutShortWords(cut: number, causes: Partial<CutCauses> = {}): string[] {
  const byWearer = Math.min(cut, causes.byWearer ?? 0);
  const byFault = Math.min(cut - byWearer, causes.byFault ?? 0);
  const byStop = cut - byWearer - byFault;
  const words: string[] = [];
  if (byStop > 0) words.push(`${byStop} cut short by Stop`);
  if (byWearer > 0) words.push(`${byWearer} cut short by the wearer`);
  if (byFault > 0) words.push(`${byFault} cut short by a fault on the sleeve`);
  return words;
}
