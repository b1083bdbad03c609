/**
 * The sleeve's queue, as the sleeve runs it (python feelmysign.sleeve.queue, pinned by
 * the vectors in testdata/queue): strokes play back to back in the order they arrive,
 * each starting when it arrives or when the stroke before it ends, whichever is later.
 * `queueStartMs` is the page's one copy of that rule and `QueueTail` the one copy of how
 * the tail moves. A stroke that arrives behind a stroke of its own drawing plays faster, by as
 * much as the sleeve is behind, down to the sleeve's floor and never slower than it came
 * (docs/protocol.md, "Playback"): `queueCatchUpMs` is the page's one copy of that rule.
 * `replayQueue` runs them over arrivals, copies and cancels as the sleeve does, so the vectors
 * check them, and the felt timeline (felt.ts, felt-placement.ts) places its strokes with the
 * same `QueueTail` and catch-up.
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
 * The paper sleeve's floor: the shortest stroke its ERM motors play without slowing it (two
 * end bursts of 20 ms in apparent motion, python `shortest_planned_ms`). Catching up stops here.
 */
export const SLEEVE_FLOOR_MS = 73.701;

/**
 * How long a stroke of `durationMs` plays when it arrives at `arrivalMs` behind strokes of its
 * drawing that end at `tailMs`: shorter by how far the sleeve is behind, down to `floorMs`,
 * never longer than it came.
 */
export function queueCatchUpMs(
  arrivalMs: number,
  tailMs: number,
  durationMs: number,
  floorMs: number,
): number {
  const behindMs = tailMs - arrivalMs;
  if (behindMs <= 0 || durationMs <= floorMs) return durationMs;
  return Math.max(floorMs, durationMs - behindMs);
}

/**
 * The tail of the queue, stroke by stroke, as the sleeve's `Queue.place` moves it: a stroke
 * starts by `queueStartMs` and holds the queue until it ends.
 */
export class QueueTail {
  /** When the last stroke queued ends: the earliest the next one can start. */
  tailMs: number;
  /** The drawing of the stroke that ends at the tail (none for a legacy stroke, or an empty queue). */
  tailDrawing: string | undefined;

  /** A queue ending at `tailMs` (by default empty: the next stroke starts when it arrives). */
  constructor(tailMs: number = EMPTY_TAIL_MS, tailDrawing?: string) {
    this.tailMs = tailMs;
    this.tailDrawing = tailDrawing;
  }

  /**
   * Queues a stroke of `drawing` that arrives at `arrivalMs` and holds the queue `heldMs` from its
   * start: when it starts. `startedMs`, when the sleeve said when it started, is taken over the rule.
   */
  place(
    arrivalMs: number,
    heldMs: number,
    startedMs: number = queueStartMs(arrivalMs, this.tailMs),
    drawing?: string,
  ): number {
    this.tailMs = startedMs + heldMs;
    this.tailDrawing = drawing;
    return startedMs;
  }

  /**
   * The duration to place a stroke of `drawing` with (`queueCatchUpMs`): shorter only when it
   * waits behind a stroke of the same drawing.
   */
  catchUpMs(arrivalMs: number, durationMs: number, floorMs: number, drawing: string | undefined): number {
    if (drawing === undefined || drawing !== this.tailDrawing) return durationMs;
    return queueCatchUpMs(arrivalMs, this.tailMs, durationMs, floorMs);
  }

  /** After a cancel: the tail is the end of the latest stroke still planned, each given as [end, drawing]. */
  replan(ends: Iterable<readonly [endMs: number, drawing: string | undefined]>): void {
    this.tailMs = EMPTY_TAIL_MS;
    this.tailDrawing = undefined;
    for (const [endMs, drawing] of ends) {
      // The first of equal ends wins, as the sleeve's max() keeps it.
      if (endMs > this.tailMs) {
        this.tailMs = endMs;
        this.tailDrawing = drawing;
      }
    }
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

/**
 * What becomes of each stroke of `steps` (in the order they reach the sleeve): one outcome per
 * stroke. Strokes behind their own drawing catch up down to `floorMs`.
 */
export function replayQueue(steps: readonly QueueStep[], floorMs: number): QueueOutcome[] {
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
      queue.replan([...planned.values()].map((p) => [p.end_ms, p.drawing] as const));
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
    // Only a stroke with drawing and seq is one of a drawing's (as the sleeve places it).
    const own = key !== null ? drawing : undefined;
    const duration_ms = queue.catchUpMs(step.arrival_ms, step.duration_ms, floorMs, own);
    const start_ms = queue.place(step.arrival_ms, duration_ms, undefined, own);
    planned.set(outcomes.length, {
      index: outcomes.length,
      start_ms,
      end_ms: queue.tailMs,
      duration_ms,
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
