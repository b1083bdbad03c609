/** The outbox: nothing drawn offline is lost, order is kept, acknowledged strokes leave. */
import { describe, expect, it } from "vitest";
import { Outbox } from "../src/outbox";

describe("Outbox", () => {
  it("counts queued and in-flight strokes until they are acknowledged", () => {
    const outbox = new Outbox<string>();
    outbox.add("a");
    outbox.add("b");
    expect(outbox.size).toBe(2);
    const taken = outbox.takeQueued();
    expect(taken.map((entry) => entry.item)).toEqual(["a", "b"]);
    expect(outbox.size).toBe(2);
    expect(outbox.queuedCount).toBe(0);
    outbox.ack(taken[0]!.id);
    expect(outbox.size).toBe(1);
  });

  it("puts failed strokes back in their original order", () => {
    const outbox = new Outbox<string>();
    ["a", "b", "c"].forEach((item) => outbox.add(item));
    const [a, b, c] = outbox.takeQueued();
    outbox.add("d");
    outbox.fail(c!.id);
    outbox.fail(a!.id);
    outbox.ack(b!.id);
    expect(outbox.takeQueued().map((entry) => entry.item)).toEqual(["a", "c", "d"]);
  });

  it("requeues everything in flight when the connection is replaced", () => {
    const outbox = new Outbox<number>();
    [1, 2].forEach((item) => outbox.add(item));
    outbox.takeQueued();
    outbox.requeueInFlight();
    expect(outbox.queuedCount).toBe(2);
    expect(outbox.takeQueued().map((entry) => entry.item)).toEqual([1, 2]);
  });

  it("requeued, strokes in flight go back among the queued ones in their order", () => {
    const outbox = new Outbox<number>();
    [1, 2, 3].forEach((item) => outbox.add(item));
    outbox.takeQueued();
    [4, 5].forEach((item) => outbox.add(item));
    outbox.requeueInFlight();
    expect(outbox.size).toBe(5);
    expect(outbox.takeQueued().map((entry) => entry.item)).toEqual([1, 2, 3, 4, 5]);
    outbox.requeueInFlight();
    expect(outbox.takeQueued().map((entry) => entry.item)).toEqual([1, 2, 3, 4, 5]);
  });
});
