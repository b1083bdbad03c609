/**
 * The wearer's page as `feelmysign up` serves it, on a phone-sized Chromium: the wearer's
 * URL opens it with the wearer's key; pause, resume, stop, the ceiling, "do not disturb"
 * and blocking a named sender each change the sleeve's state (read back from the API and
 * from the state directory), and axe-core finds no serious or critical accessibility
 * violation, paused or not. The sleeve's layout allows 0.9 at most and the phone's locale is
 * en-US (whose own clock says "10:11 PM"): the wearer's page and the sender's page, side by
 * side, say the same ceiling and the same time.
 */
import { spawnSync, type ChildProcess } from "node:child_process";
import { readFileSync, writeFileSync } from "node:fs";
import { createRequire } from "node:module";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { checkPrerequisites, FEELMYSIGN, REPO_DIR, RESULTS_DIR, startUp, stopChild } from "./harness";
import { screenshot, waitForData } from "./page";
import { Processes } from "./processes";

const AXE_SCRIPT = createRequire(import.meta.url).resolve("axe-core/axe.min.js");
const PHONE = {
  viewport: { width: 390, height: 844 },
  deviceScaleFactor: 2,
  hasTouch: true,
  isMobile: true,
  locale: "en-US",
};
const DESKTOP = { viewport: { width: 1280, height: 800 }, locale: "en-US" };
const MAX_INTENSITY = 0.9;

