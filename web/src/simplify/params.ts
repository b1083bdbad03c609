/**
 * The simplifiers' parameters: their table, and the checks on it. The table
 * (names, types, defaults, ranges, units, labels, help) is generated from the
 * Python reference's declarations into `params.generated.ts`; the page reads it
 * from there, not from testdata/ (test data stays out of the page), and a test
 * holds it equal to `testdata/params/params.json`, so the browser accepts
 * exactly the reference's values.
 */
import {
  ANGLE_PARAM_NAMES,
  PARAMETERS,
  type AngleParams,
  type PanelParams,
  type WindowParams,
} from "./params.generated";

export { ANGLE_PARAM_NAMES, PARAMETERS, WINDOW_PARAM_NAMES } from "./params.generated";
export type { AngleParams, PanelParams, SharedParams, WindowParams } from "./params.generated";

export type ParamType = "integer" | "number" | "boolean";
/** Where the settings panel shows a parameter; null: the page sets it (the drawing area's size). */
export type PanelSection = "drawing" | "simplifier" | "sleeve";

export type AngleParamName = Exclude<keyof AngleParams, "algorithm">;
/** Every parameter's name, of every simplifier. */
export type ParamName = AngleParamName | Exclude<keyof WindowParams, "algorithm">;
/** The parameters a person sets in the settings panel. */
export type PanelParamName = keyof PanelParams;

/** One row of the parameter table; `N` narrows its name. */
export interface ParamSpec<N extends string = ParamName> {
  readonly name: N;
  /** The simplifiers that have it. */
  readonly algorithms: readonly ("angle" | "window")[];
  /** Its name in the paper's appendix B.1, where it has one. */
  readonly paper: string | null;
  readonly type: ParamType;
  readonly default: number | boolean;
  readonly minimum: number | null;
  readonly maximum: number | null;
  readonly unit: string | null;
  readonly label: string;
  readonly help: string;
  readonly panel: PanelSection | null;
  /** The values of the detail control, coarse to fine, for the parameter it sets. */
  readonly detail_levels: readonly number[] | null;
  /** Its name in plot legends. */
  readonly short: string | null;
  /**
   * Read only while the boolean parameter `name` has `value` (the one core of its simplifier that
   * reads it; the other ignores it), or null: always read.
   */
  readonly only_when: ParamCondition | null;
}

/** A boolean parameter's value under which another parameter is read. */
export interface ParamCondition {
  readonly name: ParamName;
  readonly value: boolean;
}

const SPECS_BY_NAME = new Map<string, ParamSpec>(PARAMETERS.map((spec) => [spec.name, spec]));

/** The rows of these parameters, in this order. */
export function specsOf<N extends ParamName>(names: readonly N[]): readonly ParamSpec<N>[] {
  return names.map((name) => SPECS_BY_NAME.get(name) as ParamSpec<N>);
}

/** The angle simplifier's parameters, in the reference's order. */
export const PARAM_SPECS: readonly ParamSpec<AngleParamName>[] = specsOf(ANGLE_PARAM_NAMES);

export function paramSpec(name: AngleParamName): ParamSpec<AngleParamName> {
  const spec = PARAM_SPECS.find((candidate) => candidate.name === name);
  if (spec === undefined) {
    throw new Error(`the angle simplifier has no parameter '${name}'`);
  }
  return spec;
}

/** The defaults of a table, as a parameter object. */
export function defaultsOf<P>(specs: readonly ParamSpec<string>[], algorithm: string): P {
  return Object.freeze({
    algorithm,
    ...Object.fromEntries(specs.map((spec) => [spec.name, spec.default])),
  }) as unknown as P;
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
