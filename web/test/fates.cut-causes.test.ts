/**
 * A stroke cut short while playing is said with what cut it: the sender's Stop, the wearer's
 * pause or stop, or a fault on the sleeve (a chip lost mid-stroke, the sleeve stopped or its process
 * ended mid-stroke), never a fault as "Stop".
 */
import { describe, expect, it } from "vitest";
import { parseEvent, type SleeveEvent } from "../src/events";
import { cancelledWords, cutShortWords, DrawingFates } from "../src/fates";

const event = (fields: Record<string, unknown>): SleeveEvent => {
  const parsed = parseEvent(JSON.stringify(fields));
  if (parsed === null) throw new Error(`not an event: ${JSON.stringify(fields)}`);
  return parsed;
};
const stroke = { topic: "feelmysign/sleeve1/strokes", drawing: "d-1", received_at_ms: 1795326267664.25 };
const played = (seq: number): SleeveEvent =>
  event({
    type: "played",
    ...stroke,
    seq,
    start_at_ms: 1795326267664.25,
    first_command_at_ms: 1795326267664.5,
    latency_ms: 0.25,
    start_error_ms: 0.031,
    queued_ms: 0,
    duration_ms: 417.5,
    commands: 5,
  });
const cut = (seq: number, by?: string): SleeveEvent =>
  event({
    type: "cancelled",
    reason: "cancelled",
    message: "cut short",
    ...stroke,
    seq,
    cancelled_at_ms: 1795326268000.5,
    started: true,
    ...(by === undefined ? {} : { by }),
  });
const chipLost = (seq: number): SleeveEvent =>
  event({
    type: "safety",
    reason: "chip_lost",
    row: 0,
    column: 3,
    message: "a chip stopped answering",
    ...stroke,
    seq,
  });

// What the sleeve started after a kill -9 says of the stroke the killed one was playing.
const crashed = (seq: number): SleeveEvent =>
  event({
    type: "safety",
    reason: "crashed",
    row: 0,
    column: 0,
    message: "cut short, after its played event: the sleeve's process ended while it played",
    ...stroke,
    seq,
  });

describe("what cut a stroke short", () => {
  it("tells Stop, the wearer and a fault apart, each stroke once", () => {
    const fates = new DrawingFates();
    fates.add(cut(1));
    fates.add(cut(2, "wearer"));
    fates.add(cut(2, "wearer")); // delivered again
    fates.add(played(3));
    fates.add(chipLost(3)); // a lost chip after the stroke started: cut, not played
    expect(fates.counts()).toEqual({ played: 0, cut: 3, cancelled: 0, refused: 0 });
    expect(fates.cutCauses()).toEqual({ byWearer: 1, byFault: 1 });
    const causes = fates.cutCauses();
    expect(cutShortWords(3, causes)).toEqual([
      "1 cut short by Stop",
      "1 cut short by the wearer",
      "1 cut short by a fault on the sleeve",
    ]);
  });

  it("counts a stroke the sleeve's end cut short as cut by a fault, once", () => {
    const fates = new DrawingFates();
    fates.add(played(0));
    fates.add(played(1));
    fates.add(crashed(1)); // from the restarted sleeve, after the killed one's played event
    fates.add(crashed(1)); // delivered again
    expect(fates.counts()).toEqual({ played: 1, cut: 1, cancelled: 0, refused: 0 });
    expect(fates.fate(1)).toBe("cut");
    expect(cutShortWords(1, fates.cutCauses())).toEqual(["1 cut short by a fault on the sleeve"]);
  });

  it("says Stop only for what no one else cut, and never more causes than cuts", () => {
    expect(cutShortWords(2)).toEqual(["2 cut short by Stop"]);
    expect(cutShortWords(0, { byWearer: 0, byFault: 0 })).toEqual([]);
    expect(cutShortWords(1, { byWearer: 3, byFault: 2 })).toEqual(["1 cut short by the wearer"]);
  });
});

const dropped = (seq: number, by?: string): SleeveEvent =>
  event({
    type: "cancelled",
    reason: "cancelled",
    message: "dropped before it played",
    ...stroke,
    seq,
    cancelled_at_ms: 1795326268000.5,
    started: false,
    ...(by === undefined ? {} : { by }),
  });

describe("who cancelled a stroke before it played", () => {
  it("tells the wearer's stop from the sender's Stop, in the card's and the caption's words", () => {
    const fates = new DrawingFates();
    fates.add(dropped(0));
    fates.add(dropped(1, "wearer"));
    fates.add(dropped(2, "wearer"));
    fates.add(dropped(2, "wearer")); // delivered again
    expect(fates.counts()).toEqual({ played: 0, cut: 0, cancelled: 3, refused: 0 });
    expect(fates.cancelledByWearer()).toBe(2);
    expect(fates.reason(1)).toBe("wearer");
    expect(cancelledWords(3, fates.cancelledByWearer())).toEqual([
      "1 cancelled by Stop",
      "2 cancelled by the wearer",
    ]);
    expect(cancelledWords(1, 1, "before {it} played")).toEqual([
      "1 cancelled by the wearer before it played",
    ]);
    expect(cancelledWords(2, 0, "before {it} played")).toEqual(["2 cancelled by Stop before they played"]);
  });
});
