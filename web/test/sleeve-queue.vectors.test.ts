/** The sleeve's queue, run as the Python reference runs it (testdata/queue). */
import { describe, expect, it } from "vitest";
import { placeStrokes, type FeltStroke } from "../src/felt";
import {
  EMPTY_TAIL_MS,
  QueueTail,
  queueStartMs,
  replayQueue,
  type QueueArrival,
  type QueueOutcome,
  type QueueStep,
} from "../src/sleeve-queue";
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

  // The page sends each stroke once and learns of cancels from the sleeve's events: its felt
  // timeline, given the strokes in the order they arrive and the cuts the sleeve reported (a
  // stroke dropped before it started: cut at 0), places each where the sleeve played it. Not
  // where a cancel of one drawing leaves another's strokes planned: the timeline is one drawing's,
  // and where other strokes share the queue the sleeve's reported starts place them.
  const OTHER_DRAWING_KEPT = "queue/cancel-one-drawing.json";
  const oneQueue = cases.filter(([name]) => name !== OTHER_DRAWING_KEPT);
  it("leaves out only the vector of a cancel that keeps another drawing's strokes", () => {
    expect(cases.length - oneQueue.length).toBe(1);
  });
  it.each(oneQueue)("the felt timeline places %s as the sleeve played it", (_name, vector) => {
    const arrivals = vector.steps.filter((step): step is QueueArrival => !("cancel" in step));
    const strokes: FeltStroke[] = [];
    const cut = new Map<number, number>();
    const expected: { seq: number; start_ms?: number; played_ms: number }[] = [];
    arrivals.forEach((arrival, seq) => {
      const outcome = vector.outcomes[seq]!;
      if (outcome.outcome === "duplicate" || outcome.outcome === "held") return; // a copy: never sent twice
      strokes.push({
        seq,
        start: [0, 0],
        end: [1, 0],
        duration_ms: arrival.duration_ms,
        intensity: 1,
        arrives_ms: arrival.arrival_ms,
      });
      if (!("start_ms" in outcome)) {
        cut.set(seq, 0); // cancelled: dropped before it started
        expected.push({ seq, played_ms: 0 });
      } else {
        if (outcome.outcome === "cut") cut.set(seq, outcome.played_ms);
        expected.push({ seq, start_ms: outcome.start_ms, played_ms: outcome.played_ms });
      }
    });
    const placed = new Map(placeStrokes(strokes, new Map(), cut).map((p) => [p.seq, p]));
    for (const { seq, start_ms, played_ms } of expected) {
      const stroke = placed.get(seq)!;
      expect(stroke.played_ms, `stroke ${seq} played`).toBe(played_ms);
      if (start_ms !== undefined) expect(stroke.start_ms, `stroke ${seq} start`).toBe(start_ms);
    }
  });
});

it("starts a stroke when it arrives or when the one before ends, whichever is later", () => {
  expect(queueStartMs(10, Number.NEGATIVE_INFINITY)).toBe(10);
  expect(queueStartMs(10, 25)).toBe(25);
  expect(queueStartMs(30, 25)).toBe(30);
});

describe("QueueTail", () => {
  it("moves the tail to the end of each stroke it places", () => {
    const queue = new QueueTail();
    expect(queue.tailMs).toBe(EMPTY_TAIL_MS);
    expect(queue.place(10, 100)).toBe(10);
    expect(queue.tailMs).toBe(110);
    expect(queue.place(50, 40)).toBe(110);
    expect(queue.tailMs).toBe(150);
    expect(queue.place(400, 10)).toBe(400);
  });

  it("takes a start the sleeve reported over the rule, and goes on from its end", () => {
    const queue = new QueueTail(500);
    expect(queue.place(0, 100, 30)).toBe(30);
    expect(queue.tailMs).toBe(130);
  });

  it("after a cancel, ends with the latest stroke still planned, or is empty", () => {
    const queue = new QueueTail(900);
    queue.replan([300, 700, 450]);
    expect(queue.tailMs).toBe(700);
    queue.replan([]);
    expect(queue.tailMs).toBe(EMPTY_TAIL_MS);
  });
});
