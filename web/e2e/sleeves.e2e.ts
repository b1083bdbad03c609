/**
 * Two sleeves on one broker, as `feelmysign up` serves them after `broker
 * add-sleeve arm2`: the page lists both with their state from the retained
 * status, strokes go only to the sleeve chosen, switching back plays on the
 * simulated sleeve, and the choice is remembered across a reload.
 */
import { spawnSync } from "node:child_process";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { Broker, FakeSleeve, FEELMYSIGN } from "./harness";
import { drawingArea, drawWithMouse, nextFrame, screenshot, waitForData, waitForPlayed } from "./page";
import { Processes } from "./processes";

const SECOND = "arm2";
const PICKER = '[data-testid="sleeve-select"]';
const CHIP = '[data-testid="sleeve-status"]';
const LAYOUT = { rows: 3, columns: 4, spacing_cm: 3 };
/** How long each leg of a drawn Z takes to draw, by the clock. */
const LEG_MS = 400;
/** Telemetry of every actuator of a 3 x 4 sleeve at full strength. */
const ALL_ON = { rows: 3, columns: 4, intensities: [1, 1, 1].map(() => [1, 1, 1, 1]) };

/** The picker's options as the sender reads them: "id · state". */
async function options(page: Page): Promise<string[]> {
  return page.locator(`${PICKER} option`).allInnerTexts();
}

async function waitForOption(page: Page, text: string): Promise<void> {
  await page.waitForFunction(
    ({ picker, text }) =>
      [...(document.querySelector(picker) as HTMLSelectElement).options].some((o) => o.text === text),
    { picker: PICKER, text },
    { timeout: 15_000 },
  );
}

/**
 * A Z across the area: three strokes or more (a long leg may be cut by the latency cap). Each
 * leg takes LEG_MS by the clock: a step of a few pixels a frame made a Z hundreds of round
 * trips to the browser, which took minutes on a loaded machine.
 */
async function drawZ(page: Page): Promise<number> {
  const area = await drawingArea(page);
  const at = (fx: number, fy: number) => [area.left + area.width * fx, area.top + area.height * fy] as const;
  await drawWithMouse(page, [at(0.2, 0.2), at(0.8, 0.2), at(0.2, 0.8), at(0.8, 0.8)], { legMs: LEG_MS });
  await nextFrame(page);
  return Number(await page.locator('[data-testid="played-summary"]').getAttribute("data-sent"));
}

