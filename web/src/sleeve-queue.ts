/**
 * The sleeve's queue, as the sleeve runs it (python feelmysign.sleeve.queue, pinned by
 * the vectors in testdata/queue): strokes play back to back in the order they arrive,
 * each starting when it arrives or when the stroke before it ends, whichever is later.
 * `queueStartMs` is the page's one copy of that rule; `replayQueue` runs it over arrivals,
 * copies and cancels as the sleeve does, so the vectors check it.
 *
 * Pure: no DOM, no clock.
 */

/** The tail of an empty queue: the next stroke starts when it arrives. */
export const EMPTY_TAIL_MS = Number.NEGATIVE_INFINITY;

/** When a stroke that arrives at `arrivalMs` starts behind a queue that ends at `tailMs`. */
export function queueStartMs(arrivalMs: number, tailMs: number): number {
  return Math.max(arrivalMs, tailMs);
}

/** A stroke reaching the sleeve (drawing and seq absent in the legacy format). */
export interface QueueArrival {
  readonly arrival_ms: number;
  readonly duration_ms: number;
  readonly drawing?: string;
  readonly seq?: number;
}

/** A cancel of one drawing, or of every drawing ("*"). */
export interface QueueCancel {
  readonly cancel: string;
  readonly at_ms: number;
}

export type QueueStep = QueueArrival | QueueCancel;

export type QueueOutcome =
  | { readonly outcome: "played" | "cut"; readonly start_ms: number; readonly played_ms: number }
  | { readonly outcome: "cancelled" | "held" | "duplicate" };

interface Planned {
  readonly index: number;
  readonly start_ms: number;
  readonly duration_ms: number;
  readonly drawing: string | undefined;
  readonly seq: number | undefined;
}

/** What becomes of each stroke of `steps` (in the order they reach the sleeve): one outcome per stroke. */
export function replayQueue(steps: readonly QueueStep[]): QueueOutcome[] {
  const outcomes: (QueueOutcome | null)[] = [];
  const planned = new Map<number, Planned>();
  const seen = new Set<string>();
  const cancelled = new Set<string>();
  let tail = EMPTY_TAIL_MS;
  for (const step of steps) {
    if ("cancel" in step) {
      const now = step.at_ms;
      for (const [index, p] of planned) {
        if (p.start_ms + p.duration_ms <= now || (step.cancel !== "*" && p.drawing !== step.cancel)) continue;
        planned.delete(index);
        outcomes[index] =
          p.start_ms <= now
            ? { outcome: "cut", start_ms: p.start_ms, played_ms: now - p.start_ms }
            : { outcome: "cancelled" };
      }
      tail = EMPTY_TAIL_MS;
      for (const p of planned.values()) tail = Math.max(tail, p.start_ms + p.duration_ms);
      if (step.cancel !== "*") cancelled.add(step.cancel);
      continue;
    }
    const { drawing, seq } = step;
    if (drawing !== undefined && cancelled.has(drawing)) {
      outcomes.push({ outcome: "cancelled" });
      continue;
    }
    const key = drawing !== undefined && seq !== undefined ? JSON.stringify([drawing, seq]) : null;
    if (key !== null && seen.has(key)) {
      const waiting = [...planned.values()].some(
        (p) => p.drawing === drawing && p.seq === seq && p.start_ms > step.arrival_ms,
      );
      outcomes.push({ outcome: waiting ? "held" : "duplicate" });
      continue;
    }
    if (key !== null) seen.add(key);
    const start_ms = queueStartMs(step.arrival_ms, tail);
    tail = start_ms + step.duration_ms;
    planned.set(outcomes.length, {
      index: outcomes.length,
      start_ms,
      duration_ms: step.duration_ms,
      drawing,
      seq,
    });
    outcomes.push(null);
  }
  for (const p of planned.values()) {
    outcomes[p.index] = { outcome: "played", start_ms: p.start_ms, played_ms: p.duration_ms };
  }
  return outcomes.filter((o): o is QueueOutcome => o !== null);
}
