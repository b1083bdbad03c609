/**
 * The sleeve's floor (its retained status, `floor`) applied to the simplifier: its minimums are
 * raised to at least what the sleeve advertises (the shortest stroke it plays without slowing it,
 * and its wearer's measured limits), never lowered below the user's own setting. The mirror of
 * Python `wearer.respect_floor`.
 */
import type { SleeveFloor } from "./events";

export interface Minimums {
  readonly min_duration_ms: number;
  readonly min_length: number;
}

/**
 * `settings` with its minimums raised to `floor` (the same object when nothing changes). The window
 * simplifier's also take the sleeve's floor as the shortest stroke to merge up to (`floor_ms`), and
 * with a wearer's limits never go below them (`strict_minimums`), as Python's replay does.
 */
export function withFloor<T extends Minimums>(settings: T, floor: SleeveFloor | null | undefined): T {
  if (floor == null) return settings;
  let out = settings;
  if ("floor_ms" in settings && "strict_minimums" in settings) {
    // The window simplifier merges a piece briefer than the floor into its neighbour, without
    // dropping anything, so the motors' floor alone is kept to as well.
    const strict = Boolean(floor.wearer);
    if (settings.floor_ms !== floor.min_duration_ms || settings.strict_minimums !== strict) {
      out = { ...out, floor_ms: floor.min_duration_ms, strict_minimums: strict };
    }
  }
  // Only a wearer's measured limits raise the minimums (as Python's respect_floor): the motors'
  // floor alone would make a simplifier drop brief strokes, which costs more of the shape than
  // the sleeve's slowing them and catching up afterwards.
  if (!floor.wearer) return out;
  const minDurationMs = Math.max(settings.min_duration_ms, floor.min_duration_ms);
  const minLength = Math.max(settings.min_length, floor.min_length);
  if (minDurationMs === settings.min_duration_ms && minLength === settings.min_length) return out;
  return { ...out, min_duration_ms: minDurationMs, min_length: minLength };
}

/** One sentence for the settings panel: what the floor makes the simplifier use; null without one. */
export function floorNote(settings: Minimums, floor: SleeveFloor | null | undefined): string | null {
  if (floor == null) return null;
  if (!floor.wearer) {
    return `The sleeve plays strokes briefer than ${round(floor.min_duration_ms)} ms slowed to that, and catches up after them; a wearer file (feelmysign sleeve --wearer) sets limits the page keeps to.`;
  }
  const whose = floor.wearer
    ? `the sleeve's floor with wearer ${floor.wearer}'s limits`
    : "the sleeve's floor";
  const raised = [
    ...(floor.min_duration_ms > settings.min_duration_ms ? ["min duration"] : []),
    ...(floor.min_length > settings.min_length ? ["min length"] : []),
  ];
  const effect = raised.length > 0 ? `${raised.join(" and ")} raised to it` : "your settings are above it";
  return `At least ${round(floor.min_duration_ms)} ms and ${round(floor.min_length)} grid units per stroke: ${whose}; ${effect}.`;
}

function round(value: number): string {
  return String(Math.round(value * 100) / 100);
}
