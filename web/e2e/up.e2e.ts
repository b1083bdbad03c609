/**
 * The whole chain as a person gets it from `make up`: `feelmysign up` (broker,
 * simulated sleeve, this page served with its /config.json), a square drawn
 * with the mouse, the sleeve playing its four strokes, the preview lighting up.
 * Skipped, saying why, on a checkout whose CLI has no `up` yet.
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { readFileSync, rmSync } from "node:fs";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import {
  checkPrerequisites,
  FakeSleeve,
  FEELMYSIGN,
  launchBrowser,
  tempDir,
  type Credentials,
} from "./harness";
import { drawingArea, drawWithMouse, screenshot, toGrid, waitForData } from "./page";

const UP_READY_TIMEOUT_MS = 30_000;
/** Grid units, as in desktop.e2e.ts. */
const CORNER_TOLERANCE = 0.15;
const hasUp = spawnSync(FEELMYSIGN, ["up", "--help"], { stdio: "ignore" }).status === 0;

/** Starts `feelmysign up` on free ports and resolves with its page URL once it prints it. */
async function startUp(stateDir: string): Promise<{ child: ChildProcess; url: string }> {
  const child = spawn(
    FEELMYSIGN,
    ["up", "--state-dir", stateDir, "--http-port", "0", "--port", "0", "--ws-port", "0"],
    { stdio: ["ignore", "pipe", "pipe"] },
  );
  let output = "";
  const url = await new Promise<string>((ready, fail) => {
    const timer = setTimeout(
      () => fail(new Error(`feelmysign up printed no URL in ${UP_READY_TIMEOUT_MS} ms:\n${output}`)),
      UP_READY_TIMEOUT_MS,
    );
    const collect = (chunk: Buffer) => {
      output += chunk.toString();
      const match = /(http:\/\/127\.0\.0\.1:\d+\/)/.exec(output);
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

async function stopUp(child: ChildProcess): Promise<void> {
  if (child.exitCode !== null || child.signalCode !== null) return;
  const exited = new Promise((done) => child.once("exit", done));
  child.kill("SIGINT");
  const timer = setTimeout(() => child.kill("SIGKILL"), 10_000);
  await exited;
  clearTimeout(timer);
}

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

  it("plays a square drawn with the mouse: four strokes at its corners, the preview lights up", async () => {
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
    const strokes = await sleeve.waitForStrokes(4);
    expect(strokes).toHaveLength(4);
    strokes.forEach((stroke, i) => {
      const [x, y] = stroke["start"] as [number, number];
      const [wx, wy] = toGrid(area, ...corners[i]!);
      expect(Math.hypot(x - wx, y - wy), `stroke ${i} start`).toBeLessThan(CORNER_TOLERANCE);
    });
    await page.waitForFunction(
      () =>
        Number((document.querySelector('[data-testid="sleeve-preview"]') as HTMLElement).dataset["lit"]) > 0,
      undefined,
      { timeout: 15_000 },
    );
    await screenshot(page, "up-playing");
    await waitForData(page, '[data-testid="played-summary"]', "played", "4", 30_000);
  });
});
