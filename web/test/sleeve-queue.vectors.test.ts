/** The sleeve's queue, run as the Python reference runs it (testdata/queue). */
import { describe, expect, it } from "vitest";
import { placeStrokes, type FeltStroke } from "../src/felt";
import {
  EMPTY_TAIL_MS,
  queueCatchUpMs,
  QueueTail,
  queueStartMs,
  replayQueue,
  SLEEVE_FLOOR_MS,
  type QueueArrival,
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

  // The page sends each stroke once and learns of cancels from the sleeve's events: its felt
  // timeline, given the strokes in the order they arrive and the cuts the sleeve reported (a
  // stroke dropped before it started: cut at 0), places each where the sleeve played it. The
  // timeline is one drawing's, so every stroke in it that waits catches up; the sleeve catches up
  // only a stroke waiting behind its own drawing. So not the vectors where a stroke waits behind
  // another drawing's stroke or where strokes have no drawing (the legacy format): there the page
  // has only its own drawing's strokes, and the sleeve's reported starts place them.
  const NOT_ONE_DRAWING = new Set([
    "queue/cancel-one-drawing.json", // a cancel of one drawing keeps another's strokes planned
    "queue/cancel-everything.json", // a stroke waits behind another drawing's
    "queue/catch-up-after-cancel.json", // a stroke waits behind another drawing's
    "queue/catch-up-other-drawing.json", // a stroke waits behind another drawing's
    "queue/drawings-share-the-queue.json", // a stroke waits behind another drawing's
    "queue/redelivery-other-drawing.json", // a stroke waits behind another drawing's
    "queue/catch-up-legacy.json", // legacy strokes, never caught up
    "queue/no-drawing.json", // legacy strokes, never caught up
  ]);
  const oneQueue = cases.filter(([name]) => !NOT_ONE_DRAWING.has(name));
  it("leaves out only the vectors whose strokes are not one drawing's", () => {
    expect(cases.length - oneQueue.length).toBe(NOT_ONE_DRAWING.size);
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
    const placed = new Map(
      placeStrokes(strokes, new Map(), cut, new Set(), vector.floor_ms).map((p) => [p.seq, p]),
    );
    for (const { seq, start_ms, played_ms } of expected) {
      const stroke = placed.get(seq)!;
      expect(stroke.played_ms, `stroke ${seq} played`).toBe(played_ms);
      if (start_ms !== undefined) expect(stroke.start_ms, `stroke ${seq} start`).toBe(start_ms);
    }
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
    const queue = new QueueTail(900, "a");
    queue.replan([
      [300, "a"],
      [700, "b"],
      [450, "a"],
    ]);
    expect([queue.tailMs, queue.tailDrawing]).toEqual([700, "b"]);
    queue.replan([]);
    expect([queue.tailMs, queue.tailDrawing]).toEqual([EMPTY_TAIL_MS, undefined]);
  });

  it("remembers the drawing of the stroke at its tail", () => {
    const queue = new QueueTail();
    queue.place(0, 100, undefined, "a");
    expect(queue.tailDrawing).toBe("a");
    queue.place(0, 100);
    expect(queue.tailDrawing).toBeUndefined();
  });

  it("catches up only a stroke that waits behind its own drawing", () => {
    const queue = new QueueTail();
    queue.place(0, 300, undefined, "a");
    expect(queue.catchUpMs(100, 300, 73.701, "a")).toBe(100); // 200 ms behind its own drawing
    expect(queue.catchUpMs(100, 300, 73.701, "b")).toBe(300); // behind another drawing
    expect(queue.catchUpMs(100, 300, 73.701, undefined)).toBe(300); // legacy: as it came
    expect(queue.catchUpMs(400, 300, 73.701, "a")).toBe(300); // not behind
    queue.place(0, 300); // a legacy stroke at the tail: nobody's drawing
    expect(queue.catchUpMs(100, 300, 73.701, "a")).toBe(300);
  });
});
