/**
 * What became of each stroke of a drawing: the page's copy of Python's `feelmysign.fates`, the
 * one rule the page, `up`'s terminal line and the study report from, so that their counts agree
 * and add up to the strokes answered. `testdata/events/fates` keeps the two equal.
 *
 * - played: its `played` (or `adjusted`) event: felt whole;
 * - cut: cut short by Stop (or the wearer's pause or stop, `by` "wearer") while it played
 *   (`cancelled`, started), or by a fault on the sleeve after its `played` (a `safety` event:
 *   `chip_lost`, the sleeve `stopped`, or its process ended, `crashed`): felt in part, counted
 *   here only;
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
 *
 * How the sleeve kept a drawing in time (`CatchUp`, docs/protocol.md, "Catching up"): of the
 * strokes played, how many it played faster to catch up with the pen (their `played` event's
 * `compressed_ms`) and by how much in all, and how many it slowed to its floor (`adjusted`); of
 * the refused, how many it skipped as `late`. Python's `CatchUp`; the vectors keep them equal.
 * A stroke counts as played faster or slowed only when its duration changed by
 * `NOTABLE_ADJUSTMENT` (5 %) or more of the duration it came with: a stroke of a drawing played
 * as drawn waits a few ms behind the one before it (the network's jitter), and is played that
 * much faster, which no one feels.
 */
import { NOTABLE_ADJUSTMENT, type AdjustedEvent, type PlayedEvent, type SleeveEvent } from "./events";

export type Fate = "played" | "cut" | "cancelled" | "refused";
export const FATES: readonly Fate[] = ["played", "cut", "cancelled", "refused"];

const DUPLICATE = "duplicate";
const CANCELLED = "cancelled";
const DUTY_CYCLE = "duty_cycle";
const WEARER = "wearer";
const LATE = "late";
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

/**
 * How the sleeve kept one drawing in time: `compressed` strokes played faster to catch up,
 * `compressed_ms` shorter in all; `slowed` strokes slowed to its floor (each counted under played);
 * and `late` strokes skipped (counted under refused).
 */
export interface CatchUp {
  readonly compressed: number;
  readonly compressed_ms: number;
  readonly slowed: number;
  readonly late: number;
}

/**
 * From the played events of the strokes played, each once, and the strokes refused as `late`;
 * changes below `NOTABLE_ADJUSTMENT` left out.
 */
export function catchUpOf(played: Iterable<PlayedEvent | AdjustedEvent>, late: number): CatchUp {
  let compressed = 0;
  let compressedMs = 0;
  let slowed = 0;
  for (const event of played) {
    const shorterMs = event.compressed_ms;
    if (
      shorterMs !== null &&
      shorterMs > 0 &&
      shorterMs >= NOTABLE_ADJUSTMENT * (event.duration_ms + shorterMs)
    ) {
      compressed++;
      compressedMs += shorterMs;
    }
    if (event.type === "adjusted") {
      const askedMs = event.requested_duration_ms;
      if (Math.abs(event.duration_ms - askedMs) >= NOTABLE_ADJUSTMENT * askedMs) slowed++;
    }
  }
  return { compressed, compressed_ms: compressedMs, slowed, late };
}

/**
 * What to say of the strokes played, in brackets after their count: "3 faster to catch up, 210 ms
 * shorter in all; 1 slowed to the sleeve's floor" ("": none). Python's `CatchUp.played_words`.
 */
export function catchUpWords(catchUp: CatchUp): string {
  const words: string[] = [];
  if (catchUp.compressed > 0)
    words.push(
      `${catchUp.compressed} faster to catch up, ${durationWords(catchUp.compressed_ms)} shorter in all`,
    );
  if (catchUp.slowed > 0) words.push(`${catchUp.slowed} slowed to the sleeve's floor`);
  return words.join("; ");
}

/** Whole ms below a second, else seconds to a tenth (events.ts `seconds`; Python `duration_words`). */
export function durationWords(ms: number): string {
  return ms >= 1000 ? `${(Math.round(ms / 100) / 10).toFixed(1)} s` : `${Math.round(ms)} ms`;
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
        : { rank: OWN, fate: "cancelled", reason: event.by === WEARER ? WEARER : null };
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
  /** The played event that gave a stroke its fate played, by seq (and of unnamed strokes). */
  readonly #played = new Map<number, PlayedEvent | AdjustedEvent>();
  readonly #playedUnnamed: (PlayedEvent | AdjustedEvent)[] = [];

  /** Takes `event` into account; the stroke's fate now (null: it says nothing of one). */
  add(event: SleeveEvent): Fate | null {
    const seq = "seq" in event ? event.seq : null;
    const known = seq === null ? undefined : this.#bySeq.get(seq);
    const said = verdict(event, known?.fate === "played");
    if (said === null) return known?.fate ?? null;
    const played = event.type === "played" || event.type === "adjusted" ? event : null;
    if (seq === null) {
      this.#unnamed.push(said);
      if (played !== null) this.#playedUnnamed.push(played);
      return said.fate;
    }
    if (known === undefined || said.rank > known.rank) {
      this.#bySeq.set(seq, said);
      if (played !== null) this.#played.set(seq, played);
      else this.#played.delete(seq);
      return said.fate;
    }
    return known.fate;
  }

  fate(seq: number): Fate | null {
    return this.#bySeq.get(seq)?.fate ?? null;
  }

  /** Why stroke `seq` was refused, or who or what cut it ("wearer", a safety reason); null: neither. */
  reason(seq: number): string | null {
    return this.#bySeq.get(seq)?.reason ?? null;
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

  /** Of the strokes cancelled before they played: those the wearer cancelled (their stop or block). */
  cancelledByWearer(): number {
    let count = 0;
    for (const { fate, reason } of [...this.#bySeq.values(), ...this.#unnamed]) {
      if (fate === "cancelled" && reason === WEARER) count++;
    }
    return count;
  }

  /**
   * Of the strokes played (by their own played event), those played faster to catch up and those
   * slowed; of the refused, those skipped as `late`.
   */
  catchUp(): CatchUp {
    const played = [...this.#played].filter(([seq]) => this.#bySeq.get(seq)?.fate === "played");
    return catchUpOf(
      [...played.map(([, event]) => event), ...this.#playedUnnamed],
      this.refusals().get(LATE) ?? 0,
    );
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
 * wearer (their pause or stop), or by a fault on the sleeve (a chip lost mid-stroke, the sleeve
 * stopped or its process ended mid-stroke: `safety` `chip_lost`, `stopped`, `crashed`).
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

/**
 * The words for `cancelled` strokes dropped before they played: by the sender's Stop, or by the
 * wearer (`byWearer`: their stop, or a block, on the wearer's page or button). `after`: what
 * follows each ("before they played"), or "".
 */
export function cancelledWords(cancelled: number, byWearer = 0, after = ""): string[] {
  const wearer = Math.min(cancelled, byWearer);
  const stop = cancelled - wearer;
  const tail = (n: number) => (after === "" ? "" : ` ${after.replace("{it}", n === 1 ? "it" : "they")}`);
  const words: string[] = [];
  if (stop > 0) words.push(`${stop} cancelled by Stop${tail(stop)}`);
  if (wearer > 0) words.push(`${wearer} cancelled by the wearer${tail(wearer)}`);
  return words;
}
