/**
 * What simplifiers take (samples) and give (segments): the same shapes as the
 * Python reference (`feelmysign/simplify/segment.py`).
 *
 * Data shared across languages and files (recordings, vectors, the wire) keeps
 * its snake_case keys with units (`t_ms`, `start_ms`), so a value reads the
 * same in Python, TypeScript and JSON.
 */

/** A grid point: x = column index, y = row index (grid units). */
export type Point = readonly [x: number, y: number];

/** One pointer reading: canvas pixels (origin top-left, y down), ms, pressure 0..1. */
export interface Sample {
  readonly t_ms: number;
  readonly x: number;
  readonly y: number;
  readonly pressure: number;
}

/** The paper's NotEnoughDistanceException. */
export const NOT_ENOUGH_DISTANCE = "not_enough_distance";
/** The paper's NotEnoughDurationException. */
export const NOT_ENOUGH_DURATION = "not_enough_duration";

export type DropReason = typeof NOT_ENOUGH_DISTANCE | typeof NOT_ENOUGH_DURATION;

/**
 * A straight piece of a path in grid units, and when the simplifier let it go.
 * `dropped` is null for a stroke to send, else why it is too short or too brief
 * to feel. Sent and dropped segments of a path together join end to start.
 */
export interface Segment {
  readonly start: Point;
  readonly end: Point;
  readonly start_ms: number;
  readonly end_ms: number;
  /**
   * How long the sleeve is to play it: end_ms - start_ms (how long the piece took to draw), or,
   * for a stroke of the window simplifier drawn briefer than the sleeve's floor, the floor.
   */
  readonly duration_ms: number;
  readonly emitted_at_ms: number;
  readonly dropped: DropReason | null;
  /** How many pieces too short to send were merged into this one (the window simplifier's; absent: none). */
  readonly merged?: number;
}

/** The segment's length in grid units, computed as the reference does (not Math.hypot). */
export function segmentLength(segment: Segment): number {
  const dx = segment.end[0] - segment.start[0];
  const dy = segment.end[1] - segment.start[1];
  return Math.sqrt(dx * dx + dy * dy);
}

/** What decides whether a finished piece is sent: the shortest length and duration to feel. */
export interface DropLimits {
  readonly min_length: number;
  readonly min_duration_ms: number;
}

/**
 * A finished piece of a path: sent, or dropped as too short (first, as the
 * reference: a tap is "not enough distance") or too brief to feel.
 */
export function finishSegment(
  start: Point,
  end: Point,
  startMs: number,
  endMs: number,
  emittedAtMs: number,
  limits: DropLimits,
): Segment {
  // The reason first, so each piece is one object (what the app and the wire see is the same).
  const dx = end[0] - start[0];
  const dy = end[1] - start[1];
  const durationMs = endMs - startMs;
  let dropped: DropReason | null = null;
  if (Math.sqrt(dx * dx + dy * dy) < limits.min_length) dropped = NOT_ENOUGH_DISTANCE;
  else if (durationMs < limits.min_duration_ms) dropped = NOT_ENOUGH_DURATION;
  return {
    start,
    end,
    start_ms: startMs,
    end_ms: endMs,
    duration_ms: durationMs,
    emitted_at_ms: emittedAtMs,
    dropped,
  };
}
