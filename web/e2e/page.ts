/** Helpers that drive the page as a person would: find the drawing area, draw, look at the status. */
import { mkdirSync } from "node:fs";
import { join } from "node:path";
import type { CDPSession, Page } from "playwright-core";
import { CanvasMapping } from "../src/simplify/mapping";
import { RESULTS_DIR, type FakeSleeve } from "./harness";

export interface Area {
  /** The drawing area's top-left corner in viewport CSS pixels. */
  left: number;
  top: number;
  width: number;
  height: number;
  /**
   * 90 when the page shows the sleeve turned a quarter clockwise (its top edge on the
   * right, as on an upright phone): down the screen is then along the sleeve's columns.
   */
  turnDeg: 0 | 90;
}

export const CANVAS = '[data-testid="drawing-canvas"]';

/** The drawing area (inside the canvas's margin), read from the canvas the page laid out. */
export async function drawingArea(page: Page): Promise<Area> {
  const canvas = page.locator(CANVAS);
  const box = await canvas.boundingBox();
  if (box === null) throw new Error("the drawing canvas is not visible");
  const data = await canvas.evaluate((element) => ({ ...(element as HTMLElement).dataset }));
  return {
    left: box.x + Number(data["areaLeftPx"]),
    top: box.y + Number(data["areaTopPx"]),
    width: Number(data["areaWidthPx"]),
    height: Number(data["areaHeightPx"]),
    turnDeg: data["areaTurnDeg"] === "90" ? 90 : 0,
  };
}

/** Grid units of a viewport point, as the page's simplifier maps it (3 x 4 sleeve unless told). */
export function toGrid(
  area: Area,
  x: number,
  y: number,
  grid = { rows: 3, columns: 4 },
): readonly [number, number] {
  const u = x - area.left;
  const v = y - area.top;
  // Turned, the sleeve's canvas is the screen's area a quarter back: its x runs down, its y leftwards.
  const turned = area.turnDeg === 90;
  const mapping = new CanvasMapping({
    width_px: turned ? area.height : area.width,
    height_px: turned ? area.width : area.height,
    ...grid,
    stretch: false,
  });
  return turned ? mapping.toGrid(v, area.width - u) : mapping.toGrid(u, v);
}

/** Waits for the page's next animation frame: one pointer step per frame, as a hand moves. */
export async function nextFrame(page: Page): Promise<void> {
  await page.evaluate(() => new Promise<void>((done) => requestAnimationFrame(() => done())));
}

/** Points every `stepPx` along the polyline, the first point excluded. */
export function walk(points: readonly (readonly [number, number])[], stepPx: number): [number, number][] {
  const out: [number, number][] = [];
  for (let i = 1; i < points.length; i++) {
    const [ax, ay] = points[i - 1]!;
    const [bx, by] = points[i]!;
    const steps = Math.max(1, Math.round(Math.hypot(bx - ax, by - ay) / stepPx));
    for (let k = 1; k <= steps; k++) out.push([ax + ((bx - ax) * k) / steps, ay + ((by - ay) * k) / steps]);
  }
  return out;
}

/**
 * Mouse: press at the first point, move along the polyline one step per frame, release.
 * With `legMs`, each leg (from one point to the next) takes that long by the clock, however
 * slowly a loaded machine gives frames: each frame's step goes where the leg is at that time
 * (fewer, longer steps on a slow machine), so a stroke lasts as long as its leg was meant to.
 */
export async function drawWithMouse(
  page: Page,
  points: readonly (readonly [number, number])[],
  options: { stepPx?: number; legMs?: number; beforeRelease?: () => Promise<void> } = {},
): Promise<void> {
  const [x0, y0] = points[0]!;
  await page.mouse.move(x0, y0);
  await page.mouse.down();
  await nextFrame(page);
  if (options.legMs === undefined) {
    for (const [x, y] of walk(points, options.stepPx ?? 5)) {
      await page.mouse.move(x, y);
      await nextFrame(page);
    }
  } else {
    const legMs = options.legMs;
    await moveByClock(page, points, () => legMs);
  }
  await options.beforeRelease?.();
  await page.mouse.up();
}

