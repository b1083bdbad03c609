/**
 * The window simplifier gives the same strokes to the last bit as the simplifier first written
 * (`window-reference.ts`: every sample tested at every new one, the mapping computed in full),
 * on random drawings (`window-drawings.ts`).
 */
import fc from "fast-check";
import { describe, expect, it } from "vitest";
import { WindowCore } from "../src/simplify/window";
import { bits, drawingArb, pathsOf } from "./window-drawings";
import { ReferenceWindowSimplifier } from "./window-reference";

/** Thousands of drawings: generous, for a loaded machine (the work is bounded, not timed). */
const PROPERTY_TIMEOUT_MS = 240_000;

describe("window simplifier against the reference", () => {
  it(
    "gives the same segments at the same samples, to the last bit",
    () => {
      fc.assert(
        fc.property(drawingArb, (drawing) => {
          const fast = new WindowCore(drawing.params);
          const reference = new ReferenceWindowSimplifier(drawing.params);
          for (const path of pathsOf(drawing)) {
            for (const sample of path) {
              expect(bits(fast.push(sample))).toEqual(bits(reference.push(sample)));
              expect(fast.lineStart).toStrictEqual(reference.lineStart);
              expect(fast.drawing).toBe(reference.drawing);
            }
            expect(bits(fast.end())).toEqual(bits(reference.end()));
            expect(fast.drawing).toBe(false);
          }
        }),
        { numRuns: 2000 },
      );
    },
    PROPERTY_TIMEOUT_MS,
  );
});
