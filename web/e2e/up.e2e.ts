/**
 * The whole chain as a person gets it from `make up`: `feelmysign up` (broker,
 * simulated sleeve, this page served with its /config.json), a square drawn
 * with the mouse, the sleeve playing its four strokes, the preview lighting up.
 * Skipped, saying why, on a checkout whose CLI has no `up` yet.
 */
import { spawnSync } from "node:child_process";
import { readFileSync, rmSync } from "node:fs";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import {
  checkPrerequisites,
  FakeSleeve,
  FEELMYSIGN,
  launchBrowser,
  startUp,
  stopUp,
  tempDir,
  type Credentials,
} from "./harness";
import { drawingArea, drawWithMouse, nextFrame, screenshot, waitForData } from "./page";
import { expectStrokesFollow, strokeBounds } from "./strokes";

const hasUp = spawnSync(FEELMYSIGN, ["up", "--help"], { stdio: "ignore" }).status === 0;

describe.skipIf(!hasUp)("served by feelmysign up, with the simulated sleeve", () => {
  const cleanups: (() => Promise<void>)[] = [];
  let page: Page;
  let sleeve: FakeSleeve;

  beforeAll(async () => {
    checkPrerequisites();
    const stateDir = tempDir("up");
    cleanups.push(async () => rmSync(stateDir, { recursive: true, force: true }));
    const up = await startUp(stateDir);
    cleanups.push(() => stopUp(up.child));
    // A second login of the sleeve account, listening only: what the simulated sleeve receives.
    const credentials = JSON.parse(readFileSync(join(stateDir, "credentials.json"), "utf8")) as Credentials;
    sleeve = await FakeSleeve.connect(credentials);
    cleanups.push(() => sleeve.close());
    const browser = await launchBrowser({ viewport: { width: 1280, height: 800 } });
    cleanups.push(browser.close);
    page = await browser.context.newPage();
    await page.goto(up.url);
  });

  afterAll(async () => {
    for (const cleanup of cleanups.reverse()) await cleanup();
  });

  it("connects with nothing typed and sees the sleeve online", async () => {
    await waitForData(page, '[data-testid="broker-status"]', "state", "connected");
    await waitForData(page, '[data-testid="sleeve-status"]', "state", "online");
  });

  it("plays a square drawn with the mouse: strokes along it, cut at its corners, the preview lights up", async () => {
    const area = await drawingArea(page);
    const side = area.height * 0.6;
    const left = area.left + (area.width - side) / 2;
    const top = area.top + (area.height - side) / 2;
    const corners = [
      [left, top],
      [left + side, top],
      [left + side, top + side],
      [left, top + side],
    ] as const;
    await drawWithMouse(page, [...corners, corners[0]]);
    await nextFrame(page);
    // Four sides; a long side may be cut by the latency cap, so four strokes or more.
    const sent = Number(await page.locator('[data-testid="played-summary"]').getAttribute("data-sent"));
    expect(sent).toBeGreaterThanOrEqual(4);
    const strokes = await sleeve.waitForStrokes(sent);
    expectStrokesFollow(strokes, [...corners, corners[0]], area, await strokeBounds(page, area));
    await page.waitForFunction(
      () =>
        Number((document.querySelector('[data-testid="sleeve-preview"]') as HTMLElement).dataset["lit"]) > 0,
      undefined,
      { timeout: 15_000 },
    );
    await screenshot(page, "up-playing");
    await waitForData(page, '[data-testid="played-summary"]', "played", String(sent), 30_000);
  });
});
