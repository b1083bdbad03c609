/**
 * The page on a phone-sized viewport with a touch screen: drawing with a
 * finger (real touch events through the DevTools protocol) sends strokes, and
 * the layout and the settings sheet fit the small screen.
 */
import type { CDPSession, Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { checkPrerequisites, FakeSleeve, launchBrowser, serveDist } from "./harness";
import {
  CANVAS,
  drawingArea,
  drawWithTouch,
  nextFrame,
  openAdvanced,
  screenshot,
  showActuators,
  waitForData,
  type Area,
} from "./page";
import { Processes } from "./processes";
import { expectStrokesFollow, strokeBounds } from "./strokes";

/** Labels cut short by their box ("Simpli…"): none may be, in the bars or the settings. */
async function truncatedLabels(page: Page): Promise<string[]> {
  return page.evaluate(() =>
    [
      ...document.querySelectorAll<HTMLElement>(
        ".topbar *, .toolbar *, .legend *, .sheet label, .sheet legend, .sheet .button",
      ),
    ]
      .filter((element) => element.offsetParent !== null && element.scrollWidth > element.clientWidth + 1)
      .map((element) => element.textContent ?? ""),
  );
}

/** The whole area on the first screen, at least `share` of its height: no scrolling to draw. */
function expectOnScreen(area: Area, screen: { width: number; height: number }, share: number): void {
  expect(area.height).toBeGreaterThan(screen.height * share);
  expect(area.left).toBeGreaterThanOrEqual(0);
  expect(area.top).toBeGreaterThanOrEqual(0);
  expect(area.left + area.width).toBeLessThanOrEqual(screen.width);
  expect(area.top + area.height).toBeLessThanOrEqual(screen.height);
}

describe("drawing with a finger on a phone", () => {
  const processes = new Processes();
  let sleeve: FakeSleeve;
  let page: Page;
  let cdp: CDPSession;

  beforeAll(async () => {
    const { broker, url } = await processes.brokerAndPage();
    sleeve = await FakeSleeve.connect(broker.credentials);
    processes.add(() => sleeve.close());
    await sleeve.publish("status", { online: true, layout: { rows: 3, columns: 4, spacing_cm: 3 } }, true);
    const context = await processes.browser({
      viewport: { width: 390, height: 844 },
      deviceScaleFactor: 3,
      hasTouch: true,
      isMobile: true,
    });
    page = await context.newPage();
    cdp = await context.newCDPSession(page);
    await page.goto(url);
    await waitForData(page, '[data-testid="sleeve-status"]', "state", "online");
  });

  afterAll(() => processes.stop());

  it("uses the screen: the area is turned to the phone's shape, whole, with labelled buttons", async () => {
    const area = await drawingArea(page);
    // A 3 x 4 sleeve is 3:2 across; on an upright phone it is shown turned, 2:3, to use the height.
    expect(area.turnDeg).toBe(90);
    expect(area.height / area.width).toBeCloseTo(1.5, 1);
    expectOnScreen(area, { width: 390, height: 844 }, 0.45);
    expect(await page.locator('[data-testid="legend-turned"]').isVisible()).toBe(true);
    expect(await page.evaluate(() => document.documentElement.scrollWidth)).toBeLessThanOrEqual(390);
    expect(await page.locator('[data-testid="broker-status"]').isVisible()).toBe(true);
    for (const id of ["new", "undo", "stop", "replay", "record", "load"]) {
      const label = await page.locator(`[data-testid="${id}-button"]`).innerText();
      expect(label.trim().length, `${id} button has a label`).toBeGreaterThan(2);
    }
    expect(await truncatedLabels(page)).toEqual([]);
  });

  it("sends an L drawn with touch as two strokes from the touch-down to the lift", async () => {
    const area = await drawingArea(page);
    const points = [
      [area.left + area.width * 0.15, area.top + area.height * 0.15],
      [area.left + area.width * 0.15, area.top + area.height * 0.85],
      [area.left + area.width * 0.85, area.top + area.height * 0.85],
    ] as const;
    await drawWithTouch(page, cdp, points, 4);
    await nextFrame(page);
    // Two legs; a long leg may be cut by the latency cap, so two strokes or more.
    const sent = Number(await page.locator('[data-testid="played-summary"]').getAttribute("data-sent"));
    expect(sent).toBeGreaterThanOrEqual(2);
    const strokes = await sleeve.waitForStrokes(sent);
    expectStrokesFollow(strokes, points, area, await strokeBounds(page, area), 4);
    await showActuators(
      page,
      sleeve,
      [
        [0, 0, 0, 0],
        [0.7, 0, 0, 0],
        [1, 0.5, 0, 0],
      ],
      10,
    );
    await screenshot(page, "phone");
  });

  it("on its side (844 x 390): upright, the toolbar beside it, the whole area on the first screen", async () => {
    await page.setViewportSize({ width: 844, height: 390 });
    await waitForData(page, CANVAS, "areaTurnDeg", "0");
    const area = await drawingArea(page);
    expect(area.width / area.height).toBeCloseTo(1.5, 1);
    expectOnScreen(area, { width: 844, height: 390 }, 0.5);
    expect(await page.locator('[data-testid="legend-turned"]').isVisible()).toBe(false);
    const stop = await page.locator('[data-testid="stop-button"]').boundingBox();
    expect(stop !== null && stop.y + stop.height <= 390, "Stop is on the first screen").toBe(true);
    expect(await truncatedLabels(page)).toEqual([]);
    await screenshot(page, "phone-landscape");
    await page.setViewportSize({ width: 390, height: 844 });
    await waitForData(page, CANVAS, "areaTurnDeg", "90");
  });

  it("on a small phone (320 x 640): turned and staying so, no label cut short, both chips on the screen", async () => {
    try {
      await page.setViewportSize({ width: 320, height: 640 });
      await waitForData(page, CANVAS, "areaTurnDeg", "90");
      // The turn changes the legend under the area, which must not change the turn back: watch it.
      const turns = await page.locator(CANVAS).evaluate(async (canvas) => {
        const seen: string[] = [];
        const watch = new MutationObserver(() => seen.push((canvas as HTMLElement).dataset["areaTurnDeg"]!));
        watch.observe(canvas, { attributeFilter: ["data-area-turn-deg"] });
        for (let i = 0; i < 30; i++) await new Promise((done) => requestAnimationFrame(done));
        watch.disconnect();
        return seen;
      });
      expect(turns.filter((turn) => turn !== "90")).toEqual([]);
      expectOnScreen(await drawingArea(page), { width: 320, height: 640 }, 0.4);
      expect(await truncatedLabels(page)).toEqual([]);
      expect(await page.evaluate(() => document.documentElement.scrollWidth)).toBeLessThanOrEqual(320);
      for (const chip of ["broker-status", "sleeve-status"]) {
        const box = await page.locator(`[data-testid="${chip}"]`).boundingBox();
        expect(box !== null && box.x >= 0 && box.x + box.width <= 320, `${chip} on the screen`).toBe(true);
      }
      await screenshot(page, "phone-small");
    } finally {
      // The phone upright again for what follows, whatever happened above.
      await page.setViewportSize({ width: 390, height: 844 });
    }
    await waitForData(page, CANVAS, "areaTurnDeg", "90");
  });

  it("opens the settings as a full-screen sheet that scrolls to its last field", async () => {
    await page.locator('[data-testid="settings-button"]').tap();
    const panel = page.locator('[data-testid="settings-panel"]');
    await panel.waitFor({ state: "visible" });
    const box = await panel.boundingBox();
    expect(box?.width).toBeCloseTo(390, 0);
    await screenshot(page, "phone-settings");
    await openAdvanced(page);
    expect(await truncatedLabels(page)).toEqual([]);
    const password = page.locator('[data-testid="setting-password"]');
    await password.scrollIntoViewIfNeeded();
    expect(await password.isVisible()).toBe(true);
    expect(await page.locator('[data-testid="settings-save"]').isVisible()).toBe(true);
    await page.locator("#settings-cancel").tap();
    await panel.waitFor({ state: "hidden" });
    expect(await page.locator(CANVAS).isVisible()).toBe(true);
  });
});

describe("a page served without /config.json (vite dev)", () => {
  it("says so, and lets the broker be entered in the settings", async () => {
    checkPrerequisites();
    const server = await serveDist(null);
    const browser = await launchBrowser({
      viewport: { width: 390, height: 844 },
      hasTouch: true,
      isMobile: true,
    });
    try {
      const page = await browser.context.newPage();
      await page.goto(server.url);
      await page.locator("#notice").waitFor({ state: "visible" });
      await expect(page.locator("#notice").innerText()).resolves.toContain(
        "No server config (/config.json: HTTP 404)",
      );
      await page.locator('[data-testid="settings-button"]').tap();
      await openAdvanced(page);
      const url = page.locator('[data-testid="setting-ws_url"]');
      expect(await url.isEnabled()).toBe(true);
      expect(await page.locator('[data-field="broker_custom"]').isHidden()).toBe(true);
      await url.fill("http://127.0.0.1:9001");
      await expect(page.locator("#setting-ws_url-error").innerText()).resolves.toContain("ws:// or wss://");
    } finally {
      await browser.close();
      await server.stop();
    }
  });
});
