/**
 * The wearer's page as `feelmysign up` serves it, on a phone-sized Chromium: the wearer's
 * URL opens it with the wearer's key; pause, resume, stop, the ceiling, "do not disturb"
 * and blocking a named sender each change the sleeve's state (read back from the API and
 * from the state directory), and axe-core finds no serious or critical accessibility
 * violation, paused or not.
 */
import { spawnSync } from "node:child_process";
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { checkPrerequisites, FEELMYSIGN, RESULTS_DIR, startUp, stopChild } from "./harness";
import { screenshot, waitForData } from "./page";
import { Processes } from "./processes";

const AXE_SCRIPT = createRequire(import.meta.url).resolve("axe-core/axe.min.js");
const PHONE = { viewport: { width: 390, height: 844 }, deviceScaleFactor: 2, hasTouch: true, isMobile: true };

interface Controls {
  paused: boolean;
  ceiling: number | null;
  do_not_disturb_until_ms: number | null;
}

/** The state as the page's own origin reads it (with the wearer's cookie). */
async function apiState(
  page: Page,
): Promise<{ controls: Controls; senders: { name: string; blocked: boolean }[] }> {
  return page.evaluate(async () => (await fetch("/api/wearer/state")).json());
}

async function seriousViolations(page: Page): Promise<string[]> {
  await page.addScriptTag({ path: AXE_SCRIPT });
  const results = await page.evaluate(async () => {
    const axe = (window as unknown as { axe: { run: (c: Document) => Promise<unknown> } }).axe;
    return (await axe.run(document)) as {
      violations: { id: string; impact: string | null; help: string; nodes: { html: string }[] }[];
    };
  });
  return results.violations
    .filter((v) => v.impact === "serious" || v.impact === "critical")
    .map((v) => `${v.id} (${v.impact}): ${v.help}: ${v.nodes.map((n) => n.html).join(" | ")}`);
}

