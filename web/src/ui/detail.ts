/**
 * One "detail" control for both simplifiers: five steps from few long strokes
 * (coarse) to many short ones that follow the hand closely (fine). Each step
 * sets the one parameter that decides it: the window simplifier's max error
 * (grid units: 1 = the actuator spacing) or the angle rule's max angle.
 */
import type { SimplifierParams } from "../simplify/registry";

export const DETAIL_LEVELS = 5;
/** Farthest a drawn point may lie from its stroke, grid units, per level (1 = coarse). */
const MAX_ERROR = [0.4, 0.25, 0.15, 0.1, 0.05] as const;
/** Turn that ends a stroke, degrees, per level. */
const MAX_ANGLE_DEG = [60, 45, 30, 20, 12] as const;

export function detailValues(level: number): { max_error: number; max_angle_deg: number } {
  const i = Math.min(Math.max(Math.round(level), 1), DETAIL_LEVELS) - 1;
  return { max_error: MAX_ERROR[i]!, max_angle_deg: MAX_ANGLE_DEG[i]! };
}

/** The level closest to these settings (for the algorithm in use). */
export function detailLevel(algorithm: string, values: { max_error: number; max_angle_deg: number }): number {
  const table: readonly number[] = algorithm === "window" ? MAX_ERROR : MAX_ANGLE_DEG;
  const value = algorithm === "window" ? values.max_error : values.max_angle_deg;
  let best = 0;
  for (let i = 1; i < table.length; i++) {
    if (Math.abs(Math.log(table[i]! / value)) < Math.abs(Math.log(table[best]! / value))) best = i;
  }
  return best + 1;
}

/** The same parameters at another detail level. */
export function detailParams(params: SimplifierParams, level: number): SimplifierParams {
  const values = detailValues(level);
  return params.algorithm === "window"
    ? { ...params, max_error: values.max_error }
    : { ...params, max_angle_deg: values.max_angle_deg };
}
