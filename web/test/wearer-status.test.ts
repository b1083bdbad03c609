/** What the page does with the wearer's choice in the sleeve's status, and what it says of it. */
import { describe, expect, it } from "vitest";
import { clockTime } from "../src/clock";
import {
  ceilingNote,
  endedHeadline,
  holdChangeNote,
  holdDetail,
  holdHeadline,
  holdReason,
  NO_CONTROLS,
  playedIntensity,
  wearerHold,
  wearerRefusalNote,
} from "../src/wearer-status";

describe("wearerHold", () => {
  const nowMs = Date.UTC(2026, 10, 26, 13, 0);
  it("holds while paused, with the time it paused when known", () => {
    expect(wearerHold({ ...NO_CONTROLS, paused: true }, nowMs, 123)).toEqual({
      reason: "paused",
      sinceMs: 123,
      untilMs: null,
    });
  });

  it("holds while do not disturb runs, and not once it has run out", () => {
    const controls = { ...NO_CONTROLS, do_not_disturb_until_ms: nowMs + 60_000 };
    expect(wearerHold(controls, nowMs)).toEqual({ reason: "do_not_disturb", untilMs: nowMs + 60_000 });
    expect(wearerHold(controls, nowMs + 60_000)).toBeNull();
  });

  it("says paused when paused and do not disturb both hold (pausing has no end), with the end of the other", () => {
    const controls = { ...NO_CONTROLS, paused: true, do_not_disturb_until_ms: nowMs + 60_000 };
    expect(wearerHold(controls, nowMs)).toEqual({ reason: "paused", sinceMs: null, untilMs: nowMs + 60_000 });
    expect(wearerHold(controls, nowMs + 60_000)).toEqual({ reason: "paused", sinceMs: null, untilMs: null });
  });

  it("holds nothing under a ceiling alone", () => {
    expect(wearerHold({ ...NO_CONTROLS, ceiling: 0.3 }, nowMs)).toBeNull();
  });
});

