/**
 * What a new user saw on the drawing page, on real processes (`feelmysign up` with the simulated
 * sleeve, the page in Chromium): the felt timeline's caption after Undo counts the drawing as it
 * stands and never calls the sleeve's reports of the undone strokes missing; a loaded recording is
 * said not sent yet, not "0 played"; Play again is explained, and the card says a drawing played
 * again was played back to back, not "faster to catch up". Screenshots of the card and the
 * caption after each, in test-results/.
 */
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { RESULTS_DIR, type EventWatcher } from "./harness";
import {
  drawingArea,
  drawWithMouse,
  screenshot,
  SUMMARY,
  waitForData,
  waitForEveryStroke,
  type Area,
} from "./page";
import { Processes } from "./processes";

type Point = readonly [number, number];
const CAPTION = '[data-testid="timeline-caption"]';
const CARD = `section.card:has(${SUMMARY})`;
const FELT = `section:has(${CAPTION})`;

async function data(page: Page, selector: string, key: string): Promise<number> {
  return Number(await page.locator(selector).evaluate((el, k) => (el as HTMLElement).dataset[k] ?? "", key));
}

/** Screenshots of the page, and of the card and the felt timeline alone. */
async function shots(page: Page, name: string): Promise<string[]> {
  const full = await screenshot(page, name);
  const card = full.replace(/\.png$/, "-card.png");
  const felt = full.replace(/\.png$/, "-timeline.png");
  await page.locator(CARD).screenshot({ path: card });
  await page.locator(FELT).first().screenshot({ path: felt });
  console.log(`${name}: ${full}, ${card}, ${felt}`);
  return [full, card, felt];
}

describe("a new user's first drawings, served by feelmysign up with the simulated sleeve", () => {
  const processes = new Processes();
  let page: Page;
  let area: Area;
  let watcher: EventWatcher;
  const at = (fx: number, fy: number): Point => [area.left + area.width * fx, area.top + area.height * fy];

  beforeAll(async () => {
    const up = await processes.up("new-user");
    watcher = await processes.watch(up.credentials);
    page = await processes.onlinePage(up.url);
    area = await drawingArea(page);
  });

  afterAll(() => processes.stop());

  it("after Undo, the caption counts the drawing as it stands and never says the sleeve's reports are missing", async () => {
    await drawWithMouse(page, [at(0.1, 0.2), at(0.9, 0.2), at(0.1, 0.5)], { legMs: 500 });
    const first = await data(page, '[data-testid="timeline"]', "strokes");
    await drawWithMouse(page, [at(0.1, 0.8), at(0.9, 0.8), at(0.5, 0.5)], { legMs: 500 });
    const both = await waitForEveryStroke(page);
    const drawing = await page.evaluate(() => window.feelmysign?.drawingId ?? "");
    await watcher.waitFor("every played event", () => watcher.of(drawing, "played").length >= both.played);
    expect(both.played).toBe(both.sent);
    const undone = both.sent - first;
    expect(undone).toBeGreaterThan(0);
    await page.locator('[data-testid="undo-button"]').click();
    await waitForData(page, '[data-testid="timeline"]', "strokes", String(first));
    const caption = await page.locator(CAPTION).innerText();
    expect(caption).not.toContain("never came");
    expect(caption).toMatch(
      new RegExp(
        `^${first} strokes?, [\\d.]+ s, as the sleeve played them\\. ` +
          `Not counted: ${undone} strokes? taken back with Undo \\(${undone} played\\)\\.$`,
      ),
    );
    // The card counts every stroke the drawing sent, the undone ones too: all played.
    expect(await page.locator(SUMMARY).innerText()).toMatch(
      new RegExp(`^${both.sent} of ${both.sent} strokes played`),
    );
    await shots(page, "new-user-after-undo");
  });

  it("a loaded recording is said not sent yet, and Play again is explained: played back to back", async () => {
    const [download] = await Promise.all([
      page.waitForEvent("download"),
      page.locator('[data-testid="record-button"]').click(),
    ]);
    const file = join(RESULTS_DIR, "new-user-recording.json");
    await download.saveAs(file);
    await page.locator('[data-testid="new-button"]').click();
    await waitForData(page, '[data-testid="timeline"]', "strokes", "0");
    await page.locator('[data-testid="load-file"]').setInputFiles(file);
    const strokes = await data(page, '[data-testid="timeline"]', "strokes");
    expect(strokes).toBeGreaterThan(0);
    await waitForData(page, SUMMARY, "notSent", String(strokes));
    const loaded = await page.locator(SUMMARY).innerText();
    expect(loaded).toBe(`${strokes} strokes loaded, not sent yet: Play again sends them.`);
    expect(loaded).not.toMatch(/^0 of/);
    await shots(page, "new-user-loaded");

    // The sleeve idle first, so none is refused for starting too late after it was sent.
    await waitForData(page, '[data-testid="sleeve-preview"]', "lit", "0", 30_000);
    await page.locator('[data-testid="replay-button"]').click();
    const again = await waitForEveryStroke(page);
    expect(again.played).toBe(strokes);
    const summary = await page.locator(SUMMARY).innerText();
    expect(summary).toMatch(
      new RegExp(`^${strokes} of ${strokes} strokes played \\(back to back in [\\d.]+ m?s`),
    );
    expect(summary).not.toContain("catch up");
    await expect(page.locator('[data-testid="event-log"]').innerText()).resolves.toContain(
      `Played again: ${strokes} strokes sent all at once.`,
    );
    await shots(page, "new-user-played-again");
  });
});
