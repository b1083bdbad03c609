/** The sleeve's queue, run as the Python reference runs it (testdata/queue). */
import { describe, expect, it } from "vitest";
import {
  queueCatchUpMs,
  queueStartMs,
  replayQueue,
  SLEEVE_FLOOR_MS,
  type QueueOutcome,
  type QueueStep,
} from "../src/sleeve-queue";
import { hasVectors, vectors } from "./testdata";

interface Vector {
  floor_ms: number;
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
    expect(replayQueue(vector.steps, vector.floor_ms)).toEqual(vector.outcomes);
  });

  it("uses the paper sleeve's floor, as the page does", () => {
    for (const [, vector] of cases) expect(vector.floor_ms).toBe(SLEEVE_FLOOR_MS);
  });
});

it("catches up by how far behind, down to the floor, never lengthening", () => {
  expect(queueCatchUpMs(100, 300, 400, 73.701)).toBe(200); // 200 behind
  expect(queueCatchUpMs(100, 600, 400, 73.701)).toBe(73.701); // the floor stops it
  expect(queueCatchUpMs(300, 300, 400, 73.701)).toBe(400); // not behind
  expect(queueCatchUpMs(100, 300, 50, 73.701)).toBe(50); // below the floor: as it came
  expect(queueCatchUpMs(100, Number.NEGATIVE_INFINITY, 400, 73.701)).toBe(400);
});

it("starts a stroke when it arrives or when the one before ends, whichever is later", () => {
  expect(queueStartMs(10, Number.NEGATIVE_INFINITY)).toBe(10);
  expect(queueStartMs(10, 25)).toBe(25);
  expect(queueStartMs(30, 25)).toBe(30);
});
