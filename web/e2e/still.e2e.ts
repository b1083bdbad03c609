/**
 * A pen that stops mid-path and sends no event while it stays (a mouse or a finger held still),
 * on real processes (`feelmysign up` with the simulated sleeve, the page in Chromium). The page
 * samples the still pointer where it is (`ui/pointer.ts`, `STILL_SAMPLE_MS`), so the simplifier's
 * rest rule sees the stop: the stroke before it is sent at once, and the stop is not played as a
 * stroke as long as itself.
 */
import { execFileSync } from "node:child_process";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { FEELMYSIGN, RESULTS_DIR } from "./harness";
import { drawingArea, moveByClock, waitForPlayed, type Area } from "./page";
import { Processes } from "./processes";

type Point = readonly [number, number];
const STOP_MS = 600;

describe("a pen held still mid-path, no event sent", () => {
  const processes = new Processes();
  let page: Page;
  let area: Area;
  const at = (fx: number, fy: number): Point => [area.left + area.width * fx, area.top + area.height * fy];

  beforeAll(async () => {
    const up = await processes.up("still");
    page = await processes.onlinePage(up.url);
    area = await drawingArea(page);
  });

  afterAll(() => processes.stop());

  it("is a rest: sampled where it stays, not played", { timeout: 120_000 }, async () => {
    const [a, b, c] = [at(0.15, 0.3), at(0.5, 0.5), at(0.85, 0.3)];
    await page.mouse.move(...a);
    await page.mouse.down();
    await moveByClock(page, [a, b], () => 500);
    const stoppedMs = await page.evaluate(() => performance.now());
    // Held still: no mouse event at all for STOP_MS.
    await new Promise((resolve) => setTimeout(resolve, STOP_MS));
    const movedMs = await page.evaluate(() => performance.now());
    await moveByClock(page, [b, c], () => 500);
    await page.mouse.up();
    await waitForPlayed(page);
    const [download] = await Promise.all([
      page.waitForEvent("download"),
      page.locator('[data-testid="record-button"]').click(),
    ]);
    const file = join(RESULTS_DIR, "still-recording.json");
    await download.saveAs(file);
    const recording = JSON.parse(readFileSync(file, "utf8")) as {
      paths: { t_ms: number; x: number; y: number }[][];
      strokes: { start_ms: number; end_ms: number }[];
    };
    const samples = recording.paths[0]!;
    // The stop was sampled: samples at one place, no gap of more than a few frames among them.
    const gaps = samples.slice(1).map((s, i) => s.t_ms - samples[i]!.t_ms);
    expect(Math.max(...gaps), JSON.stringify(gaps)).toBeLessThan(STOP_MS / 4);
    // ... and never back in time (an event handled after a still sample may be older than it).
    expect(Math.min(...gaps), JSON.stringify(gaps)).toBeGreaterThanOrEqual(0);
    // The reference reads the recording (it refuses samples out of order) and sends the same.
    const replay = JSON.parse(
      execFileSync(FEELMYSIGN, ["simplify", file, "--json"], { encoding: "utf8" }),
    ) as {
      strokes: unknown[];
    };
    expect(replay.strokes).toHaveLength(recording.strokes.length);
    const stillSamples = samples.filter(
      (s, i) => i > 0 && s.x === samples[i - 1]!.x && s.y === samples[i - 1]!.y,
    );
    expect(stillSamples.length).toBeGreaterThanOrEqual(Math.floor(STOP_MS / 64));
    // No stroke sent spans the stop: each one lasts less than it (the cap, 200 ms, holds).
    const longest = Math.max(...recording.strokes.map((s) => s.end_ms - s.start_ms));
    expect(longest, JSON.stringify(recording.strokes)).toBeLessThan(movedMs - stoppedMs - 100);
  });
});
