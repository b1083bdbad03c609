/**
 * The page's events subscription keeps a persistent session at QoS 1, so after a reconnect the
 * broker may deliver an event again (and the sleeve may publish a copy's refusal). Whatever
 * arrives twice, each stroke counts once, under one fate.
 */
import { describe, expect, it } from "vitest";
import { parseEvent, type SleeveEvent } from "../src/events";
import { DrawingFates, type Fate } from "../src/fates";
import { hasVectors, vectors } from "./testdata";

const present = hasVectors("events", "event");
const wire = (name: string): Record<string, unknown> => {
  const found = vectors("events", "event").find(([file]) => file.endsWith(`/${name}.json`));
  if (found === undefined) throw new Error(`no vector events/event/${name}.json`);
  return (found[1] as { wire: Record<string, unknown> }).wire;
};
const event = (fields: Record<string, unknown>): SleeveEvent => {
  const parsed = parseEvent(JSON.stringify(fields));
  if (parsed === null) throw new Error(`not an event: ${JSON.stringify(fields)}`);
  return parsed;
};
const total = (counts: Record<Fate, number>): number => Object.values(counts).reduce((sum, n) => sum + n, 0);

describe.skipIf(!present)("DrawingFates with redelivered events", () => {
  it("counts a played event delivered twice as one played stroke", () => {
    const fates = new DrawingFates();
    const played = event(wire("played"));
    fates.add(played);
    fates.add(played);
    expect(fates.counts()).toEqual({ played: 1, cut: 0, cancelled: 0, refused: 0 });
  });

  it("counts a rejected event delivered twice as one refused stroke, with one reason", () => {
    const fates = new DrawingFates();
    const rejected = event(wire("rejected-late"));
    fates.add(rejected);
    fates.add(rejected);
    expect(fates.counts()).toEqual({ played: 0, cut: 0, cancelled: 0, refused: 1 });
    expect([...fates.refusals().values()]).toEqual([1]);
  });

  it("keeps a played stroke played, once, whatever copies and redeliveries follow, in any order", () => {
    const played = event(wire("played"));
    const duplicate = event({
      ...wire("rejected-late"),
      drawing: played.type === "played" ? played.drawing : null,
      seq: played.type === "played" ? played.seq : null,
      reason: "duplicate",
      message: "a copy of a stroke already received",
      original_played: true,
    });
    const orders: SleeveEvent[][] = [
      [played, duplicate, played, duplicate],
      [duplicate, played, duplicate, played],
      [duplicate, duplicate, played],
    ];
    for (const order of orders) {
      const fates = new DrawingFates();
      for (const each of order) fates.add(each);
      expect(fates.counts()).toEqual({ played: 1, cut: 0, cancelled: 0, refused: 0 });
      expect(total(fates.counts())).toBe(1);
    }
  });
});
