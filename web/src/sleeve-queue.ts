/**
 * The sleeve's queue, as the sleeve runs it (python feelmysign.sleeve.queue, pinned by
 * the vectors in testdata/queue): strokes play back to back in the order they arrive,
 * each starting when it arrives or when the stroke before it ends, whichever is later.
 * `queueStartMs` is the page's one copy of that rule and `QueueTail` the one copy of how
 * the tail moves; `replayQueue` runs them over arrivals, copies and cancels as the sleeve
 * does, so the vectors check them, and the felt timeline (felt.ts, felt-placement.ts)
 * places its strokes with the same `QueueTail`.
 *
 * Pure: no DOM, no clock.
 */

/** The tail of an empty queue: the next stroke starts when it arrives. */
export const EMPTY_TAIL_MS = Number.NEGATIVE_INFINITY;

/** When a stroke that arrives at `arrivalMs` starts behind a queue that ends at `tailMs`. */
export function queueStartMs(arrivalMs: number, tailMs: number): number {
  return Math.max(arrivalMs, tailMs);
}

/**
 * The tail of the queue, stroke by stroke, as the sleeve's `Queue.place` moves it: a stroke
 * starts by `queueStartMs` and holds the queue until it ends.
 */
export class QueueTail {
  /** When the last stroke queued ends: the earliest the next one can start. */
  tailMs: number;

  /** A queue ending at `tailMs` (by default empty: the next stroke starts when it arrives). */
  constructor(tailMs: number = EMPTY_TAIL_MS) {
    this.tailMs = tailMs;
  }

  /**
   * Queues a stroke that arrives at `arrivalMs` and holds the queue `heldMs` from its start: when it
   * starts. `startedMs`, when the sleeve said when it started, is taken over the rule.
   */
  place(arrivalMs: number, heldMs: number, startedMs: number = queueStartMs(arrivalMs, this.tailMs)): number {
    this.tailMs = startedMs + heldMs;
    return startedMs;
  }

  /** After a cancel: the tail is the end of the latest stroke still planned. */
  replan(endsMs: Iterable<number>): void {
    this.tailMs = EMPTY_TAIL_MS;
    for (const endMs of endsMs) this.tailMs = Math.max(this.tailMs, endMs);
  }
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
  readonly end_ms: number;
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
  const queue = new QueueTail();
  for (const step of steps) {
    if ("cancel" in step) {
      const now = step.at_ms;
      for (const [index, p] of planned) {
        if (p.end_ms <= now || (step.cancel !== "*" && p.drawing !== step.cancel)) continue;
        planned.delete(index);
        outcomes[index] =
          p.start_ms <= now
            ? { outcome: "cut", start_ms: p.start_ms, played_ms: now - p.start_ms }
            : { outcome: "cancelled" };
      }
      queue.replan([...planned.values()].map((p) => p.end_ms));
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
    const start_ms = queue.place(step.arrival_ms, step.duration_ms);
    planned.set(outcomes.length, {
      index: outcomes.length,
      start_ms,
      end_ms: queue.tailMs,
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
