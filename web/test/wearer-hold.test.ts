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
      hold: { reason: "paused", sinceMs: T0 + 1000 },
      held: 2,
    });
    keeper.onStatus(NO_CONTROLS, true, T0 + 5000, T0 + 5010);
    expect(keeper.view(T0 + 5010)).toEqual({ state: "resumed", held: 2 });
    expect(keeper.take().map((s) => s.seq)).toEqual([0, 1]);
    expect(keeper.view(T0 + 5020)).toEqual({ state: "none" });
    expect(keeper.keep(stroke(2), T0 + 5030)).toBe(false);
  });

  it("does not claim a pause time it did not see (the first status is already paused)", () => {
    const keeper = new WearerHoldKeeper();
    keeper.onStatus(PAUSED, true, T0, T0 + 10);
    expect(keeper.hold(T0 + 20)).toEqual({ reason: "paused", sinceMs: null });
  });

  it("keeps the last known choice through the sleeve's offline status (its last will has none)", () => {
    const keeper = new WearerHoldKeeper();
    keeper.onStatus(PAUSED, true, T0, T0);
    keeper.onStatus(NO_CONTROLS, false, null, T0 + 100);
    expect(keeper.keep(stroke(0), T0 + 200)).toBe(true);
  });

  it("lets go when do not disturb runs out, and says the wearer is back", () => {
    const keeper = new WearerHoldKeeper();
    keeper.onStatus({ ...NO_CONTROLS, do_not_disturb_until_ms: T0 + 60_000 }, true, T0, T0);
    expect(keeper.keep(stroke(0), T0 + 1000)).toBe(true);
    keeper.tick(T0 + 60_001);
    expect(keeper.view(T0 + 60_001)).toEqual({ state: "resumed", held: 1 });
    expect(keeper.keep(stroke(1), T0 + 60_002)).toBe(false);
  });

  it("resumed with nothing held: the notice goes with the next stroke sent", () => {
    const keeper = new WearerHoldKeeper();
    keeper.onStatus(PAUSED, true, T0, T0);
    keeper.onStatus(NO_CONTROLS, true, T0 + 1, T0 + 1);
    expect(keeper.view(T0 + 2)).toEqual({ state: "resumed", held: 0 });
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
