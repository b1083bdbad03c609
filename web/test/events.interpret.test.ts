/** What the sleeve's events mean for the drawing on the page: the vectors of testdata/events, read. */
import { describe, expect, it } from "vitest";
import {
  DELAYED_MS,
  deliveryDelayMs,
  interpretEvent,
  parseEvent,
  seconds,
  strokeLabel,
  type PlayedEvent,
  type SleeveEvent,
} from "../src/events";
import { hasVectors, vectors } from "./testdata";

const present = hasVectors("events", "event");
/** Every event vector, by file name (without "events/event/" and ".json"). */
const byName = new Map<string, SleeveEvent>(
  present
    ? vectors("events", "event").map(([name, vector]) => [
        name.replace(/^.*\//, "").replace(/\.json$/, ""),
        parseEvent(JSON.stringify((vector as { wire: unknown }).wire))!,
      ])
    : [],
);
const vector = (name: string): SleeveEvent => {
  const event = byName.get(name);
  if (event === undefined) throw new Error(`no vector events/event/${name}.json`);
  return event;
};
/** The drawing the vectors' strokes belong to. */
const DRAWING = "d-1";

describe.skipIf(!present)("events of the drawing on the page", () => {
  it("reads every vector as one of the drawing's, or as about no drawing in particular", () => {
    expect(byName.size).toBeGreaterThan(0);
    for (const [name, event] of byName) {
      const reading = interpretEvent(event, DRAWING);
      const aboutOne = "drawing" in event && event.drawing === DRAWING && event.seq !== null;
      // An event of the drawing is counted or noted; one of none is at most noted.
      if (aboutOne) expect(reading.counts.length + reading.notes.length, name).toBeGreaterThan(0);
      else expect(reading.counts, name).toEqual([]);
    }
  });

  it("counts a played stroke and gives it to the felt timeline", () => {
    const played = vector("played");
    const reading = interpretEvent(played, DRAWING);
    expect(reading.counts).toEqual(["played"]);
    expect(reading.played).toBe(played);
    expect(reading.notes).toEqual([]);
  });

  it("ignores a played stroke of another drawing, or of none", () => {
    expect(interpretEvent(vector("played"), "another")).toMatchObject({
      counts: [],
      notes: [],
      played: null,
    });
    expect(interpretEvent(vector("played"), null)).toMatchObject({ counts: [], played: null });
    expect(interpretEvent(vector("played-legacy"), DRAWING)).toMatchObject({ counts: [], played: null });
  });

  it("names an adjustment a person could feel", () => {
    // The vector asked for 120 ms and played 417.5 ms: far more than 5 % slower.
    const reading = interpretEvent(vector("adjusted"), DRAWING);
    expect(reading.counts).toEqual(["played"]);
    expect(reading.notes).toEqual([
      { kind: "adjusted", text: "Stroke 4 played in 418 ms instead of 120 ms (too fast)." },
    ]);
  });

  it("keeps an adjustment under 5 % quiet", () => {
    const adjusted = vector("adjusted");
    if (adjusted.type !== "adjusted") throw new Error("the adjusted vector is not one");
    const small = { ...adjusted, requested_duration_ms: adjusted.duration_ms * 0.97 };
    expect(interpretEvent(small, DRAWING).notes).toEqual([]);
  });

  it("marks a stroke delayed on its way, but not one that waited behind the strokes before it", () => {
    const played = vector("played-with-sent-at") as PlayedEvent;
    const sentAtMs = played.first_command_at_ms - 1500;
    const delayed = interpretEvent({ ...played, sent_at_ms: sentAtMs }, DRAWING);
    expect(delayed.counts).toEqual(["played", "delayed"]);
    expect(delayed.delayMs).toBeCloseTo(1500, 6);
    expect(delayed.notes.map((note) => note.text)).toEqual([
      "Stroke 4 delayed 1.5 s on the way (held while the broker was out of reach, at the broker, or by the network).",
    ]);
    const queued = interpretEvent({ ...played, sent_at_ms: sentAtMs, queued_ms: 1500 }, DRAWING);
    expect(queued.counts).toEqual(["played"]);
    // The vector's own stroke: 64.5 ms from sent to felt, far under the limit.
    expect(deliveryDelayMs(played)).toBeLessThan(DELAYED_MS);
    expect(interpretEvent(played, DRAWING).counts).toEqual(["played"]);
  });

  it("counts a refused stroke of the drawing and names it for the canvas and the timeline", () => {
    const reading = interpretEvent(vector("rejected"), DRAWING);
    expect(reading.counts).toEqual(["refused"]);
    expect(reading.refusedSeq).toBe(3);
    expect(reading.unplayed).toEqual({ seq: 3, why: "refused" });
    expect(reading.notes).toEqual([
      { kind: "rejected", text: "Stroke 4 refused: start (4, 0) is outside the grid" },
    ]);
  });

  it("says a stroke skipped as late as the card's summary says it, counted among the refused", () => {
    const message =
      "the stroke would start 2.10 s after it was due: it arrived 2.05 s later than its drawing's quickest stroke";
    const late = { ...vector("rejected"), reason: "late", message } as SleeveEvent;
    const reading = interpretEvent(late, DRAWING);
    expect(reading.counts).toEqual(["refused"]);
    expect(reading.unplayed).toEqual({ seq: 3, why: "refused" });
    expect(reading.notes).toEqual([{ kind: "rejected", text: `Stroke 4 skipped as late: ${message}` }]);
  });

  it("shows a refusal of no drawing in particular, but counts and marks nothing", () => {
    const reading = interpretEvent(vector("rejected-unparsed"), DRAWING);
    expect(reading.counts).toEqual([]);
    expect(reading.refusedSeq).toBeNull();
    expect(reading.notes).toEqual([{ kind: "rejected", text: "A stroke refused: not JSON" }]);
  });

  it("leaves the timeline alone for the refusal of a copy: the stroke itself was played or refused before", () => {
    const rejected = vector("rejected");
    if (rejected.type !== "rejected") throw new Error("the rejected vector is not one");
    const copy = interpretEvent({ ...rejected, reason: "duplicate", message: "already played" }, DRAWING);
    expect(copy.unplayed).toBeNull();
  });

  it("refuses a stroke the duty-cycle cap kept from playing: counted, marked, nothing felt of it", () => {
    expect(interpretEvent(vector("safety-duty-cycle"), DRAWING)).toMatchObject({
      counts: ["refused"],
      refusedSeq: 3,
      unplayed: { seq: 3, why: "capped" },
      notes: [
        {
          kind: "rejected",
          text: "Stroke 4 refused by the duty-cycle cap: not played: the motor would have been driven 52% of the last 60 s",
        },
      ],
    });
    // Another drawing's: a safety note, nothing counted or marked.
    const other = interpretEvent(vector("safety-duty-cycle"), "another");
    expect(other).toMatchObject({ counts: [], refusedSeq: null, unplayed: null });
    expect(other.notes.map((note) => note.kind)).toEqual(["error"]);
  });

  it("says nothing of another drawing's refusal", () => {
    expect(interpretEvent(vector("rejected"), "another")).toMatchObject({
      counts: [],
      notes: [],
      refusedSeq: null,
      unplayed: null,
    });
  });

  it("tells a stroke cut short from one cancelled before it played", () => {
    const cut = interpretEvent(vector("cancelled-playing"), DRAWING);
    expect(cut.counts).toEqual(["cancelled", "cut"]);
    expect(cut.cancelled).toBe(vector("cancelled-playing"));
    expect(cut.notes).toEqual([{ kind: "info", text: "Stroke 4 cancelled while playing." }]);
    const queued = interpretEvent(vector("cancelled-queued"), DRAWING);
    expect(queued.counts).toEqual(["cancelled"]);
    expect(queued.notes).toEqual([{ kind: "info", text: "Stroke 4 cancelled before it played." }]);
    // The wearer's stop is said as the wearer's, not as the sender's Stop.
    const byWearer = interpretEvent({ ...vector("cancelled-queued"), by: "wearer" } as SleeveEvent, DRAWING);
    expect(byWearer.notes).toEqual([
      { kind: "info", text: "Stroke 4 cancelled by the wearer before it played." },
    ]);
  });

  it("reports safety and errors whatever the drawing", () => {
    for (const drawing of [DRAWING, null]) {
      expect(interpretEvent(vector("safety-off-failed"), drawing).notes).toEqual([
        { kind: "error", text: "Safety: actuator (0, 3) switched off: off failed" },
      ]);
      expect(interpretEvent(vector("error-backend"), drawing).notes).toEqual([
        { kind: "error", text: "The sleeve reports an error: I2C error" },
      ]);
      expect(interpretEvent(vector("error-player-crashed"), drawing).notes).toEqual([
        { kind: "error", text: "The sleeve reports an error: player crashed" },
      ]);
    }
  });
});

describe("durations as read", () => {
  it.each([
    [420.4, "420 ms"],
    [999, "999 ms"],
    [1000, "1.0 s"],
    [1549, "1.5 s"],
  ])("%d ms reads %s", (ms, text) => {
    expect(seconds(ms)).toBe(text);
  });
});

describe.skipIf(!present)("strokeLabel", () => {
  it("names strokes from 1, as the sender counts them: seq 0 on the wire is the first", () => {
    expect(strokeLabel(0)).toBe("Stroke 1");
    expect(strokeLabel(75)).toBe("Stroke 76");
    expect(strokeLabel(null)).toBe("A stroke");
  });

  it("every note about a stroke names it the same way", () => {
    for (const name of ["adjusted", "cancelled-playing", "cancelled-queued"] as const) {
      const event = vector(name);
      const seq = "seq" in event ? event.seq : null;
      const reading = interpretEvent(event, DRAWING);
      expect(seq).not.toBeNull();
      for (const note of reading.notes) expect(note.text.startsWith(`${strokeLabel(seq)} `)).toBe(true);
    }
  });
});
