/**
 * The window simplifier's parameters: defaults and allowed ranges, read at
 * build time from `testdata/window/params.json`, the table the Python
 * reference writes, so the browser validates with exactly its ranges.
 */
import table from "../../../testdata/window/params.json";
import { checkParams, readSpecs, type ParamSpec } from "./params";

/** The parameters of `WindowParams` in the reference, snake_case as in every file that holds them. */
export interface WindowParams {
  readonly max_error: number;
  readonly max_window: number;
  readonly fps: number;
  readonly clear_on_press: boolean;
  readonly min_duration_ms: number;
  readonly min_length: number;
  readonly rows: number;
  readonly columns: number;
  readonly canvas_width_px: number;
  readonly canvas_height_px: number;
  readonly stretch: boolean;
}

export type WindowParamName = keyof WindowParams;

/** Every parameter, in the reference's order. */
export const WINDOW_PARAM_SPECS: readonly ParamSpec<WindowParamName>[] = readSpecs<WindowParamName>(
  table,
  "testdata/window/params.json",
);

const SPECS_BY_NAME = new Map(WINDOW_PARAM_SPECS.map((spec) => [spec.name, spec]));

export function windowParamSpec(name: WindowParamName): ParamSpec<WindowParamName> {
  const spec = SPECS_BY_NAME.get(name);
  if (spec === undefined) {
    throw new Error(`testdata/window/params.json has no parameter '${name}'; regenerate it`);
  }
  return spec;
}

/** The reference's defaults. */
export const DEFAULT_WINDOW_PARAMS: WindowParams = Object.freeze(
  Object.fromEntries(WINDOW_PARAM_SPECS.map((spec) => [spec.name, spec.default])),
) as unknown as WindowParams;

/** Throws a RangeError naming the parameter, the value and the range, for the first bad one. */
export function checkWindowParams(params: WindowParams): void {
  checkParams(WINDOW_PARAM_SPECS, params);
}

/** Whether `params` are the window simplifier's (the angle simplifier has no `max_error`). */
export function isWindowParams(params: object): params is WindowParams {
  return "max_error" in params;
}
