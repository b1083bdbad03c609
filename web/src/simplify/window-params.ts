/**
 * The window simplifier's parameters: defaults and allowed ranges, the same
 * table as the Python reference's (a test holds it equal to
 * `testdata/window/params.json`, which the reference writes).
 */
import { checkParams, defaultsOf, DROP_AND_GRID_SPECS, type ParamSpec } from "./params";

/** The parameters of `WindowParams` in the reference, snake_case as in every file that holds them. */
export interface WindowParams {
  /** Which simplifier these parameters are for (see `registry.ts`). */
  readonly algorithm: "window";
  readonly max_error: number;
  readonly max_window: number;
  readonly max_stroke_ms: number;
  readonly clear_on_press: boolean;
  readonly min_duration_ms: number;
  readonly min_length: number;
  readonly rows: number;
  readonly columns: number;
  readonly canvas_width_px: number;
  readonly canvas_height_px: number;
  readonly stretch: boolean;
}

export type WindowParamName = Exclude<keyof WindowParams, "algorithm">;

/** Every parameter, in the reference's order. */
export const WINDOW_PARAM_SPECS: readonly ParamSpec<WindowParamName>[] = [
  {
    name: "max_error",
    type: "number",
    default: 0.25,
    minimum: 0.001,
    maximum: 100,
    help: "farthest a drawn point may lie from its stroke, in grid units",
  },
  {
    name: "max_window",
    type: "integer",
    default: 256,
    minimum: 1,
    maximum: 10000,
    help: "longest stroke in samples after its start (bounds the work per sample)",
  },
  {
    name: "max_stroke_ms",
    type: "number",
    default: 300,
    minimum: 0,
    maximum: 60000,
    help: "longest stroke in ms of drawing, so a long line is felt before it ends; 0 = no limit",
  },
  ...DROP_AND_GRID_SPECS,
];

const SPECS_BY_NAME = new Map(WINDOW_PARAM_SPECS.map((spec) => [spec.name, spec]));

export function windowParamSpec(name: WindowParamName): ParamSpec<WindowParamName> {
  const spec = SPECS_BY_NAME.get(name);
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