/** "22:11", or "tomorrow at 07:00", for `ms` in the page's own time zone (24-hour, as both pages say it). */
async function untilInPage(page: Page, ms: number): Promise<string> {
  return page.evaluate((at) => {
    const date = new Date(at);
    const hhmm = `${String(date.getHours()).padStart(2, "0")}:${String(date.getMinutes()).padStart(2, "0")}`;
    return date.getDate() === new Date().getDate() ? hhmm : `tomorrow at ${hhmm}`;
  }, ms);
}

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
  let senderUrl: string;
  let up: ChildProcess;

  beforeAll(async () => {
    checkPrerequisites();
    stateDir = processes.dir("wearer");
    // The paper's sleeve, allowing 0.9 at most: the wearer's choices are laid out from there down.
    const layout = join(stateDir, "sleeve-0.9.toml");
    const paper = readFileSync(join(REPO_DIR, "deploy", "layouts", "paper-sleeve.toml"), "utf8");
    writeFileSync(layout, paper.replace(/^max_intensity = 1\.0/m, `max_intensity = ${MAX_INTENSITY}`));
    const { child, match } = await startUp(stateDir, ["--layout", layout], {
      url: /Draw here:\s+(http:\/\/127\.0\.0\.1:\d+\/\S*)[\s\S]*?(http:\/\/127\.0\.0\.1:\d+\/wearer\?key=[\w-]+)/,
    });
    processes.add(() => stopChild(child));
    up = child;
    senderUrl = match[1]!;
    const url = match[2]!;
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

  it("offers ceilings as drive levels from the sleeve's strongest down, and removes it", async () => {
    const labels = await page.locator("#ceiling-choices button").allTextContents();
    expect(labels.map((label) => label.trim())).toEqual([
      "The strongest this sleeve allows (90 %)",
      "80 % at most",
      "60 % at most",
      "40 % at most",
      "20 % at most",
    ]);
    await page.locator('[data-testid="ceiling-0.6"]').click();
    await page.waitForFunction(
      () => document.querySelector('[data-testid="ceiling-0.6"]')!.getAttribute("aria-pressed") === "true",
    );
    expect((await apiState(page)).controls.ceiling).toBe(0.6);
    expect(await page.locator('[data-testid="ceiling-line"]').textContent()).toBe(
      "At most 60 %, whatever the sender asks (this sleeve allows up to 90 %).",
    );
    expect(await page.locator('[data-testid="live"]').textContent()).toContain("Strongest vibration 60 %.");
    await screenshot(page, "wearer-phone-ceiling");
    await page.locator('[data-testid="ceiling-none"]').click();
    await page.waitForFunction(
      () => document.querySelector('[data-testid="ceiling-none"]')!.getAttribute("aria-pressed") === "true",
    );
    expect((await apiState(page)).controls.ceiling).toBeNull();
    expect(await page.locator('[data-testid="ceiling-line"]').textContent()).toBe(
      "No ceiling: up to the strongest this sleeve allows, 90 %.",
    );
  });

  it("shows the sender the same ceiling and the same time as the wearer's page", async () => {
    await page.locator('[data-testid="ceiling-0.6"]').click();
    await page.locator('[data-testid="dnd-60"]').click();
    await page.waitForFunction(() =>
      document.querySelector('[data-testid="dnd-line"]')!.getAttribute("data-until"),
    );
    const until = (await apiState(page)).controls.do_not_disturb_until_ms!;
    const when = await untilInPage(page, until);
    expect(await page.locator('[data-testid="dnd-line"]').textContent()).toBe(
      `On until ${when}: nothing reaches you.`,
    );
    const sender = await processes.page(senderUrl, DESKTOP);
    await waitForData(sender, '[data-testid="wearer-notice"]', "state", "held");
    expect(await sender.locator('[data-testid="wearer-headline"]').textContent()).toBe(
      `The wearer asked not to be disturbed until ${when}.`,
    );
    // The page's intensity is 80 %: the sleeve plays it at the wearer's 60 %, as the wearer's page says.
    expect(await sender.locator('[data-testid="wearer-ceiling"]').textContent()).toBe(
      "The wearer set a ceiling of 60 %: your 80 % plays at 60 %.",
    );
    await screenshot(sender, "wearer-sender-sees-ceiling-and-dnd");
    await page.locator('[data-testid="dnd-end"]').click();
    await waitForData(page, '[data-testid="dnd-line"]', "until", "");
    // Ended by the wearer before its time: said so, not as a resume.
    await waitForData(sender, '[data-testid="wearer-notice"]', "state", "resumed");
    expect(await sender.locator('[data-testid="wearer-headline"]').textContent()).toBe(
      "The wearer ended do not disturb.",
    );
    expect(await sender.locator('[data-testid="event-log"]').innerText()).toContain(
      `The wearer asked not to be disturbed until ${when}: what you draw is held here until then.`,
    );
    await page.locator('[data-testid="ceiling-none"]').click();
    await page.waitForFunction(
      () => document.querySelector('[data-testid="ceiling-none"]')!.getAttribute("aria-pressed") === "true",
    );
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
    // Nothing plays: said so under Vibration and to a screen reader, not "Playing".
    await page.waitForFunction(() =>
      document.querySelector('[data-testid="pause-line"]')!.textContent!.startsWith("Do not disturb until"),
    );
    expect(await page.locator('[data-testid="pause-line"]').textContent()).toContain("nothing plays");
    expect(await page.locator('[data-testid="live"]').textContent()).not.toContain("Playing");
    await page.locator('[data-testid="dnd-end"]').click();
    await waitForData(page, '[data-testid="dnd-line"]', "until", "");
    expect((await apiState(page)).controls.do_not_disturb_until_ms).toBeNull();
    expect(await end.isVisible()).toBe(false);
  });

  it("carries out a tap made while another change is under way, and never holds Stop behind it", async () => {
    // A slow network: the ceiling's answer takes a second. Taps meanwhile were once ignored.
    const posted: string[] = [];
    let releaseCeiling = () => {};
    const ceilingHeld = new Promise<void>((done) => (releaseCeiling = done));
    await page.route("**/api/wearer/ceiling", async (route) => {
      await ceilingHeld;
      await route.continue();
    });
    const seen = (request: { method(): string; url(): string }) => {
      if (request.method() === "POST") posted.push(new URL(request.url()).pathname);
    };
    page.on("request", seen);
    try {
      await page.locator('[data-testid="ceiling-0.4"]').click();
      await page.locator('[data-testid="dnd-15"]').click();
      await page.locator('[data-testid="stop"]').click();
      // Stop went out at once, while the ceiling waits; the do-not-disturb waits its turn.
      await page.waitForFunction(() =>
        document.querySelector('[data-testid="live"]')!.textContent!.includes("Stopped"),
      );
      expect(posted).toEqual(["/api/wearer/ceiling", "/api/wearer/stop"]);
      releaseCeiling();
      await page.waitForFunction(() =>
        document.querySelector('[data-testid="dnd-line"]')!.getAttribute("data-until"),
      );
      expect(posted).toEqual(["/api/wearer/ceiling", "/api/wearer/stop", "/api/wearer/do-not-disturb"]);
      const controls = (await apiState(page)).controls;
      expect(controls.ceiling).toBe(0.4);
      expect(controls.do_not_disturb_until_ms).not.toBeNull();
    } finally {
      releaseCeiling();
      page.off("request", seen);
      await page.unroute("**/api/wearer/ceiling");
    }
    await page.locator('[data-testid="dnd-end"]').click();
    await waitForData(page, '[data-testid="dnd-line"]', "until", "");
    await page.locator('[data-testid="ceiling-none"]').click();
    await page.waitForFunction(
      () => document.querySelector('[data-testid="ceiling-none"]')!.getAttribute("aria-pressed") === "true",
    );
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
    expect(await page.locator('[data-testid="dnd-line"]').textContent()).toBe(
      `On until ${await untilInPage(page, until)}: nothing reaches you.`,
    );
    await page.locator('[data-testid="dnd-end"]').click();
    await waitForData(page, '[data-testid="dnd-line"]', "until", "");
  });

  it("says tomorrow for a time that has passed today, before and after setting it", async () => {
    // Midnight has always passed today: the next one is tomorrow's.
    const hhmm = "00:00";
    const hint = page.locator('[data-testid="dnd-time-hint"]');
    await page.locator('[data-testid="dnd-time"]').fill(hhmm);
    await expect(hint.textContent()).resolves.toBe(
      `Set makes it until tomorrow at ${hhmm}: that time has passed today.`,
    );
    await screenshot(page, "wearer-phone-dnd-tomorrow-hint");
    await page.locator('[data-testid="dnd-set"]').click();
    await page.waitForFunction(() =>
      document.querySelector('[data-testid="dnd-line"]')!.getAttribute("data-until"),
    );
    const until = (await apiState(page)).controls.do_not_disturb_until_ms!;
    expect(until).toBe(
      await page.evaluate(() => new Date(new Date().setHours(24, 0, 0, 0)).getTime()), // the next midnight
    );
    expect(await page.locator('[data-testid="dnd-line"]').textContent()).toBe(
      `On until tomorrow at ${hhmm}: nothing reaches you.`,
    );
    await page.locator('[data-testid="dnd-end"]').click();
    await waitForData(page, '[data-testid="dnd-line"]', "until", "");
  });

  it("takes the time 24-hour in an en-US browser, as typed, with no AM/PM", async () => {
    // The page is en-US (PHONE): a native time field would show 10:30 PM and want AM/PM typed.
    expect(await page.evaluate(() => navigator.language)).toBe("en-US");
    const field = page.locator('[data-testid="dnd-time"]');
    await field.fill("");
    await field.pressSequentially("22:30");
    expect(await field.inputValue()).toBe("22:30");
    await expect(page.locator('[data-testid="dnd-time-hint"]').textContent()).resolves.toMatch(
      /^Set makes it until (tomorrow at )?22:30/,
    );
    expect(await field.evaluate((input) => (input as HTMLInputElement).type)).toBe("text");
    await screenshot(page, "wearer-phone-dnd-24-hour");
    // A 12-hour time typed whole reaches the check, which refuses it: not cut to "10:30" (12
    // hours early).
    await field.fill("");
    await field.pressSequentially("10:30 PM");
    expect(await field.inputValue()).toBe("10:30 PM");
    await page.locator('[data-testid="dnd-set"]').click();
    await waitForData(page, '[data-testid="dnd-time-hint"]', "state", "problem");
    expect((await apiState(page)).controls.do_not_disturb_until_ms).toBeNull();
    await field.fill("");
  });

  it("says what to enter when Set is pressed without a time", async () => {
    const field = page.locator('[data-testid="dnd-time"]');
    await field.fill("");
    await page.locator('[data-testid="dnd-set"]').click();
    const hint = page.locator('[data-testid="dnd-time-hint"]');
    await waitForData(page, '[data-testid="dnd-time-hint"]', "state", "problem");
    expect(await hint.textContent()).toBe(
      "Enter the time do not disturb ends, such as 22:30, then press Set.",
    );
    expect(await hint.isVisible()).toBe(true);
    expect(await field.getAttribute("aria-invalid")).toBe("true");
    expect(await page.evaluate(() => document.activeElement?.id)).toBe("dnd-time");
    expect((await apiState(page)).controls.do_not_disturb_until_ms).toBeNull();
    expect(await seriousViolations(page)).toEqual([]);
    await screenshot(page, "wearer-phone-dnd-empty-time");
  });

  it("blocks a named sender on the broker, and unblocks it", async () => {
    const sendersFile = join(stateDir, "senders.json");
    await page.locator('[data-testid="sender-alice"]').click();
    await waitForData(page, '[data-sender="alice"]', "blocked", "true");
    expect(JSON.parse(readFileSync(sendersFile, "utf8")).alice.blocked).toBe(true);
    expect(await page.locator('[data-testid="live"]').textContent()).toBe(
      "Blocked alice. What was playing or waiting was stopped too.",
    );
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

  it("says the sleeve does not answer once its server is gone, and disables every control", async () => {
    await stopChild(up);
    await waitForData(page, '[data-testid="sleeve-line"]', "state", "unreachable");
    expect(await page.locator('[data-testid="sleeve-line"]').textContent()).toContain(
      "The sleeve does not answer",
    );
    expect(await page.locator('[data-testid="sleeve-line"]').textContent()).not.toContain("broker");
    for (const id of ["pause", "stop", "dnd-15", "sender-alice"]) {
      expect(await page.locator(`[data-testid="${id}"]`).isDisabled(), id).toBe(true);
    }
    expect(await page.locator('[data-testid="dnd-line"]').textContent()).toContain("Unknown");
    await page.evaluate(() => window.scrollTo(0, 0));
    await screenshot(page, "wearer-sleeve-gone");
  });
});
