/** Copies of a stroke's event (QoS 1 after a broker restart) are told apart from new events. */
import { describe, expect, it } from "vitest";
import { EventCopies, parseEvent, type SleeveEvent } from "../src/events";
import { hasVectors, vectors } from "./testdata";

const present = hasVectors("events", "event");
const wire = (name: string): string => {
  const found = vectors("events", "event").find(([file]) => file.endsWith(`/${name}.json`));
  if (found === undefined) throw new Error(`no vector events/event/${name}.json`);
  return JSON.stringify((found[1] as { wire: unknown }).wire);
};
const read = (text: string): SleeveEvent => parseEvent(text)!;

describe.skipIf(!present)("EventCopies", () => {
  it("holds back the second copy of a stroke's event, not the first", () => {
    const copies = new EventCopies();
    const played = wire("played");
    expect(copies.isCopy(played, read(played))).toBe(false);
    expect(copies.isCopy(played, read(played))).toBe(true);
  });

  it("lets through the same stroke's other events, and an event of the next stroke", () => {
    const copies = new EventCopies();
    const played = wire("played");
    const event = JSON.parse(played) as Record<string, unknown>;
    const next = JSON.stringify({ ...event, seq: (event.seq as number) + 1 });
    const cancelled = wire("cancelled-playing");
    for (const text of [played, next, cancelled]) expect(copies.isCopy(text, read(text))).toBe(false);
  });

  it("never holds back an event that names no stroke: two errors are two errors", () => {
    const copies = new EventCopies();
    for (const name of ["error-backend", "rejected-unparsed", "played-legacy"]) {
      const text = wire(name);
      expect(copies.isCopy(text, read(text))).toBe(false);
      expect(copies.isCopy(text, read(text))).toBe(false);
    }
  });

  it("forgets the oldest event beyond its capacity, so memory stays bounded", () => {
    const copies = new EventCopies(3);
    const event = JSON.parse(wire("played")) as Record<string, unknown>;
    const texts = [1, 2, 3, 4].map((seq) => JSON.stringify({ ...event, seq }));
    for (const text of texts) expect(copies.isCopy(text, read(text))).toBe(false);
    expect(copies.isCopy(texts[0]!, read(texts[0]!))).toBe(false); // forgotten
    expect(copies.isCopy(texts[3]!, read(texts[3]!))).toBe(true); // still remembered
  });
});
