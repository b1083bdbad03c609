/**
 * The window simplifier, whose window and merger share one store of the drawn samples, gives the
 * same strokes to the last bit as the window first written (`window-reference.ts`) with the merger
 * first written (`merger-reference.ts`, its own copy of every sample) fed every sample as taken,
 * on random drawings (`window-drawings.ts`), and merges as many pieces back at release.
 */
import fc from "fast-check";
import { describe, expect, it } from "vitest";
import type { Sample, Segment } from "../src/simplify/segment";
import { takenSamples, WindowSimplifier } from "../src/simplify/window";
import type { WindowParams } from "../src/simplify/window-params";
import { ReferenceMerger } from "./merger-reference";
import { bits, drawingArb, pathsOf } from "./window-drawings";
import { ReferenceWindowSimplifier } from "./window-reference";

/** Thousands of drawings: generous, for a loaded machine (the work is bounded, not timed). */
const PROPERTY_TIMEOUT_MS = 240_000;

/** The window simplifier as first composed: every sample to the merger, then the pieces. */
class ReferenceMergedSimplifier {
  readonly #core: ReferenceWindowSimplifier;
  readonly #merger: ReferenceMerger;

  constructor(params: WindowParams) {
    this.#core = new ReferenceWindowSimplifier(params);
    this.#merger = new ReferenceMerger(
      params.max_error,
      params.min_length,
      params.min_duration_ms,
      params.floor_ms,
      params.strict_minimums,
    );
  }

  get mergedBack(): number {
    return this.#merger.mergedBack;
  }

  get lineStart(): Sample | null {
    return this.#core.lineStart;
  }

  push(sample: Sample): Segment[] {
    const pieces = this.#core.push(sample);
    const { t_ms, point } = this.#core.taken;
    this.#merger.sample(t_ms, point[0], point[1]);
    const out: Segment[] = [];
    for (const piece of pieces) this.#merger.take(piece, t_ms, out);
    if (this.#core.rested) this.#merger.rest(t_ms, out);
    return out;
  }

  end(): Segment[] {
    const nowMs = this.#core.taken.t_ms;
    const out: Segment[] = [];
    for (const piece of this.#core.end()) this.#merger.take(piece, nowMs, out);
    this.#merger.end(nowMs, out);
    return out;
  }
}

/** `bits`, and how many pieces each segment merged. */
function merged(segments: readonly Segment[]): (string | number | undefined)[][] {
  return bits(segments).map((row, i) => [...row, segments[i]!.merged]);
}

describe("window simplifier against the window and merger first written", () => {
  it(
    "gives the same strokes at the same samples, to the last bit",
    () => {
      fc.assert(
        fc.property(drawingArb, (drawing) => {
          const fast = new WindowSimplifier(drawing.params);
          const reference = new ReferenceMergedSimplifier(drawing.params);
          for (const path of pathsOf(drawing)) {
            // The merger first written knows no gap: it takes the still sample the simplifier
            // takes before a sample after a stop (`takenSamples`).
            const taken = takenSamples(path, drawing.params.rest_ms);
            let at = 0;
            for (const sample of path) {
              const expected = taken[at] === sample ? [] : [...reference.push(taken[at++]!)];
              expected.push(...reference.push(taken[at++]!));
              expect(merged(fast.push(sample))).toEqual(merged(expected));
              expect(fast.lineStart).toStrictEqual(reference.lineStart);
            }
            expect(merged(fast.end())).toEqual(merged(reference.end()));
            expect(fast.mergedBack).toBe(reference.mergedBack);
          }
        }),
        { numRuns: 2000 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );
});
