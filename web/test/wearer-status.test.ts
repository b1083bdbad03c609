/** What the page does with the wearer's choice in the sleeve's status, and what it says of it. */
import { describe, expect, it } from "vitest";
import {
  ceilingNote,
  clockTime,
  holdDetail,
  holdHeadline,
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
    });
  });

  it("holds while do not disturb runs, and not once it has run out", () => {
    const controls = { ...NO_CONTROLS, do_not_disturb_until_ms: nowMs + 60_000 };
    expect(wearerHold(controls, nowMs)).toEqual({ reason: "do_not_disturb", untilMs: nowMs + 60_000 });
    expect(wearerHold(controls, nowMs + 60_000)).toBeNull();
  });

  it("says paused when paused and do not disturb both hold (pausing has no end)", () => {
    const controls = { ...NO_CONTROLS, paused: true, do_not_disturb_until_ms: nowMs + 60_000 };
    expect(wearerHold(controls, nowMs)?.reason).toBe("paused");
  });

  it("holds nothing under a ceiling alone", () => {
    expect(wearerHold({ ...NO_CONTROLS, ceiling: 0.3 }, nowMs)).toBeNull();
  });
});

describe("the page's words", () => {
  const at = new Date(2026, 10, 26, 14, 30).getTime();

  it("names the wearer's pause, and when when known", () => {
    expect(holdHeadline({ reason: "paused", sinceMs: null })).toBe("The wearer paused the sleeve.");
    expect(holdHeadline({ reason: "paused", sinceMs: at })).toBe("The wearer paused the sleeve at 14:30.");
  });

  it("names the end of do not disturb", () => {
    expect(holdHeadline({ reason: "do_not_disturb", untilMs: at })).toBe(
      "The wearer asked not to be disturbed until 14:30.",
    );
    expect(clockTime(new Date(2026, 0, 1, 9, 5).getTime())).toBe("09:05");
  });

  it("says how many strokes are held and that they are not sent", () => {
    expect(holdDetail({ reason: "paused", sinceMs: null }, 3)).toBe(
      "3 strokes held here, not sent: the sleeve would refuse them. The page offers to send them when the wearer resumes.",
    );
    expect(holdDetail({ reason: "paused", sinceMs: null }, 1)).toMatch(/^1 stroke held/);
    expect(holdDetail({ reason: "paused", sinceMs: null }, 0)).toMatch(
      /^What you draw is held here, not sent/,
    );
    expect(holdDetail({ reason: "do_not_disturb", untilMs: at }, 2)).toContain(
      "when 14:30, or when the wearer ends it",
    );
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
