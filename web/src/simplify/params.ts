/**
 * The angle simplifier's parameters: defaults (the paper's, appendix B.1) and
 * allowed ranges, read at build time from `testdata/angle/params.json`, the
 * table the Python reference writes. The browser therefore validates with
 * exactly the Python ranges and can never drift from them.
 */
import table from "../../../testdata/angle/params.json";

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

export type AngleParamName = keyof AngleParams;

const PARAM_TYPES: readonly string[] = ["integer", "number", "boolean"];

/** A simplifier's parameter table (`source` names its file, for the errors). */
export function readSpecs<N extends string>(raw: unknown, source: string): ParamSpec<N>[] {
  // Checked once at load: a reshaped params.json should fail loudly, not validate wrongly.
  const parameters = (raw as { parameters?: unknown }).parameters;
  if (!Array.isArray(parameters)) {
    throw new Error(`${source} has no 'parameters' list; regenerate it`);
  }
  return parameters.map((entry: Record<string, unknown>, index) => {
    const { name, type, minimum, maximum, help } = entry;
    const value = entry["default"];
    const bound = (b: unknown) => b === null || typeof b === "number";
    if (
      typeof name !== "string" ||
      typeof type !== "string" ||
      !PARAM_TYPES.includes(type) ||
      !(typeof value === "number" || typeof value === "boolean") ||
      !bound(minimum) ||
      !bound(maximum) ||
      typeof help !== "string"
    ) {
      throw new Error(`${source}: parameters[${index}] is malformed`);
    }
    return {
      name: name as N,
      type: type as ParamType,
      default: value,
      minimum: minimum as number | null,
      maximum: maximum as number | null,
      help,
    };
  });
}

/** Every parameter, in the reference's order. */
export const PARAM_SPECS: readonly ParamSpec[] = readSpecs<AngleParamName>(
  table,
  "testdata/angle/params.json",
);

const SPECS_BY_NAME = new Map(PARAM_SPECS.map((spec) => [spec.name, spec]));

export function paramSpec(name: AngleParamName): ParamSpec {
  const spec = SPECS_BY_NAME.get(name);
  if (spec === undefined) {
    throw new Error(`testdata/angle/params.json has no parameter '${name}'; regenerate it`);
  }
  return spec;
}

/** The paper's defaults, as the reference writes them. */
export const DEFAULT_ANGLE_PARAMS: AngleParams = Object.freeze(
  Object.fromEntries(PARAM_SPECS.map((spec) => [spec.name, spec.default])),
) as unknown as AngleParams;

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
export function checkParams<N extends string>(
  specs: readonly ParamSpec<N>[],
  params: Readonly<Record<N, number | boolean>>,
): void {
  for (const spec of specs) {
    const value = params[spec.name];
    const problem = paramProblem(spec, value);
    if (problem !== null) {
      throw new RangeError(`${spec.name} = ${String(value)} is not allowed; it ${problem}`);
    }
  }
}
