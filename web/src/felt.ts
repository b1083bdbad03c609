/**
 * What the wearer feels over time, for the page's timeline: each stroke placed
 * at the time the sleeve plays it, and the brush along it rendered on the
 * actuators around it by funneling (Israr & Poupyrev 2011, the energy model:
 * a virtual point between actuators is felt when their energies, intensity
 * squared, add up to its own, split by proximity). This is the page's view
 * of the Tactile Brush, not the sleeve's exact plan (which times its bursts
 * by the apparent-motion model): it shows where and when the touch is.
 *
 * Times: where the sleeve told when it played a stroke, that time; otherwise
 * the sleeve's own rule (docs/protocol.md, "Playback"; `QueueTail` in
 * sleeve-queue.ts, pinned by testdata/queue): a stroke starts when it arrives,
 * or when the one before it ends if that is later, and one that waits plays
 * faster to catch up, down to the sleeve's floor (`queueCatchUpMs`): the strokes
 * placed here are one drawing's.
 */
import type { Point } from "./simplify/segment";
import { queueCatchUpMs, QueueTail, SLEEVE_FLOOR_MS } from "./sleeve-queue";

export interface FeltStroke {
  readonly seq: number;
  readonly start: Point;
  readonly end: Point;
  readonly duration_ms: number;
  readonly intensity: number;
  /** When it reaches the sleeve, ms on the timeline's clock. */
  readonly arrives_ms: number;
}

/** `duration_ms` of a placed stroke is how long the sleeve plays it: shorter when it caught up. */
export interface PlacedStroke extends FeltStroke {
  /** When it plays, ms on the timeline's clock. */
  readonly start_ms: number;
  /** True when the sleeve reported it; false for the page's own estimate. */
  readonly reported: boolean;
  /** Cut short (or dropped) by a cancel: it ends at `start_ms + played_ms`. */
  readonly played_ms: number;
  /**
   * Kept from playing by the sleeve's duty-cycle cap when its turn came: nothing felt
   * (`played_ms` 0), and its turn passes in silence (the sleeve does not move the strokes after it).
   */
  readonly capped: boolean;
}

export interface Grid {
  readonly rows: number;
  readonly columns: number;
}

/** One actuator's share of a touch: its row, column and intensity 0..1. */
export interface Drive {
  readonly row: number;
  readonly column: number;
  readonly intensity: number;
}

/**
 * Places strokes in time: a reported start wins; otherwise arrival, or the end
 * of the stroke before, whichever is later. A stroke arriving before the one
 * before it ends plays faster, down to `floorMs` (the sleeve's catch-up rule).
 * `reported` maps seq -> start (ms); `cut` maps seq -> ms after its start when
 * a cancel stopped it; `capped` holds the seqs the duty-cycle cap kept from playing.
 * A stroke the sleeve refused on arrival never entered its queue: leave it out of `strokes`.
 */
export function placeStrokes(
  strokes: readonly FeltStroke[],
  reported: ReadonlyMap<number, number> = new Map(),
  cut: ReadonlyMap<number, number> = new Map(),
  capped: ReadonlySet<number> = new Set(),
  floorMs: number = SLEEVE_FLOOR_MS,
): PlacedStroke[] {
  const placed: PlacedStroke[] = [];
  const queue = new QueueTail();
  for (const stroke of [...strokes].sort((a, b) => a.seq - b.seq)) {
    const known = reported.get(stroke.seq);
    const played = caughtUp(stroke, queue.tailMs, floorMs);
    const turn = turnOf(played, cut, capped);
    const start_ms = queue.place(stroke.arrives_ms, turn.held_ms, known);
    placed.push({ ...played, start_ms, reported: known !== undefined, ...turn.felt });
  }
  return placed;
}

/**
 * The stroke as the sleeve plays it behind a queue ending at `tailMs`: faster when it waits, down to
 * `floorMs` (`queueCatchUpMs`). The strokes placed here are one drawing's, so every stroke that waits
 * is behind its own drawing and catches up.
 */
export function caughtUp(stroke: FeltStroke, tailMs: number, floorMs: number): FeltStroke {
  const duration_ms = queueCatchUpMs(stroke.arrives_ms, tailMs, stroke.duration_ms, floorMs);
  return duration_ms === stroke.duration_ms ? stroke : { ...stroke, duration_ms };
}

/**
 * What a stroke's turn is: how long it holds the sleeve's queue (whole, or until a cancel cut it;
 * `cut`: seq -> ms into it), and what of it is felt (nothing, when the duty-cycle cap kept it from
 * playing: `capped`).
 */
export function turnOf(
  stroke: FeltStroke,
  cut: ReadonlyMap<number, number>,
  capped: ReadonlySet<number>,
): { held_ms: number; felt: { played_ms: number; capped: boolean } } {
  const held_ms = Math.min(stroke.duration_ms, Math.max(0, cut.get(stroke.seq) ?? stroke.duration_ms));
  const isCapped = capped.has(stroke.seq);
  return { held_ms, felt: { played_ms: isCapped ? 0 : held_ms, capped: isCapped } };
}

/** When the touch of a placed stroke ends. */
export function feltEndMs(stroke: PlacedStroke): number {
  return stroke.start_ms + stroke.played_ms;
}

/** Where the brush is `t_ms` into the stroke (clamped to its ends). */
export function brushAt(stroke: FeltStroke, t_ms: number): Point {
  const k = stroke.duration_ms > 0 ? Math.min(Math.max(t_ms / stroke.duration_ms, 0), 1) : 1;
  return [
    stroke.start[0] + (stroke.end[0] - stroke.start[0]) * k,
    stroke.start[1] + (stroke.end[1] - stroke.start[1]) * k,
  ];
}

/** A share of the energy this small or smaller drives no actuator (so a point on one is that one alone). */
export const NEGLIGIBLE_WEIGHT = 1e-9;

/**
 * The actuators that render a point at `intensity`: the (up to) four around it,
 * each with energy in proportion to its closeness along each axis (bilinear), so
 * the energies add up to intensity squared and a point on an actuator is that one alone.
 */
export function funnel(point: Point, intensity: number, grid: Grid): Drive[] {
  const x = Math.min(Math.max(point[0], 0), grid.columns - 1);
  const y = Math.min(Math.max(point[1], 0), grid.rows - 1);
  const c0 = Math.floor(x);
  const r0 = Math.floor(y);
  const fx = x - c0;
  const fy = y - r0;
  const drives: Drive[] = [];
  const add = (row: number, column: number, weight: number) => {
    if (weight > NEGLIGIBLE_WEIGHT && row < grid.rows && column < grid.columns) {
      drives.push({ row, column, intensity: intensity * Math.sqrt(weight) });
    }
  };
  add(r0, c0, (1 - fx) * (1 - fy));
  add(r0, c0 + 1, fx * (1 - fy));
  add(r0 + 1, c0, (1 - fx) * fy);
  add(r0 + 1, c0 + 1, fx * fy);
  return drives;
}

/** The stroke playing at `t_ms` and how far into it, or null between strokes. */
export function playingAt(
  placed: readonly PlacedStroke[],
  t_ms: number,
): { stroke: PlacedStroke; into_ms: number } | null {
  for (const stroke of placed) {
    const into_ms = t_ms - stroke.start_ms;
    if (into_ms >= 0 && into_ms <= stroke.played_ms) return { stroke, into_ms };
  }
  return null;
}

/** When the last stroke ends (0 for none). */
export function totalMs(placed: readonly PlacedStroke[]): number {
  return placed.reduce((end, stroke) => Math.max(end, feltEndMs(stroke)), 0);
}
