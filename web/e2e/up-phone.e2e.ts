/**
 * A phone against `feelmysign up`: its broker killed (SIGKILL, by its process
 * id) and started again by `up`, while the page goes offline and back: the
 * drawing area never moves, however the status chips change, and the
 * simulated sleeve plays what is drawn afterwards.
 */
import { spawnSync, type ChildProcess } from "node:child_process";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import {
  CANVAS,
  drawingArea,
  drawWithTouch,
  nextFrame,
  screenshot,
  waitForData,
  waitForPlayed,
} from "./page";
import { Processes } from "./processes";

const BROKER = '[data-testid="broker-status"]';

/** The Mosquitto `up` runs, by parent process id: the one this test may kill. */
function mosquittoOf(up: ChildProcess): number {
  const found = spawnSync("pgrep", ["-P", String(up.pid), "mosquitto"], { encoding: "utf8" });
  const pids = found.stdout.split(/\s+/).filter(Boolean).map(Number);
  if (pids.length !== 1) throw new Error(`expected one mosquitto under up (pid ${up.pid}), found ${pids}`);
  return pids[0]!;
}

describe("a phone against feelmysign up, its broker killed and started again", () => {
  const processes = new Processes();
  let page: Page;
  let up: ChildProcess;

  beforeAll(async () => {
    const started = await processes.up("up-phone");
    up = started.child;
    page = await processes.page(started.url, {
      viewport: { width: 390, height: 844 },
      deviceScaleFactor: 2,
      hasTouch: true,
      isMobile: true,
    });
    await waitForData(page, '[data-testid="sleeve-status"]', "state", "online", 30_000);
  });

  afterAll(() => processes.stop());

  it("keeps the drawing area still while offline and back, then plays what is drawn", async () => {
    const before = await page.locator(CANVAS).boundingBox();
    const states = new Set<string>();
    process.kill(mosquittoOf(up), "SIGKILL");
    // Until the page is connected again and the sleeve online: the area never moves meanwhile.
    const deadline = Date.now() + 60_000;
    let shot = false;
    for (;;) {
      if (Date.now() > deadline) throw new Error(`not back within 60 s; broker states seen: ${[...states]}`);
      expect(await page.locator(CANVAS).boundingBox()).toEqual(before);
      const broker = (await page.locator(BROKER).getAttribute("data-state")) ?? "";
      states.add(broker);
      const sleeve = await page.locator('[data-testid="sleeve-status"]').getAttribute("data-state");
      if (states.has("offline") && broker === "connected" && sleeve === "online") break;
      if (states.has("offline") && !shot) {
        shot = true;
        await screenshot(page, "up-phone-offline");
      }
      await new Promise((wake) => setTimeout(wake, 50));
    }
    expect(await page.locator(CANVAS).boundingBox()).toEqual(before);

    const cdp = await page.context().newCDPSession(page);
    const area = await drawingArea(page);
    const at = (fx: number, fy: number) =>
      [area.left + area.width * fx, area.top + area.height * fy] as const;
    await drawWithTouch(page, cdp, [at(0.2, 0.2), at(0.8, 0.2), at(0.8, 0.8)]);
    await nextFrame(page);
    await waitForPlayed(page);
    expect(await page.locator(CANVAS).boundingBox()).toEqual(before);
    await screenshot(page, "up-phone");
  });
});