describe("the wearer's page served by feelmysign up", () => {
  const processes = new Processes();
  let page: Page;
  let stateDir: string;

  beforeAll(async () => {
    checkPrerequisites();
    stateDir = processes.dir("wearer");
    const { child, url } = await startUp(stateDir, [], {
      url: /(http:\/\/127\.0\.0\.1:\d+\/wearer\?key=[\w-]+)/,
    });
    processes.add(() => stopChild(child));
    const added = spawnSync(
      FEELMYSIGN,
      ["broker", "--state-dir", stateDir, "add-sender", "--name", "alice"],
      {
        encoding: "utf8",
      },
    );
    expect(added.status, added.stderr).toBe(0);
    page = await processes.page(url, PHONE);
    await waitForData(page, '[data-testid="sleeve-line"]', "state", "online");
  });

  afterAll(() => processes.stop());

  it("opens with the wearer's key and has no serious accessibility violation", async () => {
    expect(page.url()).toMatch(/\/wearer$/); // the key went into a cookie, out of the address bar
    await page.locator('[data-testid="sender-alice"]').waitFor();
    expect(await seriousViolations(page)).toEqual([]);
    await screenshot(page, "wearer-phone");
    await page.screenshot({ path: join(RESULTS_DIR, "wearer-phone-full.png"), fullPage: true });
  });

  it("pauses and resumes with one large toggle, and says so", async () => {
    const toggle = page.locator('[data-testid="pause"]');
    expect(await toggle.textContent()).toBe("Pause the sleeve");
    const box = await toggle.boundingBox();
    expect(box!.height).toBeGreaterThanOrEqual(48);
    await toggle.click();
    await waitForData(page, '[data-testid="pause"]', "paused", "true");
    expect((await apiState(page)).controls.paused).toBe(true);
    expect(await page.locator('[data-testid="live"]').textContent()).toContain("Paused");
    expect(await seriousViolations(page)).toEqual([]);
    await screenshot(page, "wearer-phone-paused");
    await toggle.click();
    await waitForData(page, '[data-testid="pause"]', "paused", "false");
    expect((await apiState(page)).controls.paused).toBe(false);
  });

  it("works from the keyboard, with its focus shown", async () => {
    // From the heading (not focusable), Tab goes to the first control: the toggle.
    await page.locator("h1").click();
    await page.keyboard.press("Tab");
    const outline = await page.evaluate(() => {
      const focused = document.activeElement as HTMLElement;
      return { testid: focused.dataset["testid"], style: getComputedStyle(focused).outlineStyle };
    });
    expect(outline).toEqual({ testid: "pause", style: "solid" });
    await page.keyboard.press("Space");
    await waitForData(page, '[data-testid="pause"]', "paused", "true");
    await page.keyboard.press("Enter");
    await waitForData(page, '[data-testid="pause"]', "paused", "false");
  });

  it("stops what plays", async () => {
    await page.locator('[data-testid="stop"]').click();
    await page.waitForFunction(() =>
      document.querySelector('[data-testid="live"]')!.textContent!.includes("Stopped"),
    );
  });

  it("sets a ceiling below the sleeve's maximum, and removes it", async () => {
    await page.locator('[data-testid="ceiling-0.6"]').click();
    await page.waitForFunction(
      () => document.querySelector('[data-testid="ceiling-0.6"]')!.getAttribute("aria-pressed") === "true",
    );
    expect((await apiState(page)).controls.ceiling).toBe(0.6);
    await page.locator('[data-testid="ceiling-none"]').click();
    await page.waitForFunction(
      () => document.querySelector('[data-testid="ceiling-none"]')!.getAttribute("aria-pressed") === "true",
    );
    expect((await apiState(page)).controls.ceiling).toBeNull();
  });

  it("turns on do not disturb for 15 minutes, and ends it", async () => {
    const before = Date.now();
    const end = page.locator('[data-testid="dnd-end"]');
    expect(await end.isVisible()).toBe(false); // nothing to end yet
    await page.locator('[data-testid="dnd-15"]').click();
    await page.waitForFunction(() =>
      document.querySelector('[data-testid="dnd-line"]')!.getAttribute("data-until"),
    );
    const until = (await apiState(page)).controls.do_not_disturb_until_ms!;
    expect(until).toBeGreaterThan(before + 14 * 60_000);
    expect(until).toBeLessThan(Date.now() + 16 * 60_000);
    await page.locator('[data-testid="dnd-end"]').click();
    await waitForData(page, '[data-testid="dnd-line"]', "until", "");
    expect((await apiState(page)).controls.do_not_disturb_until_ms).toBeNull();
    expect(await end.isVisible()).toBe(false);
  });

  it("turns on do not disturb until a time of day", async () => {
    // Two hours from now, in the browser's own time zone, as the time field takes it.
    const hhmm = await page.evaluate(() => {
      const at = new Date(Date.now() + 2 * 3_600_000);
      return `${String(at.getHours()).padStart(2, "0")}:${String(at.getMinutes()).padStart(2, "0")}`;
    });
    await page.locator('[data-testid="dnd-time"]').fill(hhmm);
    await page.locator('[data-testid="dnd-set"]').click();
    await page.waitForFunction(() =>
      document.querySelector('[data-testid="dnd-line"]')!.getAttribute("data-until"),
    );
    const until = (await apiState(page)).controls.do_not_disturb_until_ms!;
    expect(until).toBeGreaterThan(Date.now() + 118 * 60_000);
    expect(until).toBeLessThanOrEqual(Date.now() + 120 * 60_000);
    await page.locator('[data-testid="dnd-end"]').click();
    await waitForData(page, '[data-testid="dnd-line"]', "until", "");
  });

  it("blocks a named sender on the broker, and unblocks it", async () => {
    const sendersFile = join(stateDir, "senders.json");
    await page.locator('[data-testid="sender-alice"]').click();
    await waitForData(page, '[data-sender="alice"]', "blocked", "true");
    expect(JSON.parse(readFileSync(sendersFile, "utf8")).alice.blocked).toBe(true);
    expect(readFileSync(join(stateDir, "passwd"), "utf8")).not.toContain("sender-alice:");
    expect(await page.locator('[data-testid="sender-alice"]').getAttribute("aria-label")).toBe(
      "Unblock alice",
    );
    await page.locator('[data-testid="sender-alice"]').click();
    await waitForData(page, '[data-sender="alice"]', "blocked", "false");
    expect(JSON.parse(readFileSync(sendersFile, "utf8")).alice.blocked).toBe(false);
    expect(readFileSync(join(stateDir, "passwd"), "utf8")).toContain("sender-alice:");
  });

  it("refuses the API to a browser without the wearer's key", async () => {
    const other = await (await processes.browser(PHONE)).newPage();
    await other.goto(page.url()); // /wearer without ?key=
    await waitForData(other, '[data-testid="sleeve-line"]', "state", "no-key");
    expect(await other.locator('[data-testid="problem"]').textContent()).toContain("wearer's key");
  });
});
