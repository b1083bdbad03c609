/** The sleeve's queue, run as the Python reference runs it (testdata/queue). */
import { describe, expect, it } from "vitest";
import { queueStartMs, replayQueue, type QueueOutcome, type QueueStep } from "../src/sleeve-queue";
import { hasVectors, vectors } from "./testdata";

interface Vector {
  steps: QueueStep[];
  outcomes: QueueOutcome[];
}

const present = hasVectors("queue");
const cases = present ? (vectors("queue") as [string, Vector][]) : [];

describe.skipIf(!present)("queue vectors", () => {
  it("finds every outcome", () => {
    const seen = new Set(cases.flatMap(([, v]) => v.outcomes.map((o) => o.outcome)));
    expect([...seen].sort()).toEqual(["cancelled", "cut", "duplicate", "held", "played"]);
  });

  it.each(cases)("%s", (_name, vector) => {
    expect(replayQueue(vector.steps)).toEqual(vector.outcomes);
  });
});

it("starts a stroke when it arrives or when the one before ends, whichever is later", () => {
  expect(queueStartMs(10, Number.NEGATIVE_INFINITY)).toBe(10);
  expect(queueStartMs(10, 25)).toBe(25);
  expect(queueStartMs(30, 25)).toBe(30);
});
