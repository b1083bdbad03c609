/** The page holds the drawing while the wearer paused, and offers it when the wearer is back. */
import { describe, expect, it } from "vitest";
import type { Stroke } from "../src/protocol";
import { WearerHoldKeeper } from "../src/wearer-hold";
import { NO_CONTROLS } from "../src/wearer-status";

const PAUSED = { ...NO_CONTROLS, paused: true, paused_by: "button" };
const T0 = 1_800_000_000_000;

function stroke(seq: number): Stroke {
  return { start: [0, 0], end: [1, 0], duration_ms: 200, intensity: 0.8, drawing: "d1", seq };
}

describe("WearerHoldKeeper", () => {
  it("lets strokes through when the wearer has chosen nothing", () => {
    const keeper = new WearerHoldKeeper();
    keeper.onStatus(NO_CONTROLS, true, T0, T0);
    expect(keeper.keep(stroke(0), T0)).toBe(false);
    expect(keeper.view(T0)).toEqual({ state: "none" });
  });

  it("keeps the strokes drawn while paused, and hands them over once resumed", () => {
    const keeper = new WearerHoldKeeper();
    keeper.onStatus(NO_CONTROLS, true, T0, T0);
    keeper.onStatus(PAUSED, true, T0 + 1000, T0 + 1010);
    expect(keeper.keep(stroke(0), T0 + 2000)).toBe(true);
    expect(keeper.keep(stroke(1), T0 + 2100)).toBe(true);
    // The page saw the pause happen: it knows when.
    expect(keeper.view(T0 + 2200)).toEqual({
      state: "held",
      hold: { reason: "paused", sinceMs: T0 + 1000, untilMs: null },
      held: 2,
    });
    keeper.onStatus(NO_CONTROLS, true, T0 + 5000, T0 + 5010);
    expect(keeper.view(T0 + 5010)).toEqual({
      state: "resumed",
      held: 2,
      ended: { hold: { reason: "paused", sinceMs: T0 + 1000, untilMs: null }, ranOut: false },
    });
    expect(keeper.take().map((s) => s.seq)).toEqual([0, 1]);
    expect(keeper.view(T0 + 5020)).toEqual({ state: "none" });
    expect(keeper.keep(stroke(2), T0 + 5030)).toBe(false);
  });

  it("does not claim a pause time it did not see (the first status is already paused)", () => {
    const keeper = new WearerHoldKeeper();
    keeper.onStatus(PAUSED, true, T0, T0 + 10);
    expect(keeper.hold(T0 + 20)).toEqual({ reason: "paused", sinceMs: null, untilMs: null });
  });

  it("keeps the last known choice through the sleeve's offline status (its last will has none)", () => {
    const keeper = new WearerHoldKeeper();
    keeper.onStatus(PAUSED, true, T0, T0);
    keeper.onStatus(NO_CONTROLS, false, null, T0 + 100);
    expect(keeper.keep(stroke(0), T0 + 200)).toBe(true);
  });

  it("lets go when do not disturb runs out, and says it ran out (not that the wearer resumed)", () => {
    const keeper = new WearerHoldKeeper();
    const dnd = { reason: "do_not_disturb", untilMs: T0 + 60_000 } as const;
    expect(keeper.onStatus({ ...NO_CONTROLS, do_not_disturb_until_ms: T0 + 60_000 }, true, T0, T0)).toEqual({
      before: null,
      after: dnd,
      ranOut: false,
    });
    expect(keeper.keep(stroke(0), T0 + 1000)).toBe(true);
    expect(keeper.tick(T0 + 30_000)).toBeNull(); // nothing changed
    expect(keeper.tick(T0 + 60_001)).toEqual({ before: dnd, after: null, ranOut: true });
    expect(keeper.view(T0 + 60_001)).toEqual({
      state: "resumed",
      held: 1,
      ended: { hold: dnd, ranOut: true },
    });
    // The sleeve's own status saying so a moment later changes nothing more.
    expect(keeper.onStatus(NO_CONTROLS, true, T0 + 60_020, T0 + 60_030)).toBeNull();
    expect(keeper.keep(stroke(1), T0 + 60_040)).toBe(false);
  });

  it("takes do not disturb as run out when the sleeve's clock reached its end before the page's", () => {
    const keeper = new WearerHoldKeeper();
    const until = T0 + 60_000;
    keeper.onStatus({ ...NO_CONTROLS, do_not_disturb_until_ms: until }, true, T0, T0);
    // The page's clock is 3 s behind: the sleeve ended it at its time, the page has not yet.
    expect(keeper.onStatus(NO_CONTROLS, true, until + 5, until - 3000)?.ranOut).toBe(true);
  });

  it("says the wearer ended do not disturb early (its status came well before the end)", () => {
    const keeper = new WearerHoldKeeper();
    const dnd = { reason: "do_not_disturb", untilMs: T0 + 60_000 } as const;
    keeper.onStatus({ ...NO_CONTROLS, do_not_disturb_until_ms: T0 + 60_000 }, true, T0, T0);
    expect(keeper.onStatus(NO_CONTROLS, true, T0 + 20_000, T0 + 20_010)).toEqual({
      before: dnd,
      after: null,
      ranOut: false,
    });
    expect(keeper.view(T0 + 20_010)).toEqual({
      state: "resumed",
      held: 0,
      ended: { hold: dnd, ranOut: false },
    });
  });

  it("still holds when the wearer resumes under do not disturb, and says so as a change", () => {
    const keeper = new WearerHoldKeeper();
    const both = { ...PAUSED, do_not_disturb_until_ms: T0 + 60_000 };
    keeper.onStatus(NO_CONTROLS, true, T0, T0);
    expect(keeper.onStatus(both, true, T0 + 10, T0 + 10)?.after).toEqual({
      reason: "paused",
      sinceMs: T0 + 10,
      untilMs: T0 + 60_000,
    });
    const change = keeper.onStatus({ ...both, paused: false, paused_by: null }, true, T0 + 20, T0 + 20);
    expect(change?.before?.reason).toBe("paused");
    expect(change?.after).toEqual({ reason: "do_not_disturb", untilMs: T0 + 60_000 });
    expect(keeper.keep(stroke(0), T0 + 30)).toBe(true);
    expect(keeper.view(T0 + 30).state).toBe("held");
  });

  it("resumed with nothing held: the notice goes with the next stroke sent", () => {
    const keeper = new WearerHoldKeeper();
    keeper.onStatus(PAUSED, true, T0, T0);
    keeper.onStatus(NO_CONTROLS, true, T0 + 1, T0 + 1);
    expect(keeper.view(T0 + 2)).toMatchObject({ state: "resumed", held: 0 });
    keeper.dismissResumed();
    expect(keeper.view(T0 + 3)).toEqual({ state: "none" });
  });

  it("gives the held strokes back for a new drawing, and forgets another sleeve's wearer", () => {
    const keeper = new WearerHoldKeeper();
    keeper.onStatus(PAUSED, true, T0, T0);
    keeper.keep(stroke(0), T0);
    expect(keeper.newDrawing()).toHaveLength(1);
    expect(keeper.heldCount).toBe(0);
    keeper.forgetSleeve();
    expect(keeper.keep(stroke(1), T0)).toBe(false);
  });
});

describe("WearerHoldKeeper.release", () => {
  it("lets go of the held strokes of a path taken back, keeping the rest in order", () => {
    const keeper = new WearerHoldKeeper();
    keeper.onStatus(PAUSED, true, T0, T0);
    for (const seq of [0, 1, 2, 3]) keeper.keep(stroke(seq), T0);
    expect(keeper.release((s) => (s.seq ?? 0) < 2).map((s) => s.seq)).toEqual([2, 3]);
    expect(keeper.take().map((s) => s.seq)).toEqual([0, 1]);
  });
});