describe("two sleeves on one broker, chosen on the page", () => {
  const processes = new Processes();
  let page: Page;
  let first: FakeSleeve;
  let second: FakeSleeve;

  beforeAll(async () => {
    // The broker's state first, then the second sleeve's account, then everything up.
    const up = await processes.up("sleeves", {
      prepare: async (stateDir) => {
        const broker = await Broker.start(stateDir);
        await broker.stop();
        const added = spawnSync(
          FEELMYSIGN,
          ["broker", "--state-dir", stateDir, "add-sleeve", SECOND, "--url", "mqtts://127.0.0.1:8883"],
          { encoding: "utf8" },
        );
        expect(added.status, added.stderr).toBe(0);
      },
    });
    const { stateDir, credentials } = up;
    const accounts = JSON.parse(readFileSync(join(stateDir, "sleeves.json"), "utf8")) as Record<
      string,
      { username: string; password: string }
    >;
    // A second login of the simulated sleeve's account, listening only: what it receives.
    first = await FakeSleeve.connect(credentials);
    processes.add(() => first.close());
    // The second sleeve, played by the test with its own account.
    second = await FakeSleeve.connect(
      { ...credentials, sleeve: { id: SECOND, ...accounts[SECOND]! } },
      { sleeveId: SECOND },
    );
    processes.add(() => second.close());
    await second.publish("status", { online: true, layout: LAYOUT }, true);
    page = await processes.page(up.url);
    await waitForData(page, CHIP, "state", "online", 30_000);
  });

  afterAll(() => processes.stop());

  it("lists both sleeves with their state from the retained status", async () => {
    await waitForOption(page, `${SECOND} · online`);
    await waitForOption(page, "sleeve1 · online");
    expect(await page.locator(PICKER).isVisible()).toBe(true);
    expect(await page.locator(PICKER).inputValue()).toBe("sleeve1");
    await second.publish("status", { online: false, layout: LAYOUT }, true);
    await waitForOption(page, `${SECOND} · offline`);
    await second.publish("status", { online: true, layout: LAYOUT }, true);
    await waitForOption(page, `${SECOND} · online`);
    expect((await options(page)).length).toBe(2);
  });

  it("sends strokes only to the sleeve chosen", async () => {
    await page.locator(PICKER).selectOption(SECOND);
    await waitForData(page, CHIP, "state", "online");
    await expect(page.locator(CHIP).innerText()).resolves.toContain(SECOND);
    const sent = await drawZ(page);
    expect(sent).toBeGreaterThanOrEqual(3);
    const onSecond = await second.waitForStrokes(sent);
    const drawingOnSecond = onSecond[0]!["drawing"];
    expect(onSecond.every((stroke) => stroke["drawing"] === drawingOnSecond)).toBe(true);

    // Back to the simulated sleeve: a new drawing, played there, and nothing more for arm2.
    await page.locator(PICKER).selectOption("sleeve1");
    await waitForData(page, CHIP, "state", "online");
    const sentAgain = await drawZ(page);
    const onFirst = await first.waitForStrokes(sentAgain);
    expect(onFirst.length).toBe(sentAgain);
    expect(onFirst.every((stroke) => stroke["drawing"] !== drawingOnSecond)).toBe(true);
    // Every stroke the page sent is accounted for: sent - arm2's went to sleeve1, none to both.
    expect(onFirst.length + onSecond.length).toBe(sent + sentAgain);
    // Played there (every stroke, or skipped as late by a sleeve fallen behind on a loaded machine).
    await waitForPlayed(page);
    expect(second.strokes().length).toBe(sent);
    await screenshot(page, "sleeves-picker");
  });

  it("once another sleeve is picked, shows none of the first sleeve's events or telemetry", async () => {
    await page.locator(PICKER).selectOption("sleeve1");
    await waitForData(page, CHIP, "state", "online");
    // The first sleeve's events still show while it is the one chosen.
    await first.publish("events", {
      type: "error",
      reason: "backend",
      message: "sleeve1 speaks while chosen",
    });
    await page.getByText("sleeve1 speaks while chosen").waitFor({ timeout: 15_000 });
    // And its actuators light the preview (again if the simulated sleeve's own frame came between).
    for (let tries = 0; ; tries++) {
      await first.publish("actuators", ALL_ON);
      try {
        await waitForData(page, '[data-testid="sleeve-preview"]', "lit", "12", 2000);
        break;
      } catch (error) {
        if (tries === 10) throw error;
      }
    }

    await page.locator(PICKER).selectOption(SECOND);
    await waitForData(page, CHIP, "state", "online");
    await waitForData(page, '[data-testid="sleeve-preview"]', "lit", "0");
    // Then the first sleeve speaks and vibrates, and after it (acknowledged by the broker first,
    // so delivered first) the second: once the second's line shows, the first's would have.
    await first.publish("events", {
      type: "error",
      reason: "backend",
      message: "sleeve1 speaks after the switch",
    });
    await first.publish("actuators", ALL_ON);
    await second.publish("events", { type: "error", reason: "backend", message: `${SECOND} speaks` });
    await page.getByText(`${SECOND} speaks`).waitFor({ timeout: 15_000 });
    await nextFrame(page);
    const log = await page.locator('[data-testid="event-log"]').innerText();
    expect(log).not.toContain("sleeve1 speaks after the switch");
    await expect(page.locator('[data-testid="sleeve-preview"]').getAttribute("data-lit")).resolves.toBe("0");
    await expect(page.locator(CHIP).innerText()).resolves.toContain(SECOND);
  });

  it("remembers the choice across a reload", async () => {
    await page.locator(PICKER).selectOption(SECOND);
    await waitForData(page, CHIP, "state", "online");
    await page.reload();
    await waitForData(page, '[data-testid="broker-status"]', "state", "connected", 30_000);
    await waitForData(page, CHIP, "state", "online", 30_000);
    expect(await page.locator(PICKER).inputValue()).toBe(SECOND);
    await expect(page.locator(CHIP).innerText()).resolves.toContain(SECOND);
  });
});
