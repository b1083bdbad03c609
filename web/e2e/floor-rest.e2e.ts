/**
 * A pen that rests mid-path, on real processes (`feelmysign up` with the simulated sleeve, the page
 * in Chromium, its window simplifier with the chord core): a piece briefer than the sleeve's floor, held to merge when the pen stops, is sent
 * at the rest lent the time it needs from it (window.ts `Merger.rest`). It must last the floor to
 * the last bit: `start + floor - start` rounds below the floor for about half the start times of a
 * page open 5 to 20 s (73.70099999999911 ms from 15000.1 ms), and the sleeve slowed such a stroke
 * to 73.701 ms and reported it `adjusted`: a mid-path stroke the sleeve had to slow. No stroke is
 * sent briefer than the floor (one drawn briefer that cannot merge is sent to last the floor).
 */
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import type { EventWatcher } from "./harness";
import { drawingArea, moveByClock, nextFrame, setLeastSquares, type Area } from "./page";
import { Processes } from "./processes";

type Point = readonly [number, number];
/** The ERM sleeve's floor (its status): the shortest stroke it plays without slowing it. */
const FLOOR_MS = 73.701;
/** Brief moves, each then held still well past the simplifier's rest_ms (100 ms). */
const MOVE_MS = 40;
const REST_MS = 300;
const RESTS = 12;

describe("a pen resting mid-path", () => {
  const processes = new Processes();
  let page: Page;
  let area: Area;
  let watcher: EventWatcher;
  const at = (fx: number, fy: number): Point => [area.left + area.width * fx, area.top + area.height * fy];

  beforeAll(async () => {
    const up = await processes.up("floor-rest");
    watcher = await processes.watch(up.credentials);
    page = await processes.onlinePage(up.url);
    // The chord core's merger holds a brief piece until the rest (the least squares send theirs
    // as they are, lasting the floor: their own tests).
    await setLeastSquares(page, false);
    area = await drawingArea(page);
  });

  afterAll(() => processes.stop());

  /** The pen held still at `point` for `ms`, still reporting (a tenth of a pixel's jitter). */
  async function rest(point: Point, ms: number): Promise<void> {
    const startMs = performance.now();
    for (let i = 0; performance.now() - startMs < ms; i++) {
      await page.mouse.move(point[0] + (i % 2) * 0.1, point[1]);
      await nextFrame(page);
    }
  }

  it("sends no stroke the sleeve must slow", { timeout: 120_000 }, async () => {
    // Page times where the plain sum rounds down for about half the start times.
    await page.waitForFunction(() => performance.now() > 6000);
    const corners: Point[] = [];
    for (let i = 0; i <= RESTS; i++) corners.push(at(0.1 + (0.8 * i) / RESTS, i % 2 === 0 ? 0.45 : 0.55));
    await page.mouse.move(...corners[0]!);
    await page.mouse.down();
    await nextFrame(page);
    for (let i = 1; i < corners.length; i++) {
      await moveByClock(page, [corners[i - 1]!, corners[i]!], () => MOVE_MS);
      await rest(corners[i]!, REST_MS);
    }
    await page.mouse.up();
    const drawing = await page.evaluate(() => window.feelmysign?.drawingId ?? "");
    const sent = Number(await page.locator('[data-testid="played-summary"]').getAttribute("data-sent"));
    await watcher.waitFor("every stroke answered", () => watcher.of(drawing).length >= sent, 60_000);
    const answered = watcher.of(drawing);
    // The rests lent pieces the floor: strokes of the floor to the last bit, as sent.
    const lent = answered.filter((e) => {
      const asked = (e["type"] === "adjusted" ? e["requested_duration_ms"] : e["duration_ms"]) as number;
      return Math.abs(asked - FLOOR_MS) < 1e-6;
    });
    expect(lent.length, JSON.stringify(answered)).toBeGreaterThanOrEqual(RESTS / 2);
    // None of them slowed, nor any other.
    const slowed = answered
      .filter((e) => e["type"] === "adjusted")
      .map((e) => `seq ${String(e["seq"])}: ${String(e["requested_duration_ms"])} ms`);
    expect(slowed).toEqual([]);
    for (const event of lent) expect(event["type"]).toBe("played");
  });
});
