/**
 * The recognition study end to end, as a researcher runs a dry run: `feelmysign up --study`
 * (broker, simulated sleeve, the /study page), a simulated participant whose answers are
 * typed into the page, every trial really played by the sleeve; the server killed mid-
 * session (the whole process group, as a power cut) and restarted, the session resuming
 * with every answer kept (checked in the SQLite file); questionnaire, review, analysis.
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { rmSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { checkPrerequisites, FEELMYSIGN, launchBrowser, REPO_DIR, tempDir } from "./harness";
import { screenshot } from "./page";

const PYTHON = join(REPO_DIR, ".venv", "bin", "python");
const UP_READY_TIMEOUT_MS = 40_000;
const hasStudy = spawnSync(FEELMYSIGN, ["study", "--help"], { stdio: "ignore" }).status === 0;

// Small, so the test is quick: 1 practice + 2 shapes x 2 resolutions x 1 repetition = 5 trials.
const DESIGN = `
[study]
name = "Browser dry run"
seed = 7
repetitions = 1
resolutions = ["coarse", "fine"]
[stimulus]
speed_cm_s = 30.0
[[shapes]]
name = "line"
segments = [1, 2]
[[shapes]]
name = "square"
segments = [4, 8]
synonyms = ["box"]
[[practice]]
shape = "line"
[comfort]
questions = ["Does the sleeve sit comfortably?"]
[questionnaire]
items = ["The sleeve was comfortable.", "The vibrations were pleasant."]
`;

interface Up {
  child: ChildProcess;
  url: string;
}

/** `feelmysign up --study` in its own process group, so that a kill takes its broker too. */
async function startUp(stateDir: string, study: string): Promise<Up> {
  const args = [
    "up",
    "--state-dir",
    stateDir,
    "--http-port",
    "0",
    "--port",
    "0",
    "--ws-port",
    "0",
    "--study",
    study,
  ];
  const child = spawn(FEELMYSIGN, args, { stdio: ["ignore", "pipe", "pipe"], detached: true });
  let output = "";
  const url = await new Promise<string>((ready, fail) => {
    const timer = setTimeout(
      () => fail(new Error(`no study URL in ${UP_READY_TIMEOUT_MS} ms:\n${output}`)),
      UP_READY_TIMEOUT_MS,
    );
    const collect = (chunk: Buffer) => {
      output += chunk.toString();
      const match = /Study:\s+(http:\/\/127\.0\.0\.1:\d+\/study)/.exec(output);
      if (match && /Ctrl-C/.test(output)) {
        clearTimeout(timer);
        ready(match[1]!);
      }
    };
    child.stdout!.on("data", collect);
    child.stderr!.on("data", collect);
    child.once("exit", (code) => {
      clearTimeout(timer);
      fail(new Error(`feelmysign up exited with ${code}:\n${output}`));
    });
  });
  return { child, url };
}

async function killGroup(up: Up, signal: NodeJS.Signals): Promise<void> {
  if (up.child.exitCode !== null || up.child.signalCode !== null) return;
  const exited = new Promise((done) => up.child.once("exit", done));
  process.kill(-up.child.pid!, signal);
  await exited;
}

/** Counts in the study file, read by Python's sqlite3 while the server is down or up. */
function rows(study: string): { answered: number; codings: number; played: number; questionnaire: number } {
  const script = `
import json, sqlite3, sys
db = sqlite3.connect(sys.argv[1])
one = lambda q: db.execute(q).fetchone()[0]
print(json.dumps({
  "answered": one("SELECT COUNT(*) FROM trials WHERE answered_at_ms IS NOT NULL"),
  "codings": one("SELECT COUNT(DISTINCT trial) FROM codings"),
  "played": one("SELECT COUNT(*) FROM events WHERE type IN ('played', 'adjusted')"),
  "questionnaire": one("SELECT COUNT(*) FROM questionnaire"),
}))`;
  const result = spawnSync(PYTHON, ["-c", script, study], { encoding: "utf8" });
  if (result.status !== 0) throw new Error(result.stderr);
  return JSON.parse(result.stdout) as ReturnType<typeof rows>;
}

async function answered(page: Page): Promise<number> {
  const text = (await page.locator('[data-testid="progress"]').textContent()) ?? "";
  return Number(/^(\d+)/.exec(text)?.[1] ?? NaN);
}