/**
 * Moves the mouse along the polyline from its first point, each leg taking `legMs(from, to)`
 * by the clock: each frame's step goes where the leg is at that time, so a loaded machine that
 * gives frames slowly gets fewer, longer steps, and a path takes as long as on a quiet one.
 */
export async function moveByClock(
  page: Page,
  points: readonly (readonly [number, number])[],
  legMs: (from: readonly [number, number], to: readonly [number, number]) => number,
  move: (x: number, y: number) => Promise<unknown> = (x, y) => page.mouse.move(x, y),
): Promise<void> {
  for (let i = 1; i < points.length; i++) {
    const [ax, ay] = points[i - 1]!;
    const [bx, by] = points[i]!;
    const durationMs = legMs([ax, ay], [bx, by]);
    const startMs = performance.now();
    for (let done = 0; done < 1;) {
      done = Math.min(1, (performance.now() - startMs) / durationMs);
      await move(ax + (bx - ax) * done, ay + (by - ay) * done);
      await nextFrame(page);
    }
  }
}

/**
 * Touch through the DevTools protocol: a real touchstart/touchmove/touchend sequence, a move a
 * frame, `step` px apart, or with `{ legMs }` each leg taking that long by the clock (as
 * drawWithMouse's legMs).
 */
export async function drawWithTouch(
  page: Page,
  cdp: CDPSession,
  points: readonly (readonly [number, number])[],
  step: number | { legMs: number } = 5,
): Promise<void> {
  const [x0, y0] = points[0]!;
  const touch = (x: number, y: number) =>
    cdp.send("Input.dispatchTouchEvent", { type: "touchMove", touchPoints: [{ x, y, id: 1 }] });
  await cdp.send("Input.dispatchTouchEvent", { type: "touchStart", touchPoints: [{ x: x0, y: y0, id: 1 }] });
  await nextFrame(page);
  if (typeof step === "number") {
    for (const [x, y] of walk(points, step)) {
      await touch(x, y);
      await nextFrame(page);
    }
  } else {
    await moveByClock(page, points, () => step.legMs, touch);
  }
  await cdp.send("Input.dispatchTouchEvent", { type: "touchEnd", touchPoints: [] });
}

export async function screenshot(page: Page, name: string): Promise<string> {
  mkdirSync(RESULTS_DIR, { recursive: true });
  // A sheet sliding in would be caught half transparent: wait for running animations to end.
  // One cancelled meanwhile (the page replaced it) rejects its `finished` with an AbortError:
  // it has ended too.
  await page.evaluate(() =>
    Promise.all(
      document
        .getAnimations()
        .filter((animation) => animation.effect?.getComputedTiming().iterations !== Infinity)
        .map((animation) => animation.finished.catch(() => animation)),
    ),
  );
  const path = join(RESULTS_DIR, `${name}.png`);
  await page.screenshot({ path });
  return path;
}

/** Waits until `selector` has data-`key` equal to `value`, or fails saying what it had. */
export async function waitForData(
  page: Page,
  selector: string,
  key: string,
  value: string,
  timeoutMs = 30_000,
): Promise<void> {
  try {
    await page.waitForFunction(
      ({ selector, key, value }) =>
        (document.querySelector(selector) as HTMLElement | null)?.dataset[key] === value,
      { selector, key, value },
      { timeout: timeoutMs },
    );
  } catch {
    const actual = await page.evaluate(
      ({ selector, key }) => (document.querySelector(selector) as HTMLElement | null)?.dataset[key],
      { selector, key },
    );
    throw new Error(`${selector} data-${key}: expected ${value}, still ${actual} after ${timeoutMs} ms`);
  }
}

/**
 * `sleeve` publishes an actuator frame (its telemetry) of `intensities`, one array per row of
 * the grid; resolves once the page's preview lights as many actuators as are on.
 */
