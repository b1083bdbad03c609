/**
 * Each TypeScript simplifier against every vector of its testdata folder
 * (testdata/angle, testdata/window): frames per path and every segment (path,
 * start, end, times, dropped reason), within the file's own tolerance.
 */
import { describe, expect, it } from "vitest";
import type { AngleParams } from "../src/simplify/params";
import { inputsFor, simplifyPaths } from "../src/simplify/registry";
import type { Sample } from "../src/simplify/segment";
import { WindowSimplifier } from "../src/simplify/window";
import type { WindowParams } from "../src/simplify/window-params";
import { vectors } from "./testdata";

interface ExpectedSegment {
  path: number;
  start: [number, number];
  end: [number, number];
  start_ms: number;
  end_ms: number;
  emitted_at_ms: number;
  dropped: string | null;
  /** The window simplifier's: how many pieces too short to send were merged into it. */
  merged?: number;
  /** The window simplifier's: how long the sleeve is to play it (a stroke drawn briefer than the floor lasts the floor). */
  duration_ms?: number;
}

interface SimplifierVector<P> {
  description: string;
  tolerance: number;
  params: Omit<P, "algorithm">;
  paths: [number, number, number, number][][];
  /** merged_back (the window simplifier's): per path, the pieces merged at release into a stroke already sent. */
  expected: { inputs: number[]; segments: ExpectedSegment[]; merged_back?: number[] };
}

function casesOf<P>(folder: string): [string, SimplifierVector<P>][] {
  return vectors(folder).filter(([name]) => !name.endsWith("params.json")) as [string, SimplifierVector<P>][];
}

function close(actual: number, expected: number, tolerance: number, what: string): void {
  if (Math.abs(actual - expected) > tolerance) {
    throw new Error(`${what}: got ${actual}, expected ${expected} (tolerance ${tolerance})`);
  }
}

function checkVector(
  vector: SimplifierVector<AngleParams | WindowParams>,
  params: AngleParams | WindowParams,
): void {
  const paths: Sample[][] = vector.paths.map((path) =>
    path.map(([t_ms, x, y, pressure]) => ({ t_ms, x, y, pressure })),
  );
  expect(paths.map((path) => inputsFor(params, path).length)).toEqual(vector.expected.inputs);
  const actual = simplifyPaths(params, paths);
  expect(actual.length, "segment count").toBe(vector.expected.segments.length);
  const tol = vector.tolerance;
  vector.expected.segments.forEach((want, i) => {
    const got = actual[i]!;
    const where = `segment ${i}`;
    expect(got.path, `${where} path`).toBe(want.path);
    expect(got.segment.dropped, `${where} dropped`).toBe(want.dropped);
    expect(got.segment.merged ?? 0, `${where} merged`).toBe(want.merged ?? 0);
    close(got.segment.start[0], want.start[0], tol, `${where} start x`);
    close(got.segment.start[1], want.start[1], tol, `${where} start y`);
    close(got.segment.end[0], want.end[0], tol, `${where} end x`);
    close(got.segment.end[1], want.end[1], tol, `${where} end y`);
    close(got.segment.start_ms, want.start_ms, tol, `${where} start_ms`);
    close(got.segment.end_ms, want.end_ms, tol, `${where} end_ms`);
    close(got.segment.emitted_at_ms, want.emitted_at_ms, tol, `${where} emitted_at_ms`);
    close(
      got.segment.duration_ms,
      want.duration_ms ?? want.end_ms - want.start_ms,
      tol,
      `${where} duration_ms`,
    );
  });
  if (params.algorithm === "window") {
    // The pieces merged at release into the stroke before them, path by path (nothing was sent).
    const simplifier = new WindowSimplifier(params);
    const mergedBack = paths.map((path) => {
      const before = simplifier.mergedBack;
      for (const sample of path) simplifier.push(sample);
      simplifier.end();
      return simplifier.mergedBack - before;
    });
    expect(mergedBack, "merged back").toEqual(vector.expected.merged_back);
  }
}

describe.each(["angle", "window"] as const)("%s vectors", (algorithm) => {
  const cases = casesOf<AngleParams | WindowParams>(algorithm);

  it("finds the vectors", () => {
    expect(cases.length).toBeGreaterThanOrEqual(50);
  });

  it.each(cases)("%s", (_name, vector) => {
    checkVector(vector, { ...vector.params, algorithm } as AngleParams | WindowParams);
  });
});
