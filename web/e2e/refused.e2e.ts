/**
 * A stroke the sleeve itself refuses, on real processes: `feelmysign up` with the simulated
 * sleeve, on a layout whose longest stroke is short, and a drawing with one leg drawn too
 * slowly for it. The sleeve refuses that stroke (`duration_too_long`) and plays the rest: the
 * page marks it refused on the canvas, counts it, and leaves it out of the felt timeline.
 */
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { REPO_DIR, type EventWatcher } from "./harness";
import {
  drawingArea,
  drawWithMouse,
  screenshot,
  setLongestStroke,
  setRest,
  waitForData,
  type Area,
} from "./page";
import { Processes } from "./processes";

type Point = readonly [number, number];
/** The sleeve's longest stroke on this layout, and how long the slow leg takes to draw: ms. */
const MAX_STROKE_DURATION_MS = 1500;
const SLOW_LEG_MS = 3000;
const FAST_LEG_MS = 500;
const SUMMARY = '[data-testid="played-summary"]';
const TIMELINE = '[data-testid="timeline"]';

describe("a stroke the sleeve refuses", () => {
  const processes = new Processes();
  let page: Page;
  let area: Area;
  let watcher: EventWatcher;
  const at = (fx: number, fy: number): Point => [area.left + area.width * fx, area.top + area.height * fy];

  beforeAll(async () => {
    const layout = join(processes.dir("refused-layout"), "short-strokes.toml");
    const paper = readFileSync(join(REPO_DIR, "deploy", "layouts", "paper-sleeve.toml"), "utf8");
    const short = paper.replace(
      /^max_stroke_duration_ms = \d+/m,
      `max_stroke_duration_ms = ${MAX_STROKE_DURATION_MS}`,
    );
    expect(short).not.toBe(paper);
    writeFileSync(layout, short);
    const up = await processes.up("refused", { args: ["--layout", layout] });
    watcher = await processes.watch(up.credentials);
    page = await processes.onlinePage(up.url);
    area = await drawingArea(page);
  });

  afterAll(() => processes.stop());

  it("marks it refused, counts it, and leaves it out of the felt timeline", async () => {
    // One stroke a leg (no cap on a stroke's length): each lasts as long as its leg took to draw.
    // No rest rule either: on a loaded machine the mouse's events can stall for longer than
    // rest_ms, and the page's samples of the still pointer would end the slow leg's stroke there.
    await setLongestStroke(page, "0");
    await setRest(page, "0");
    await drawWithMouse(page, [at(0.1, 0.8), at(0.3, 0.2), at(0.5, 0.8), at(0.7, 0.2)], {
      legMs: FAST_LEG_MS,
    });
    await drawWithMouse(page, [at(0.75, 0.8), at(0.95, 0.8)], { legMs: SLOW_LEG_MS });
    const drawing = await page.evaluate(() => window.feelmysign?.drawingId ?? "");
    const sent = Number(await page.locator(SUMMARY).getAttribute("data-sent"));
    expect(sent).toBeGreaterThanOrEqual(4);
    await watcher.waitFor(
      "every stroke answered",
      () => watcher.of(drawing).filter((e) => e["type"] !== "cancelled").length >= sent,
      60_000,
    );
    // The slow leg's stroke at least (a loaded machine may draw a fast leg slowly too).
    const refused = watcher.of(drawing, "rejected");
    expect(refused.length).toBeGreaterThanOrEqual(1);
    expect(new Set(refused.map((e) => e["reason"]))).toEqual(new Set(["duration_too_long"]));
    await waitForData(page, SUMMARY, "refused", String(refused.length));
    // The refused strokes are not on the timeline: the others are.
    await waitForData(page, TIMELINE, "strokes", String(sent - refused.length));
    const log = await page.locator('[data-testid="event-log"]').innerText();
    for (const event of refused) expect(log).toContain(`Stroke ${(event["seq"] as number) + 1} refused`);
    await screenshot(page, "refused-by-the-sleeve");
  });
});