export async function showActuators(
  page: Page,
  sleeve: FakeSleeve,
  intensities: readonly (readonly number[])[],
  tMs = 0,
): Promise<void> {
  const [rows, columns] = [intensities.length, intensities[0]?.length ?? 0];
  await sleeve.publish("actuators", { t_ms: tMs, rows, columns, intensities });
  const lit = intensities.flat().filter((intensity) => intensity > 0).length;
  await waitForData(page, '[data-testid="sleeve-preview"]', "lit", String(lit));
}

/** The "Sleeve says" card's summary line, whose data-* attributes hold the drawing's counts. */
export const SUMMARY = '[data-testid="played-summary"]';

/** What became of a stroke, on the card: every one sent has one of these once answered. */
const ANSWERED = ["played", "cut", "cancelled", "refused", "dropped"] as const;
type Answered = (typeof ANSWERED)[number];

/** The card's counts named by `keys` (its summary's data-* attributes), as numbers. */
export async function cardCounts<K extends string>(
  page: Page,
  keys: readonly K[],
): Promise<Record<K, number>> {
  const data = await page.locator(SUMMARY).evaluate((element) => ({ ...(element as HTMLElement).dataset }));
  return Object.fromEntries(keys.map((key) => [key, Number(data[key])])) as Record<K, number>;
}

/**
 * Waits until every stroke the card counts sent has a fate there (or was never sent); returns
 * the counts named by `keys` then, with "sent" and the fates.
 */
export async function waitForEveryStroke<K extends string = never>(
  page: Page,
  keys: readonly K[] = [],
  timeoutMs = 60_000,
): Promise<Record<K | Answered | "sent", number>> {
  const deadline = Date.now() + timeoutMs;
  for (;;) {
    const counts = await cardCounts(page, [...new Set([...keys, "sent" as const, ...ANSWERED])]);
    const answered = ANSWERED.reduce((sum, fate) => sum + counts[fate], 0);
    if (counts.sent > 0 && answered === counts.sent) return counts;
    if (Date.now() > deadline) throw new Error(`not every stroke answered: ${JSON.stringify(counts)}`);
    await new Promise((wake) => setTimeout(wake, 100));
  }
}

/** Waits until the sleeve has played at least one stroke of the page's current drawing. */
export async function waitForPlayed(page: Page, timeoutMs = 30_000): Promise<void> {
  await page.waitForFunction(
    () =>
      Number((document.querySelector('[data-testid="played-summary"]') as HTMLElement).dataset["played"]) > 0,
    undefined,
    { timeout: timeoutMs },
  );
}

/** Opens the settings' Advanced level (whatever state it was left in). */
export async function openAdvanced(page: Page): Promise<void> {
  await page.locator('[data-testid="settings-advanced"]').evaluate((details) => {
    (details as HTMLDetailsElement).open = true;
  });
}

/** Settings → Advanced → Least squares on or off (the window simplifier's core), saved. */
export async function setLeastSquares(page: Page, on: boolean): Promise<void> {
  await page.locator('[data-testid="settings-button"]').click();
  await openAdvanced(page);
  await page.locator('[data-testid="setting-least_squares"]').setChecked(on);
  await page.locator('[data-testid="settings-save"]').click();
  await page.locator('[data-testid="settings-panel"]').waitFor({ state: "hidden" });
}

/** Settings → Advanced → Rest (ms a pen rests before the stroke so far ends; 0 = never), saved. */
export async function setRest(page: Page, ms: string): Promise<void> {
  await page.locator('[data-testid="settings-button"]').click();
  await openAdvanced(page);
  await page.locator('[data-testid="setting-rest_ms"]').fill(ms);
  await page.locator('[data-testid="settings-save"]').click();
  await page.locator('[data-testid="settings-panel"]').waitFor({ state: "hidden" });
}

/** Settings → Advanced → Longest stroke (ms of drawing; 0 = no limit), saved. */
export async function setLongestStroke(page: Page, ms: string): Promise<void> {
  await page.locator('[data-testid="settings-button"]').click();
  await openAdvanced(page);
  await page.locator('[data-testid="setting-max_stroke_ms"]').fill(ms);
  await page.locator('[data-testid="settings-save"]').click();
  await page.locator('[data-testid="settings-panel"]').waitFor({ state: "hidden" });
}
