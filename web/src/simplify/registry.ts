/**
 * The simplifiers by name (the reference's `ALGORITHMS` in
 * `simplify/registry.py`), and a whole recording through one,
 * deterministically: every path fed to it (as animation frames or as every
 * sample, see `AlgorithmEntry.input`) and ended, in order. Parameters say which
 * simplifier they are for in their `algorithm` field.
 */
import { AngleSimplifier } from "./angle";
import { framesFromSamples } from "./frames";
import { DEFAULT_ANGLE_PARAMS, PARAM_SPECS, type AngleParams, type ParamSpec } from "./params";
import type { Sample, Segment } from "./segment";
import { WindowSimplifier } from "./window";
import { DEFAULT_WINDOW_PARAMS, WINDOW_PARAM_SPECS, type WindowParams } from "./window-params";

export type SimplifierParams = AngleParams | WindowParams;
export type Algorithm = SimplifierParams["algorithm"];

/** What every simplifier offers: frames or samples in, finished segments out. */
export interface Simplifier {
  readonly drawing: boolean;
  /** Where the stroke being drawn starts (canvas pixels); null between paths. */
  readonly lineStart: Sample | null;
  /** The strokes this input finished (often none: a shared empty array, not to be changed). */
  push(input: Sample): readonly Segment[];
  end(): Segment[];
}

/** What a simplifier is fed: animation frames (resampled at `fps`), or every pointer sample. */
export type InputKind = "frames" | "samples";

/** A simplifier by name: its parameter table, its defaults, how to make one. */
export interface AlgorithmEntry<P extends SimplifierParams> {
  readonly name: P["algorithm"];
  readonly summary: string;
  readonly specs: readonly ParamSpec<string>[];
  readonly defaults: P;
  readonly input: InputKind;
  make(params: P): Simplifier;
}

export const ALGORITHMS: {
  readonly angle: AlgorithmEntry<AngleParams>;
  readonly window: AlgorithmEntry<WindowParams>;
} = {
  angle: {
    name: "angle",
    summary: "the paper's turn-angle rule",
    specs: PARAM_SPECS,
    defaults: DEFAULT_ANGLE_PARAMS,
    input: "frames",
    make: (params) => new AngleSimplifier(params),
  },
  window: {
    name: "window",
    summary: "error-bounded, cut at features",
    specs: WINDOW_PARAM_SPECS,
    defaults: DEFAULT_WINDOW_PARAMS,
    input: "samples",
    make: (params) => new WindowSimplifier(params),
  },
};

/** Parameter name -> the one algorithm that has it (the others would ignore it). */
export const ONLY_FOR: Readonly<Partial<Record<string, Algorithm>>> = (() => {
  const owners = new Map<string, Algorithm[]>();
  for (const entry of Object.values(ALGORITHMS)) {
    for (const spec of entry.specs) owners.set(spec.name, [...(owners.get(spec.name) ?? []), entry.name]);
  }
  return Object.fromEntries(
    [...owners].filter(([, names]) => names.length === 1).map(([name, [owner]]) => [name, owner]),
  );
})();

/** A segment and the index of the path it came from. */
export interface PathSegment {
  readonly path: number;
  readonly segment: Segment;
}

/** The simplifier the parameters are for. */
export function makeSimplifier(params: SimplifierParams): Simplifier {
  switch (params.algorithm) {
    case "angle":
      return ALGORITHMS.angle.make(params);
    case "window":
      return ALGORITHMS.window.make(params);
  }
}

/** What the simplifier the parameters are for is fed for one path drawn as `samples`. */
export function inputsFor(params: SimplifierParams, samples: readonly Sample[]): Sample[] {
  return params.algorithm === "angle" ? framesFromSamples(samples, params.fps) : [...samples];
}

export function simplifyPaths(
  params: SimplifierParams,
  paths: readonly (readonly Sample[])[],
): PathSegment[] {
  const simplifier = makeSimplifier(params);
  const out: PathSegment[] = [];
  paths.forEach((samples, path) => {
    for (const input of inputsFor(params, samples)) {
      for (const segment of simplifier.push(input)) out.push({ path, segment });
    }
    for (const segment of simplifier.end()) out.push({ path, segment });
  });
  return out;
}
