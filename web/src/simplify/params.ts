/**
 * Parameter tables of the simplifiers: defaults, allowed ranges, units, help,
 * and the angle simplifier's own (defaults from the paper, appendix B.1). The
 * tables are written here, not read from the `params.json` files in testdata/ (test data
 * stays out of the page), and a test holds them equal to those files, which the
 * Python reference writes: the browser validates with exactly its ranges.
 */
export type ParamType = "integer" | "number" | "boolean";

/** One row of a parameter table; `N` names the parameters of one simplifier. */
export interface ParamSpec<N extends string = AngleParamName> {
  readonly name: N;
  readonly type: ParamType;
  readonly default: number | boolean;
  readonly minimum: number | null;
  readonly maximum: number | null;
  readonly help: string;
}

/** The parameters of `AngleParams` in the reference, snake_case as in every file that holds them. */
export interface AngleParams {
  /** Which simplifier these parameters are for (see `registry.ts`). */
  readonly algorithm: "angle";
  readonly check_frames: number;
  readonly max_angle_deg: number;
  readonly frame_max: number;
  readonly fps: number;
  readonly recover: boolean;
  readonly clear_on_press: boolean;
  readonly min_duration_ms: number;
  readonly min_length: number;
  readonly rows: number;
  readonly columns: number;
  readonly canvas_width_px: number;
  readonly canvas_height_px: number;
  readonly stretch: boolean;
}

export type AngleParamName = Exclude<keyof AngleParams, "algorithm">;

/** The frame, drop and grid parameters every simplifier has, named as in every simplifier. */
export type FrameAndGridName =
  | "fps"
  | "clear_on_press"
  | "min_duration_ms"
  | "min_length"
  | "rows"
  | "columns"
  | "canvas_width_px"
  | "canvas_height_px"
  | "stretch";

export const FPS_SPEC: ParamSpec<FrameAndGridName> = {
  name: "fps",
  type: "number",
  default: 60,
  minimum: 1,
  maximum: 1000,
  help: "frames per second of the drawing loop",
};

export type DropAndGridName = Exclude<FrameAndGridName, "fps">;

/** The drop and grid settings every simplifier has, after its own (and `fps` for frames). */
export const DROP_AND_GRID_SPECS: readonly ParamSpec<DropAndGridName>[] = [
  {
    name: "clear_on_press",
    type: "boolean",
    default: true,
    minimum: null,
    maximum: null,
    help: "a new press clears the drawing",
  },
  {
    name: "min_duration_ms",
    type: "number",
    default: 6.1,
    minimum: 0,
    maximum: 10000,
    help: "shortest stroke to send, in ms",
  },
  {
    name: "min_length",
    type: "number",
    default: 0.1,
    minimum: 0,
    maximum: 100,
    help: "shortest stroke to send, in grid units",
  },
  { name: "rows", type: "integer", default: 3, minimum: 1, maximum: 64, help: "actuator rows of the sleeve" },
  {
    name: "columns",
    type: "integer",
    default: 4,
    minimum: 1,
    maximum: 64,
    help: "actuator columns of the sleeve",
  },
  {
    name: "canvas_width_px",
    type: "number",
    default: 1920,
    minimum: 1,
    maximum: 100000,
    help: "drawing area width in pixels",
  },
  {
    name: "canvas_height_px",
    type: "number",
    default: 1080,
    minimum: 1,
    maximum: 100000,
    help: "drawing area height in pixels",
  },
  {
    name: "stretch",
    type: "boolean",
    default: false,
    minimum: null,
    maximum: null,
    help: "stretch the canvas onto the grid (the paper's)",
  },
];

/** The defaults of a table, as a parameter object. */
export function defaultsOf<P>(specs: readonly ParamSpec<string>[], algorithm: string): P {
  return Object.freeze({
    algorithm,
    ...Object.fromEntries(specs.map((spec) => [spec.name, spec.default])),
  }) as unknown as P;
}

/** Every parameter, in the reference's order. */
export const PARAM_SPECS: readonly ParamSpec[] = [
  {
    name: "check_frames",
    type: "integer",
    default: 5,
    minimum: 2,
    maximum: 600,
    help: "frames between two checks (the paper's checkFrame)",
  },
  {
    name: "max_angle_deg",
    type: "number",
    default: 20,
    minimum: 1,
    maximum: 179,
    help: "largest turn, in degrees, that continues a line",
  },
  {
    name: "frame_max",
    type: "integer",
    default: 0,
    minimum: 0,
    maximum: 36000,
    help: "longest line in frames; 0 = no limit",
  },
  FPS_SPEC,
  {
    name: "recover",
    type: "boolean",
    default: true,
    minimum: null,
    maximum: null,
    help: "start a new line at the last check (no gaps)",
  },
  ...DROP_AND_GRID_SPECS,
];

const SPECS_BY_NAME = new Map(PARAM_SPECS.map((spec) => [spec.name, spec]));

export function paramSpec(name: AngleParamName): ParamSpec {
  const spec = SPECS_BY_NAME.get(name);
  if (spec === undefined) {
    throw new Error(`the angle simplifier has no parameter '${name}'`);
  }
  return spec;
}

/** The paper's defaults, as the reference writes them. */
export const DEFAULT_ANGLE_PARAMS: AngleParams = defaultsOf<AngleParams>(PARAM_SPECS, "angle");

/** "[2, 600]"-style text, or "from 2 to 600" for sentences. */
export function rangeText(spec: ParamSpec<string>): string {
  const low = spec.minimum === null ? "unbounded" : String(spec.minimum);
  const high = spec.maximum === null ? "unbounded" : String(spec.maximum);
  return `from ${low} to ${high}`;
}

/**
 * Why `value` is not allowed for `spec` (a sentence naming the allowed range),
 * or null when it is. The same checks, in the same order, as `ParamSpec.check`.
 */
export function paramProblem(spec: ParamSpec<string>, value: unknown): string | null {
  if (spec.type === "boolean") {
    return typeof value === "boolean" ? null : "must be on or off";
  }
  if (typeof value !== "number" || Number.isNaN(value)) {
    return `must be a number ${rangeText(spec)}`;
  }
  if (spec.type === "integer" && !Number.isInteger(value) && Number.isFinite(value)) {
    return `must be a whole number ${rangeText(spec)}`;
  }
  const lowOk = spec.minimum === null || value >= spec.minimum;
  const highOk = spec.maximum === null || value <= spec.maximum;
  if (!Number.isFinite(value) || !lowOk || !highOk) {
    const kind = spec.type === "integer" ? "a whole number" : "a number";
    return `must be ${kind} ${rangeText(spec)}`;
  }
  return null;
}

/** Throws a RangeError naming the parameter, the value and the range, for the first bad one. */
export function checkAngleParams(params: AngleParams): void {
  checkParams(PARAM_SPECS, params);
}

/** `checkAngleParams` for any simplifier's table. */
export function checkParams<N extends string>(specs: readonly ParamSpec<N>[], params: object): void {
  for (const spec of specs) {
    const value = (params as Record<string, unknown>)[spec.name];
    const problem = paramProblem(spec, value);
    if (problem !== null) {
      throw new RangeError(`${spec.name} = ${String(value)} is not allowed; it ${problem}`);
    }
  }
}
