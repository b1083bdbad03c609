/**
 * The sleeve's queue, as the sleeve runs it (python feelmysign.sleeve.queue, pinned by
 * the vectors in testdata/queue): strokes play back to back in the order they arrive,
 * each starting when it arrives or when the stroke before it ends, whichever is later.
 * `queueStartMs` is the page's one copy of that rule. A stroke that arrives behind a stroke of
 * its own drawing plays faster, by as much as the sleeve is behind, down to the sleeve's floor
 * and never slower than it came (docs/protocol.md, "Playback"): `queueCatchUpMs` is the
 * page's one copy of that rule. `replayQueue` runs both over arrivals, copies and cancels as
 * the sleeve does, so the vectors check them.
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

/**
 * What becomes of each stroke of `steps` (in the order they reach the sleeve): one outcome per
 * stroke. Strokes behind their own drawing catch up down to `floorMs`.
 */
export function replayQueue(steps: readonly QueueStep[], floorMs: number): QueueOutcome[] {
  const outcomes: (QueueOutcome | null)[] = [];
  const planned = new Map<number, Planned>();
  const seen = new Set<string>();
  const cancelled = new Set<string>();
  let tail = EMPTY_TAIL_MS;
  // The drawing of the stroke ending at the tail (only a stroke with drawing and seq has one).
  let tailDrawing: string | undefined = undefined;
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
      tailDrawing = undefined;
      for (const p of planned.values()) {
        if (p.start_ms + p.duration_ms > tail) {
          tail = p.start_ms + p.duration_ms;
          tailDrawing = p.drawing;
        }
      }
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
    const behindOwn = key !== null && drawing === tailDrawing;
    const duration_ms = behindOwn
      ? queueCatchUpMs(step.arrival_ms, tail, step.duration_ms, floorMs)
      : step.duration_ms;
    const start_ms = queueStartMs(step.arrival_ms, tail);
    tail = start_ms + duration_ms;
    tailDrawing = key !== null ? drawing : undefined;
    planned.set(outcomes.length, {
      index: outcomes.length,
      start_ms,
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
