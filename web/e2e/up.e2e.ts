/**
 * The whole chain as a person gets it from `make up`: `feelmysign up` (broker,
 * simulated sleeve, this page served with its /config.json), a square drawn
 * with the mouse, the sleeve playing its four strokes, the preview lighting up.
 * Skipped, saying why, on a checkout whose CLI has no `up` yet.
 */
import { spawnSync } from "node:child_process";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, it } from "vitest";
import { FakeSleeve, FEELMYSIGN } from "./harness";
import { screenshot, waitForData } from "./page";
import { Processes } from "./processes";
import { drawSquare, expectStrokesFollow, strokeBounds } from "./strokes";

const hasUp = spawnSync(FEELMYSIGN, ["up", "--help"], { stdio: "ignore" }).status === 0;

describe.skipIf(!hasUp)("served by feelmysign up, with the simulated sleeve", () => {
  const processes = new Processes();
  let page: Page;
  let sleeve: FakeSleeve;

  beforeAll(async () => {
    const up = await processes.up("up");
    // A second login of the sleeve account, listening only: what the simulated sleeve receives.
    sleeve = await FakeSleeve.connect(up.credentials);
    processes.add(() => sleeve.close());
    page = await processes.page(up.url);
  });

  afterAll(() => processes.stop());

  it("connects with nothing typed and sees the sleeve online", async () => {
    await waitForData(page, '[data-testid="broker-status"]', "state", "connected");
    await waitForData(page, '[data-testid="sleeve-status"]', "state", "online");
  });

  it("plays a square drawn with the mouse: strokes along it, cut at its corners, the preview lights up", async () => {
    // Watched from before the first stroke: the sleeve catches up with a drawing, so its last
    // strokes may be over before all of them have reached this test's listener.
    await page.evaluate(() => {
      const preview = document.querySelector('[data-testid="sleeve-preview"]') as HTMLElement;
      const seen = window as unknown as { litSeen: number };
      seen.litSeen = 0;
      new MutationObserver(() => {
        seen.litSeen = Math.max(seen.litSeen, Number(preview.dataset["lit"]));
      }).observe(preview, { attributeFilter: ["data-lit"] });
    });
    const { area, path, sent } = await drawSquare(page);
    const strokes = await sleeve.waitForStrokes(sent);
    expectStrokesFollow(strokes, path, area, await strokeBounds(page, area));
    await page.waitForFunction(() => (window as unknown as { litSeen: number }).litSeen > 0, undefined, {
      timeout: 15_000,
    });
    await screenshot(page, "up-playing");
    await waitForData(page, '[data-testid="played-summary"]', "played", String(sent), 30_000);
  });
});