describe("the page's words", () => {
  const at = new Date(2026, 10, 26, 14, 30).getTime();
  const before = new Date(2026, 10, 26, 13, 0).getTime();
  const paused = { reason: "paused", sinceMs: null, untilMs: null } as const;
  const dnd = { reason: "do_not_disturb", untilMs: at } as const;

  it("names the wearer's pause, and when when known", () => {
    expect(holdHeadline(paused, before)).toBe("The wearer paused the sleeve.");
    expect(holdHeadline({ ...paused, sinceMs: before }, at)).toBe("The wearer paused the sleeve at 13:00.");
    // Seen yesterday: said so, not as if today.
    const lateLastNight = new Date(2026, 10, 25, 23, 50).getTime();
    expect(holdHeadline({ ...paused, sinceMs: lateLastNight }, at)).toBe(
      "The wearer paused the sleeve yesterday at 23:50.",
    );
  });

  it("names the end of do not disturb, and its day when not today", () => {
    expect(holdHeadline(dnd, before)).toBe("The wearer asked not to be disturbed until 14:30.");
    const lateEvening = new Date(2026, 10, 25, 23, 0).getTime();
    expect(holdHeadline(dnd, lateEvening)).toBe(
      "The wearer asked not to be disturbed until tomorrow at 14:30.",
    );
    expect(clockTime(new Date(2026, 0, 1, 9, 5).getTime())).toBe("09:05");
  });

  it("says how many strokes are held, that they are not sent, and when they may be", () => {
    expect(holdDetail(paused, 3, before)).toBe(
      "3 strokes held here, not sent: the sleeve would refuse them. The page offers to send them when the wearer resumes.",
    );
    expect(holdDetail(paused, 1, before)).toMatch(/^1 stroke held/);
    expect(holdDetail(paused, 0, before)).toMatch(/^What you draw is held here, not sent/);
    expect(holdDetail(dnd, 2, before)).toBe(
      "2 strokes held here, not sent: the sleeve would refuse them. The page offers to send them at 14:30, when do not disturb ends, or sooner if the wearer ends it.",
    );
    // Paused under do not disturb: resuming alone does not let them through.
    expect(holdDetail({ ...paused, untilMs: at }, 2, before)).toContain(
      "when the wearer resumes and do not disturb has ended (it runs until 14:30)",
    );
  });

  it("says who ended the hold: the wearer's resume, do not disturb's time, or the wearer ending it", () => {
    expect(endedHeadline({ hold: paused, ranOut: false }, at)).toBe("The wearer resumed the sleeve.");
    expect(endedHeadline({ hold: dnd, ranOut: true }, at)).toBe("Do not disturb ended at 14:30.");
    expect(endedHeadline({ hold: dnd, ranOut: false }, before)).toBe("The wearer ended do not disturb.");
    expect(endedHeadline(null, at)).not.toMatch(/wearer/);
  });

  it("logs each change of what holds the drawing as what happened", () => {
    expect(holdChangeNote(null, paused, false, before)).toBe(
      "The wearer paused the sleeve: what you draw is held here until the wearer resumes.",
    );
    expect(holdChangeNote(null, dnd, false, before)).toBe(
      "The wearer asked not to be disturbed until 14:30: what you draw is held here until then.",
    );
    expect(holdChangeNote(paused, null, false, before)).toBe(
      "The wearer resumed the sleeve: what you draw is sent again.",
    );
    expect(holdChangeNote(dnd, null, true, at)).toBe(
      "Do not disturb ended at 14:30: what you draw is sent again.",
    );
    expect(holdChangeNote(dnd, null, false, before)).toBe(
      "The wearer ended do not disturb: what you draw is sent again.",
    );
    expect(holdChangeNote(paused, dnd, false, before)).toBe(
      "The wearer resumed the sleeve, but asked not to be disturbed until 14:30: what you draw is still held here.",
    );
    expect(holdChangeNote(dnd, { ...paused, untilMs: at }, false, before)).toContain(
      "until the wearer resumes and do not disturb has ended (it runs until 14:30)",
    );
    expect(holdChangeNote(dnd, { ...dnd, untilMs: at + 3_600_000 }, false, before)).toBe(
      "The wearer now asks not to be disturbed until 15:30: what you draw is held here until then.",
    );
    // Nothing new: no line.
    expect(holdChangeNote(dnd, dnd, false, before)).toBeNull();
    expect(holdChangeNote(paused, { ...paused, untilMs: at }, false, before)).toBeNull();
    expect(holdChangeNote(null, null, false, before)).toBeNull();
  });

  it("says a late refusal is the wearer's pause, with the sleeve's message", () => {
    expect(wearerRefusalNote("Stroke 4", "paused", "Paused by the wearer.")).toBe(
      "Stroke 4 not played: the wearer paused the sleeve. Paused by the wearer.",
    );
    expect(wearerRefusalNote("Stroke 4", "do_not_disturb", "Until 14:30.")).toContain(
      "asked not to be disturbed",
    );
  });

  it("says what the sleeve plays under the wearer's ceiling", () => {
    expect(ceilingNote(null, 0.8)).toBeNull();
    expect(ceilingNote(0.6, 0.8)).toBe("The wearer set a ceiling of 60 %: your 80 % plays at 60 %.");
    expect(ceilingNote(0.6, 0.5)).toBe("The wearer set a ceiling of 60 %: your 50 % plays as set.");
    expect(playedIntensity(0.8, 0.6)).toBe(0.6);
    expect(playedIntensity(0.5, 0.6)).toBe(0.5);
    expect(playedIntensity(0.8, null)).toBe(0.8);
  });
});

describe("a sleeve that paused itself", () => {
  it("is not said as the wearer's pause", () => {
    // Started paused because its settings file could not be read (`paused_by: "sleeve"`).
    const controls = { paused: true, paused_by: "sleeve", ceiling: 0.05, do_not_disturb_until_ms: null };
    const hold = wearerHold(controls, 1_000);
    expect(hold).toEqual({ reason: "paused", sinceMs: null, untilMs: null, bySleeve: true });
    expect(holdHeadline(hold!, 1_000)).toBe(
      "The sleeve paused itself (it could not read its wearer's last choices).",
    );
    expect(holdChangeNote(null, hold, false, 1_000)).toMatch(/^The sleeve paused itself \(/);
    expect(holdReason(hold!)).toBe("the sleeve paused itself");
    const byWearer = wearerHold({ ...controls, paused_by: "page" }, 1_000);
    expect(holdHeadline(byWearer!, 1_000)).toBe("The wearer paused the sleeve.");
  });
});