/** One trial: send, wait until the sleeve played it, type the simulated participant's answer. */
async function runTrial(page: Page): Promise<void> {
  const before = await answered(page);
  await page.click('[data-testid="send"]');
  await page.waitForFunction(
    () => /played \d+ of \d+/.test(document.querySelector('[data-testid="send-status"]')?.textContent ?? ""),
    undefined,
    { timeout: 30_000 },
  );
  const status = (await page.locator('[data-testid="send-status"]').textContent()) ?? "";
  const [, played, strokes] = /played (\d+) of (\d+)/.exec(status)!;
  expect(played, `every stroke played by the sleeve: ${status}`).toBe(strokes);
  const hint = page.locator('[data-testid="simulated-answer"][data-answer]');
  await hint.waitFor({ timeout: 15_000 });
  if ((await hint.getAttribute("data-felt-nothing")) === "true") {
    await page.click('[data-testid="felt-nothing"]');
  } else {
    await page.fill('[data-testid="answer"]', (await hint.getAttribute("data-answer")) ?? "");
    const confidence = (await hint.getAttribute("data-confidence")) ?? "";
    await page.selectOption('[data-testid="confidence"]', confidence);
    await page.click('[data-testid="record"]');
  }
  await page.waitForFunction(
    (count) =>
      Number(/^(\d+)/.exec(document.querySelector('[data-testid="progress"]')?.textContent ?? "")?.[1]) >
      count,
    before,
    { timeout: 15_000 },
  );
}

describe.skipIf(!hasStudy)("the study page against feelmysign up --study", () => {
  const cleanups: (() => Promise<void>)[] = [];
  const dir = tempDir("study");
  const stateDir = join(dir, "state");
  const study = join(dir, "dry-run.sqlite");
  let up: Up;
  let page: Page;

  beforeAll(async () => {
    checkPrerequisites();
    cleanups.push(async () => rmSync(dir, { recursive: true, force: true }));
    writeFileSync(join(dir, "design.toml"), DESIGN);
    const made = spawnSync(FEELMYSIGN, ["study", "new", join(dir, "design.toml"), "--out", study], {
      encoding: "utf8",
    });
    expect(made.status, made.stderr).toBe(0);
    up = await startUp(stateDir, study);
    cleanups.push(() => killGroup(up, "SIGINT"));
    const browser = await launchBrowser({ viewport: { width: 1280, height: 900 } });
    cleanups.push(browser.close);
    page = await browser.context.newPage();
    await page.goto(up.url);
  });

  afterAll(async () => {
    for (const cleanup of cleanups.reverse()) await cleanup();
  });

  it("runs a simulated participant through consent, comfort and the first trials", async () => {
    await page.click('[data-testid="new-simulated"]');
    await page.check('[data-testid="consent-box"]');
    await page.click('[data-testid="consent-yes"]');
    await page.check('[data-testid="comfort-0"]');
    await page.click('[data-testid="comfort-done"]');
    for (let i = 0; i < 3; i++) await runTrial(page);
    expect(await answered(page)).toBe(3);
    await screenshot(page, "study-trial");
  });

  it("loses nothing when the server is killed, and resumes at the next trial", async () => {
    await killGroup(up, "SIGKILL");
    const stored = rows(study);
    expect(stored.answered).toBe(3);
    expect(stored.codings).toBe(3);
    expect(stored.played).toBeGreaterThanOrEqual(1 + 1 + 1);
    up = await startUp(stateDir, study);
    const code = (await page.locator('[data-testid="participant-code"]').textContent())!;
    await page.goto(`${up.url}#${code}`);
    await page.waitForFunction(() => document.querySelector('[data-testid="progress"]') !== null);
    expect(await answered(page)).toBe(3);
    await page.locator('[data-testid="trial"]').waitFor();
  });

  it("finishes the trials and the questionnaire", async () => {
    while ((await page.locator('[data-testid="trial"]').count()) > 0) await runTrial(page);
    for (const item of [0, 1]) await page.check(`[data-testid="likert-${item}"] input[value="4"]`);
    await page.click('[data-testid="questionnaire-done"]');
    await page.locator('[data-testid="done"]').waitFor();
    const stored = rows(study);
    expect(stored.answered).toBe(5);
    expect(stored.questionnaire).toBe(2);
  });

  it("reviews unclear answers, then exports and analyses with plots and a report", async () => {
    await page.click('[data-testid="review-tab"]');
    await page.locator('[data-testid="review-list"], [data-testid="review-empty"]').first().waitFor();
    while ((await page.locator('[data-testid="review-list"] li').count()) > 0) {
      await page.locator('[data-testid="review-list"] li').first().getByText("no shape").click();
      await page.waitForTimeout(100);
    }
    await page.click('[data-testid="results-tab"]');
    await page.click('[data-testid="analyse"]');
    await page.locator('[data-testid="report"]').waitFor({ timeout: 60_000 });
    expect(await page.locator('[data-testid="report"]').textContent()).toContain(
      "Accuracy by shape and resolution",
    );
    const figure = page.locator('[data-testid="figure-accuracy.png"]');
    await page.waitForFunction(
      () =>
        (document.querySelector('[data-testid="figure-accuracy.png"]') as HTMLImageElement | null)
          ?.naturalWidth,
      undefined,
      { timeout: 15_000 },
    );
    expect(await figure.evaluate((img) => (img as HTMLImageElement).naturalWidth)).toBeGreaterThan(100);
    await screenshot(page, "study-results");
  });
});
