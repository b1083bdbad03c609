/**
 * The sleeve's floor, on real processes: `feelmysign up --wearer FILE` advertises a wearer's
 * measured limits in its status; the page raises its simplifier's minimums to them, says so
 * in its settings panel, and sends no stroke the sleeve must slow or the wearer cannot feel.
 */
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import type { EventWatcher } from "./harness";
import { drawingArea, drawWithMouse, openAdvanced, setLongestStroke, type Area } from "./page";
import { Processes } from "./processes";

type Point = readonly [number, number];
/** The wearer's measured limits: above the sleeve's own (73.7 ms, 0.05 grid units). */
const WEARER_MIN_DURATION_MS = 150;
const WEARER_MIN_LENGTH = 0.3;
const FAST_LEG_MS = 80;
const SLOW_LEG_MS = 600;

describe("the sleeve's floor", () => {
  const processes = new Processes();
  let page: Page;
  let area: Area;
  let watcher: EventWatcher;
  const at = (fx: number, fy: number): Point => [area.left + area.width * fx, area.top + area.height * fy];

  beforeAll(async () => {
    const wearer = join(processes.dir("floor-wearer"), "wearer.json");
    writeFileSync(
      wearer,
      JSON.stringify({
        wearer: "W1",
        min_length: WEARER_MIN_LENGTH,
        min_duration_ms: WEARER_MIN_DURATION_MS,
      }),
    );
    const up = await processes.up("floor", { args: ["--wearer", wearer] });
    watcher = await processes.watch(up.credentials);
    page = await processes.onlinePage(up.url);
    area = await drawingArea(page);
  });

  afterAll(() => processes.stop());

  it("says the floor in the settings panel", async () => {
    await page.locator('[data-testid="settings-button"]').click();
    await openAdvanced(page);
    await expect(page.locator('[data-testid="floor-note"]').innerText()).resolves.toBe(
      `At least ${WEARER_MIN_DURATION_MS} ms and ${WEARER_MIN_LENGTH} grid units per stroke: ` +
        "the sleeve's floor with wearer W1's limits; min duration and min length raised to it.",
    );
    await page.locator("#settings-cancel").click();
    await page.locator('[data-testid="settings-panel"]').waitFor({ state: "hidden" });
  });

  it("sends no stroke briefer than the floor", async () => {
    // One stroke a leg (no latency cap): fast legs alone would be briefer than the floor.
    await setLongestStroke(page, "0");
    await drawWithMouse(page, [at(0.1, 0.8), at(0.2, 0.3), at(0.3, 0.8), at(0.4, 0.3)], {
      legMs: FAST_LEG_MS,
    });
    await drawWithMouse(page, [at(0.5, 0.8), at(0.7, 0.2), at(0.9, 0.8)], { legMs: SLOW_LEG_MS });
    const drawing = await page.evaluate(() => window.feelmysign?.drawingId ?? "");
    const sent = Number(await page.locator('[data-testid="played-summary"]').getAttribute("data-sent"));
    expect(sent).toBeGreaterThanOrEqual(1);
    await watcher.waitFor("every stroke answered", () => watcher.of(drawing).length >= sent, 60_000);
    const answered = watcher.of(drawing);
    // None needed slowing, and every one lasts at least the wearer's shortest felt duration.
    expect(answered.map((e) => e["type"])).toEqual(answered.map(() => "played"));
    for (const event of answered) expect(event["duration_ms"]).toBeGreaterThanOrEqual(WEARER_MIN_DURATION_MS);
  });
});
