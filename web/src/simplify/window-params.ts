/**
 * The window simplifier's parameters: its rows of the parameter table
 * (`params.generated.ts`, from the reference's declarations), its defaults and
 * its checks.
 */
import {
  checkParams,
  defaultsOf,
  specsOf,
  WINDOW_PARAM_NAMES,
  type ParamSpec,
  type WindowParams,
} from "./params";

export type { WindowParams } from "./params";

export type WindowParamName = Exclude<keyof WindowParams, "algorithm">;

/** Every parameter, in the reference's order. */
export const WINDOW_PARAM_SPECS: readonly ParamSpec<WindowParamName>[] = specsOf(WINDOW_PARAM_NAMES);

export function windowParamSpec(name: WindowParamName): ParamSpec<WindowParamName> {
  const spec = WINDOW_PARAM_SPECS.find((candidate) => candidate.name === name);
  if (spec === undefined) {
    throw new Error(`the window simplifier has no parameter '${name}'`);
  }
  return spec;
}

/** The reference's defaults. */
export const DEFAULT_WINDOW_PARAMS: WindowParams = defaultsOf<WindowParams>(WINDOW_PARAM_SPECS, "window");

/** Throws a RangeError naming the parameter, the value and the range, for the first bad one. */
export function checkWindowParams(params: WindowParams): void {
  checkParams(WINDOW_PARAM_SPECS, params);
}
