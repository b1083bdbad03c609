/** The sleeve's events and status, read and written as the Python reference does (testdata/events). */
import { describe, expect, it } from "vitest";
import {
  DELAYED_MS,
  deliveryDelayMs,
  eventToJson,
  isDelayed,
  NOTABLE_ADJUSTMENT,
  parseEvent,
  parseStatus,
  readEvent,
  readStatus,
  statusToJson,
} from "../src/events";
import { catchUpWords, DrawingFates, type CatchUp } from "../src/fates";
import { hasVectors, vectors } from "./testdata";

interface ValidVector {
  description: string;
  wire: unknown;
  typed: Record<string, unknown>;
  json: Record<string, unknown>;
}

interface InvalidVector {
  description: string;
  kind: "event" | "status";
  wire: unknown;
}

/** A played event's delivery delay, as the terminal of `feelmysign up` computes it. */
interface DelayVector {
  description: string;
  wire: unknown;
  delayed_ms: number;
  delay_ms: number | null;
  delayed: boolean;
}

const present = hasVectors("events");
const events = present ? (vectors("events", "event") as [string, ValidVector][]) : [];
const statuses = present ? (vectors("events", "status") as [string, ValidVector][]) : [];
const invalid = present ? (vectors("events", "invalid") as [string, InvalidVector][]) : [];
const delays = present ? (vectors("events", "delay") as [string, DelayVector][]) : [];

describe.skipIf(!present)("event and status vectors", () => {
  it("finds every group", () => {
    expect(events.length).toBeGreaterThan(0);
    expect(statuses.length).toBeGreaterThan(0);
    expect(invalid.length).toBeGreaterThan(0);
    expect(delays.length).toBeGreaterThan(0);
  });

  it("marks delayed strokes at the threshold the terminal uses", () => {
    expect(delays.every(([, vector]) => vector.delayed_ms === DELAYED_MS)).toBe(true);
  });

  it.each(delays)("delay %s", (_name, vector) => {
    const event = parseEvent(JSON.stringify(vector.wire));
    if (event === null || (event.type !== "played" && event.type !== "adjusted")) {
      throw new Error("a delay vector is a played or adjusted event");
    }
    expect(deliveryDelayMs(event)).toBe(vector.delay_ms);
    expect(isDelayed(event)).toBe(vector.delayed);
  });

  it.each(events)("%s", (_name, vector) => {
    const event = parseEvent(JSON.stringify(vector.wire));
    expect(event).toEqual(vector.typed);
    expect(eventToJson(event!)).toEqual(vector.json);
  });

  it.each(statuses)("%s", (_name, vector) => {
    const status = parseStatus(JSON.stringify(vector.wire));
    expect(status).toEqual(vector.typed);
    expect(statusToJson(status!)).toEqual(vector.json);
  });

  it.each(invalid)("%s", (_name, vector) => {
    const read = vector.kind === "event" ? readEvent : readStatus;
    expect(read(vector.wire)).toBeNull();
  });
});

describe("text that is not JSON", () => {
  it.each(["", "{", "null", '"played"'])("gives null for %j", (text) => {
    expect(parseEvent(text)).toBeNull();
    expect(parseStatus(text)).toBeNull();
  });
});

/** What became of a drawing's strokes, as feelmysign.fates says (the page, `up` and the study). */
interface FateVector {
  description: string;
  wire: unknown[];
  fates: Record<string, string>;
  counts: Record<string, number>;
  refusals: Record<string, number>;
  /** Played faster to catch up (and by how much in all), slowed to the floor, skipped as late. */
  catch_up: CatchUp;
  /** Changes of duration below this share are not said (events.ts `NOTABLE_ADJUSTMENT`). */
  notable_change: number;
  /** What the card, `up` and `send --wait` say of the played strokes' pace. */
  catch_up_words: string;
}

const fates = present ? (vectors("events", "fates") as [string, FateVector][]) : [];

describe.skipIf(!present)("fate vectors", () => {
  it("finds them", () => {
    expect(fates.length).toBeGreaterThan(0);
  });

  it.each(fates)("fates %s", (_name, vector) => {
    const drawing = new DrawingFates();
    for (const wire of vector.wire) {
      const event = readEvent(wire);
      if (event === null) throw new Error(`not an event: ${JSON.stringify(wire)}`);
      drawing.add(event);
    }
    expect(Object.fromEntries([...drawing.fates()].map(([seq, fate]) => [String(seq), fate]))).toEqual(
      vector.fates,
    );
    expect(drawing.counts()).toEqual(vector.counts);
    expect(Object.fromEntries(drawing.refusals())).toEqual(vector.refusals);
    expect(NOTABLE_ADJUSTMENT).toBe(vector.notable_change);
    expect(drawing.catchUp()).toEqual(vector.catch_up);
    expect(catchUpWords(drawing.catchUp())).toBe(vector.catch_up_words);
  });

  it("cover catching up, slowing and skipping as late", () => {
    const caughtUp = fates.map(([, vector]) => vector.catch_up);
    expect(caughtUp.some((c) => c.compressed > 0 && c.compressed_ms >= 1000)).toBe(true);
    expect(caughtUp.some((c) => c.compressed > 0 && c.compressed_ms < 1000)).toBe(true);
    expect(caughtUp.some((c) => c.slowed > 0)).toBe(true);
    expect(caughtUp.some((c) => c.late > 0)).toBe(true);
  });
});
