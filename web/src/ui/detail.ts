/**
 * One "detail" control for both simplifiers: five steps from few long strokes
 * (coarse) to many short ones that follow the hand closely (fine). Each step
 * sets the one parameter of each simplifier that decides it, the one whose
 * table row lists its detail levels (the window simplifier's max error, in grid
 * units: 1 = the actuator spacing; the angle rule's max angle).
 */
import { PARAMETERS, type ParamName, type ParamSpec } from "../simplify/params";
import type { Algorithm, SimplifierParams } from "../simplify/registry";

export const DETAIL_LEVELS = 5;

/** The parameters the control sets, with their values per level (1 = coarse). */
export const DETAIL_SPECS = PARAMETERS.filter(
  (spec): spec is ParamSpec & { detail_levels: readonly number[] } => spec.detail_levels !== null,
);

function detailSpec(algorithm: string): ParamSpec & { detail_levels: readonly number[] } {
  const spec = DETAIL_SPECS.find((candidate) => candidate.algorithms.includes(algorithm as Algorithm));
  if (spec === undefined) throw new Error(`the ${algorithm} simplifier has no detail parameter`);
  return spec;
}

function index(level: number): number {
  return Math.min(Math.max(Math.round(level), 1), DETAIL_LEVELS) - 1;
}

/** The value of every detail parameter at this level, by name. */
export function detailValues(level: number): Partial<Record<ParamName, number>> {
  return Object.fromEntries(DETAIL_SPECS.map((spec) => [spec.name, spec.detail_levels[index(level)]!]));
}

/** The level closest to these settings (for the algorithm in use). */
export function detailLevel(algorithm: string, values: Partial<Record<ParamName, number | boolean>>): number {
  const spec = detailSpec(algorithm);
  const table = spec.detail_levels;
  const value = values[spec.name] as number;
  let best = 0;
  for (let i = 1; i < table.length; i++) {
    if (Math.abs(Math.log(table[i]! / value)) < Math.abs(Math.log(table[best]! / value))) best = i;
  }
  return best + 1;
}

/** The same parameters at another detail level. */
export function detailParams(params: SimplifierParams, level: number): SimplifierParams {
  const spec = detailSpec(params.algorithm);
  return { ...params, [spec.name]: spec.detail_levels[index(level)]! };
}
