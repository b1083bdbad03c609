/**
 * The sender's page in real Chromium against a real Mosquitto: draw a square
 * with the mouse and receive its four strokes as the sleeve; see the sleeve's
 * status, preview and events; settings with inline errors that persist; a
 * recording that `feelmysign simplify` reads; strokes drawn while the broker is
 * down, kept and sent when it is back.
 */
import { execFileSync } from "node:child_process";
import { readFileSync, rmSync } from "node:fs";
import { createServer } from "node:net";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import {
  Broker,
  checkPrerequisites,
  FakeSleeve,
  FEELMYSIGN,
  launchBrowser,
  pageConfig,
  portOf,
  RESULTS_DIR,
  serveDist,
  tempDir,
} from "./harness";
import {
  CANVAS,
  drawingArea,
  drawWithMouse,
  nextFrame,
  screenshot,
  showActuators,
  toGrid,
  waitForData,
  walk,
  openAdvanced,
} from "./page";
import { DESKTOP, Processes } from "./processes";
import { drawSquare, expectStrokesFollow, strokeBounds } from "./strokes";

const UUID = /^[0-9a-f]{8}-[0-9a-f]{4}-4[0-9a-f]{3}-[89ab][0-9a-f]{3}-[0-9a-f]{12}$/;
const STATUS_ONLINE = { online: true, layout: { rows: 3, columns: 4, spacing_cm: 3.0 }, version: "test" };

type Point = readonly [number, number];

describe("drawing with a mouse on a desktop", () => {
  const processes = new Processes();
  let broker: Broker;
  let sleeve: FakeSleeve;
  let page: Page;
  let pageUrl: string;
  const pageErrors: string[] = [];
  /** The strokes the square was sent as (four sides, a long one cut by the latency cap). */
  let sentCount = 0;

  beforeAll(async () => {
    ({ broker, url: pageUrl } = await processes.brokerAndPage());
    sleeve = await FakeSleeve.connect(broker.credentials);
    processes.add(() => sleeve.close());
    page = await (await processes.browser({ ...DESKTOP, deviceScaleFactor: 1 })).newPage();
    page.on("pageerror", (error) => pageErrors.push(String(error)));
    page.on("console", (message) => {
      if (message.type() === "error") pageErrors.push(message.text());
    });
    await page.goto(pageUrl);
  });

  afterAll(() => processes.stop());

  it("connects with the server's config and shows the sleeve online from its retained status", async () => {
    await waitForData(page, '[data-testid="broker-status"]', "state", "connected");
    expect(await page.locator('[data-testid="sleeve-status"]').getAttribute("data-state")).toBe("unknown");
    await sleeve.publish("status", STATUS_ONLINE, true);
    await waitForData(page, '[data-testid="sleeve-status"]', "state", "online");
    await expect(page.locator('[data-testid="sleeve-status"]').innerText()).resolves.toContain("online");
    // The drawing area has the sleeve's aspect ratio: (4 - 1) : (3 - 1).
    const area = await drawingArea(page);
    expect(area.width / area.height).toBeCloseTo(1.5, 2);
    await screenshot(page, "desktop-idle");
  });

  it("sends a square drawn with the mouse as strokes along its four sides, with its corners", async () => {
    const drawnFromMs = Date.now();
    const { area, path, sent } = await drawSquare(page, {
      beforeRelease: async () => {
        await screenshot(page, "desktop-drawing");
      },
    });
    sentCount = sent;
    const strokes = await sleeve.waitForStrokes(sentCount);
    expect(strokes).toHaveLength(sentCount);
    const bounds = await strokeBounds(page, area);
    expectStrokesFollow(strokes, path, area, bounds);
    strokes.forEach((stroke, i) => {
      expect(stroke).toMatchObject({ v: 1, seq: i, intensity: 0.8 });
      expect(stroke["duration_ms"] as number).toBeGreaterThan(0);
      // A wall-clock time (the page and this test share the machine's clock), taken while
      // the square was drawn: not a page-relative or monotonic time. 1 s for rounding.
      expect(stroke["sent_at_ms"] as number).toBeGreaterThanOrEqual(drawnFromMs - 1_000);
      expect(stroke["sent_at_ms"] as number).toBeLessThanOrEqual(Date.now() + 1_000);
      if (i > 0) {
        // Sent strokes join end to start, or leave the gap of a dropped one (< min_length).
        const [x, y] = stroke["start"] as [number, number];
        const [px, py] = strokes[i - 1]!["end"] as [number, number];
        expect(Math.hypot(x - px, y - py), `stroke ${i} joins the one before`).toBeLessThan(bounds.minLength);
      }
    });
    expect(stroke0Drawing(strokes)).toMatch(UUID);
    expect(new Set(strokes.map((stroke) => stroke["drawing"])).size).toBe(1);
  });

  it("lights the preview from the sleeve's actuator telemetry", async () => {
    const preview = '[data-testid="sleeve-preview"]';
    expect(await page.locator(preview).getAttribute("data-lit")).toBe("0");
    const frame = [
      [0, 0.9, 0.4, 0],
      [0, 0.2, 0, 0],
      [0, 0, 0, 0],
    ];
    await showActuators(page, sleeve, frame, 1200); // three on: the preview lights three
    expect(await page.locator(preview).getAttribute("data-max-intensity")).toBe("0.900");
  });

  it("reports what the sleeve said: played strokes counted, a refused one marked", async () => {
    const drawing = stroke0Drawing(sleeve.strokes());
    const now = Date.now();
    const timing = { received_at_ms: now, start_at_ms: now, first_command_at_ms: now, latency_ms: 0.3 };
    const played = { ...timing, start_error_ms: 0, queued_ms: 0, duration_ms: 400, commands: 4 };
    for (const seq of [0, 1, 3]) await sleeve.publish("events", { type: "played", drawing, seq, ...played });
    await sleeve.publish("events", {
      type: "rejected",
      drawing,
      seq: 2,
      received_at_ms: now,
      reason: "duration_too_long",
      message: "duration_ms is 12000; this sleeve plays strokes of at most 10000 ms.",
    });
    await waitForData(page, '[data-testid="played-summary"]', "played", "3");
    const log = page.locator('[data-testid="event-log"] li').first();
    await expect(log.innerText()).resolves.toContain("Stroke 3 refused: duration_ms is 12000");
    // (With a note of the strokes drawn faster than the sleeve plays, sent at its floor, when the
    // drawing by the clock of a loaded machine made some.)
    await expect(page.locator('[data-testid="played-summary"]').innerText()).resolves.toMatch(
      new RegExp(
        `^3 of ${sentCount} strokes played( \\(\\d+ drawn faster than the sleeve can play, sent at its floor\\))?, 1 refused\\.$`,
      ),
    );
    await screenshot(page, "desktop-after");
  });

  it("keeps adjustments under 5% quiet, names a larger one, and marks a stroke delayed on its way with by how much", async () => {
    const drawing = stroke0Drawing(sleeve.strokes());
    const before = Number(await page.locator('[data-testid="played-summary"]').getAttribute("data-played"));
    const now = Date.now();
    const timing = { received_at_ms: now, start_at_ms: now, first_command_at_ms: now, latency_ms: 0.3 };
    const played = { ...timing, start_error_ms: 0, queued_ms: 0, duration_ms: 418, commands: 4 };
    const adjusted = { type: "adjusted", drawing, reason: "min_duration" };
    // 418 ms instead of 417: noise. 600 instead of 417: felt.
    await sleeve.publish("events", { ...adjusted, seq: 0, ...played, requested_duration_ms: 417 });
    await sleeve.publish("events", {
      ...adjusted,
      seq: 1,
      ...played,
      duration_ms: 600,
      requested_duration_ms: 417,
    });
    // Sent 1.5 s before it was felt, none of it waiting behind other strokes: delayed by 1.5 s.
    await sleeve.publish("events", { type: "played", drawing, seq: 2, ...played, sent_at_ms: now - 1500 });
    // Sent as long before, but all of that behind the strokes before it (played back to back): not delayed.
    await sleeve.publish("events", {
      type: "played",
      drawing,
      seq: 3,
      ...played,
      sent_at_ms: now - 1500,
      queued_ms: 1500,
    });
    // All four taken in, then what the card says of them. Each stroke counts once, under one fate
    // (fates.ts): strokes 0, 1 and 3 were played already, and stroke 2's own played event outranks
    // its refusal, so one more stroke is played.
    await waitForData(page, '[data-testid="played-summary"]', "played", String(before + 1));
    await waitForData(page, '[data-testid="played-summary"]', "refused", "0");
    await waitForData(page, '[data-testid="played-summary"]', "delayed", "1");
    const log = await page.locator('[data-testid="event-log"]').innerText();
    expect(log).toContain("Stroke 2 played in 600 ms instead of 417 ms (min duration).");
    expect(log).toContain("Stroke 3 delayed 1.5 s on the way");
    expect(log).not.toContain("Stroke 1 played in");
    expect(log).not.toContain("Stroke 4 played");
    await expect(page.locator('[data-testid="played-summary"]').innerText()).resolves.toContain(
      "1 delayed on the way (last by 1.5 s)",
    );
    const full = await screenshot(page, "desktop-notes-numbered-from-1");
    await page
      .locator('section.card:has([data-testid="played-summary"])')
      .screenshot({ path: full.replace(/\.png$/, "-card.png") });
  });

  it("downloads a recording that feelmysign simplify reads, with the same ends", async () => {
    const [download] = await Promise.all([
      page.waitForEvent("download"),
      page.locator('[data-testid="record-button"]').click(),
    ]);
    expect(download.suggestedFilename()).toMatch(/^feelmysign-drawing-.*\.json$/);
    const file = join(RESULTS_DIR, "recording.json");
    await download.saveAs(file);
    const recording = JSON.parse(readFileSync(file, "utf8"));
    expect(recording.sleeve).toEqual({ rows: 3, columns: 4 });
    expect(recording.strokes).toHaveLength(sentCount);
    const replay = JSON.parse(execFileSync(FEELMYSIGN, ["simplify", file, "--json"], { encoding: "utf8" }));
    // Replay resamples pointer events into frames; the press and the release are frames in both.
    const sent = sleeve.strokes();
    expect(replay.strokes.length).toBeGreaterThanOrEqual(3);
    expect(replay.strokes[0].start).toEqual(sent[0]!["start"]);
    expect(replay.strokes.at(-1).end).toEqual(sent.at(-1)!["end"]);
  });

  it("keeps pen pressure and lets it set the intensity", async () => {
    await page.locator('[data-testid="new-button"]').click();
    const area = await drawingArea(page);
    const cdp = await page.context().newCDPSession(page);
    const before = sleeve.strokes().length;
    const pen = async (type: string, x: number, y: number, force: number) =>
      cdp.send("Input.dispatchMouseEvent", {
        type: type as "mousePressed" | "mouseMoved" | "mouseReleased",
        x,
        y,
        button: "left",
        buttons: type === "mouseReleased" ? 0 : 1,
        clickCount: 1,
        pointerType: "pen",
        force,
      });
    const y = area.top + area.height / 2;
    await pen("mousePressed", area.left + area.width * 0.2, y, 0.5);
    for (const [x] of walk(
      [
        [area.left + area.width * 0.2, y],
        [area.left + area.width * 0.8, y],
      ],
      5,
    )) {
      await pen("mouseMoved", x, y, 0.5);
      await nextFrame(page);
    }
    await pen("mouseReleased", area.left + area.width * 0.8, y, 0);
    const strokes = await sleeve.waitForStrokes(before + 1);
    // The intensity setting (0.8) scaled by the pen's pressure (0.5).
    expect(strokes[before]!["intensity"]).toBe(0.4);
    expect(strokes[before]!["seq"]).toBe(0);
    await cdp.detach();
  });

  it("validates settings inline with the shared ranges and keeps them across a reload", async () => {
    await page.locator('[data-testid="settings-button"]').click();
    const panel = page.locator('[data-testid="settings-panel"]');
    await panel.waitFor({ state: "visible" });
    await screenshot(page, "desktop-settings");
    await openAdvanced(page);
    // The default simplifier is the window one: its max error is open, the angle options locked.
    expect(await page.locator('[data-testid="setting-check_frames"]').isDisabled()).toBe(true);
    const maxError = page.locator('[data-testid="setting-max_error"]');
    await maxError.fill("0");
    await expect(page.locator("#setting-max_error-error").innerText()).resolves.toBe(
      "Max error must be a number from 0.001 to 100.",
    );
    expect(await page.locator('[data-testid="settings-save"]').isDisabled()).toBe(true);
    await screenshot(page, "desktop-settings-error");
    // Only decimal numbers: 0x1 is not read as 1.
    await page.locator('[data-testid="setting-intensity"]').fill("0x1");
    await expect(page.locator("#setting-intensity-error").innerText()).resolves.toContain(
      "Intensity must be",
    );
    await maxError.fill("0.3");
    await page.locator('[data-testid="setting-intensity"]').fill("0.5");
    expect(await page.locator('[data-testid="settings-save"]').isDisabled()).toBe(false);
    await page.locator('[data-testid="settings-save"]').click();
    await panel.waitFor({ state: "hidden" });
    await page.reload();
    await page.locator('[data-testid="settings-button"]').click();
    await openAdvanced(page);
    await expect(page.locator('[data-testid="setting-max_error"]').inputValue()).resolves.toBe("0.3");
    await expect(page.locator('[data-testid="setting-intensity"]').inputValue()).resolves.toBe("0.5");
    await page.locator("#settings-reset").click();
    await expect(page.locator('[data-testid="setting-max_error"]').inputValue()).resolves.toBe("0.25");
    await page.locator('[data-testid="settings-save"]').click();
    await panel.waitFor({ state: "hidden" });
  });

  it("sends legacy text to the legacy topic when chosen", async () => {
    await sleeve.client.subscribeAsync("deviceOne/line", { qos: 1 });
    await page.locator('[data-testid="settings-button"]').click();
    await openAdvanced(page);
    await page.locator('label:has([data-testid="setting-protocol"][value="legacy"])').click();
    await page.locator('[data-testid="settings-save"]').click();
    await waitForData(page, '[data-testid="broker-status"]', "state", "connected");
    const area = await drawingArea(page);
    const y = area.top + area.height * 0.3;
    await drawWithMouse(page, [
      [area.left + area.width * 0.1, y],
      [area.left + area.width * 0.9, y],
    ]);
    const deadline = Date.now() + 15_000;
    let legacy = sleeve.received.filter((message) => message.topic === "deviceOne/line");
    while (legacy.length === 0 && Date.now() < deadline) {
      await nextFrame(page);
      legacy = sleeve.received.filter((message) => message.topic === "deviceOne/line");
    }
    // The line's first stroke (a long line may be cut by the latency cap into several).
    expect(legacy.length).toBeGreaterThanOrEqual(1);
    // startX,startY,endX,endY,duration: grid units with at most 4 decimals, then milliseconds.
    const fields = legacy[0]!.payload.split(",");
    expect(fields).toHaveLength(5);
    for (const field of fields) expect(field).toMatch(/^-?\d+(\.\d{1,4})?$/);
    const [sx, sy] = toGrid(area, area.left + area.width * 0.1, y);
    expect(Number(fields[0])).toBeCloseTo(sx, 3);
    expect(Number(fields[1])).toBeCloseTo(sy, 3);
  });

  it("raised no error in the page", () => {
    expect(pageErrors).toEqual([]);
  });
});

describe("a broker that goes away", () => {
  /**
   * How long each leg of a path takes to draw, by the clock: what is drawn here only has to
   * make strokes, and a step per frame (hundreds of round trips to the browser a path) took
   * minutes on a loaded machine.
   */
  const LEG_MS = 400;
  const cleanups: (() => Promise<void>)[] = [];

  afterAll(async () => {
    for (const cleanup of cleanups.reverse()) await cleanup();
  });

  it("keeps the strokes drawn meanwhile and sends them when it is back; with Drop late, drops and counts them", async () => {
    checkPrerequisites();
    const stateDir = tempDir("broker");
    cleanups.push(async () => rmSync(stateDir, { recursive: true, force: true }));
    let broker = await Broker.start(stateDir, { port: await freePort(), wsPort: await freePort() });
    cleanups.push(() => broker.stop());
    const ports = { port: portOf(broker.credentials.mqtt_url), wsPort: portOf(broker.credentials.ws_url) };
    const server = await serveDist(pageConfig(broker.credentials));
    cleanups.push(server.stop);
    // A persistent session: strokes that reach the broker before this client is back are kept for it.
    const sleeve = await FakeSleeve.connect(broker.credentials, {
      clientId: `test-sleeve-offline-${process.pid}`,
      clean: false,
    });
    cleanups.push(() => sleeve.close());
    const browser = await launchBrowser({ viewport: { width: 1280, height: 800 } });
    cleanups.push(browser.close);
    const page = await browser.context.newPage();
    await page.goto(server.url);
    await waitForData(page, '[data-testid="broker-status"]', "state", "connected");

    const stageBefore = await page.locator(CANVAS).boundingBox();
    const legendBefore = await page.locator("#legend").boundingBox();
    // The legend follows the area (its 10 px gap), with no empty band between them.
    const below = legendBefore!.y - (stageBefore!.y + stageBefore!.height);
    expect(below, "from the area's bottom to its legend").toBeGreaterThanOrEqual(0);
    expect(below, "from the area's bottom to its legend").toBeLessThan(20);
    await broker.stop();
    await waitForData(page, '[data-testid="broker-status"]', "state", "offline");
    // Reconnection attempts every 2 s: the notice stays up and the drawing area does not move.
    // Watched in the page through two attempts (connecting, then offline again), on every frame
    // drawn and every change of the broker's state: what a person would see, however slowly a
    // loaded machine answers this test.
    const unsteady = await page.evaluate(watchWhileReconnecting, { attempts: 2, canvas: CANVAS });
    expect(unsteady, "the notice or the drawing area while reconnecting").toEqual([]);
    // The notice covers no part of the drawing area: it sits under it, over the legend.
    const notice = (await page.locator("#notice").boundingBox())!;
    expect(notice.y, "the notice's top against the area's bottom").toBeGreaterThanOrEqual(
      stageBefore!.y + stageBefore!.height,
    );
    const area = await drawingArea(page);
    const at = (fx: number, fy: number): Point => [area.left + area.width * fx, area.top + area.height * fy];
    await drawWithMouse(page, [at(0.2, 0.2), at(0.2, 0.8), at(0.8, 0.8)], { legMs: LEG_MS });
    await nextFrame(page);
    // Two legs; a long leg may be cut by the latency cap, so two strokes or more.
    const unsent = Number(await page.locator('[data-testid="unsent-count"]').getAttribute("data-count"));
    expect(unsent).toBeGreaterThanOrEqual(2);
    await expect(page.locator('[data-testid="unsent-count"]').innerText()).resolves.toBe(
      `${unsent} strokes unsent`,
    );
    await expect(page.locator("#notice").innerText()).resolves.toContain("No connection to");
    await screenshot(page, "desktop-offline");
    expect(sleeve.strokes()).toHaveLength(0);

    broker = await Broker.start(stateDir, ports);
    const strokes = await sleeve.waitForStrokes(unsent, 60_000);
    expect(strokes.map((stroke) => stroke["seq"])).toEqual([...Array(unsent).keys()]);
    await waitForData(page, '[data-testid="unsent-count"]', "count", "0");
    expect(await page.locator(CANVAS).isVisible()).toBe(true);
    await page.locator("#notice").waitFor({ state: "hidden" });
    expect(await page.locator(CANVAS).boundingBox()).toEqual(stageBefore);

    // Timing "Drop late": what waited longer than 2 s for the broker is dropped, counted, never sent.
    await page.locator('[data-testid="settings-button"]').click();
    await page.getByText("Drop late").click();
    await page.locator('[data-testid="settings-save"]').click();
    await page.locator('[data-testid="settings-panel"]').waitFor({ state: "hidden" });
    await broker.stop();
    await waitForData(page, '[data-testid="broker-status"]', "state", "offline");
    await drawWithMouse(page, [at(0.3, 0.3), at(0.7, 0.3)], { legMs: LEG_MS });
    await nextFrame(page);
    const late = Number(await page.locator('[data-testid="unsent-count"]').getAttribute("data-count"));
    expect(late).toBeGreaterThanOrEqual(1);
    await new Promise((wake) => setTimeout(wake, 2500)); // longer than the 2 s the policy allows
    broker = await Broker.start(stateDir, ports);
    await waitForData(page, '[data-testid="played-summary"]', "dropped", String(late), 60_000);
    await waitForData(page, '[data-testid="unsent-count"]', "count", "0");
    await expect(page.locator('[data-testid="played-summary"]').innerText()).resolves.toContain(
      `${late} never sent`,
    );
    await expect(page.locator('[data-testid="event-log"] li').first().innerText()).resolves.toContain(
      "dropped: not sent within 2 s",
    );
    // A path drawn now is sent; nothing of the dropped one ever was.
    await drawWithMouse(page, [at(0.3, 0.6), at(0.7, 0.6)], { legMs: LEG_MS });
    await nextFrame(page);
    const sentNow = Number(await page.locator('[data-testid="played-summary"]').getAttribute("data-sent"));
    const after = await sleeve.waitForStrokes(sentNow - late, 60_000);
    expect(after.map((stroke) => stroke["seq"])).toEqual(
      [...Array(sentNow).keys()].filter((seq) => seq < unsent || seq >= unsent + late),
    );
  });
});

describe("a wrong password", () => {
  it("stops retrying and says what to fix", async () => {
    checkPrerequisites();
    const stateDir = tempDir("broker");
    const broker = await Broker.start(stateDir);
    const server = await serveDist({ ...pageConfig(broker.credentials), password: "not-the-password" });
    const browser = await launchBrowser({ viewport: { width: 1280, height: 800 } });
    try {
      const page = await browser.context.newPage();
      await page.goto(server.url);
      await waitForData(page, '[data-testid="broker-status"]', "state", "offline");
      await expect(page.locator("#notice").innerText()).resolves.toMatch(
        /refused the login of 'sender'.*Fix the username or password in Settings/,
      );
    } finally {
      await browser.close();
      await server.stop();
      await broker.stop();
      rmSync(stateDir, { recursive: true, force: true });
    }
  });
});

/**
 * In the page: resolves once the broker's state has gone from connecting back to offline
 * `attempts` times, with what changed meanwhile (the notice hidden, the drawing area or its
 * legend moved), looked at on every animation frame and after every change of that state.
 */
function watchWhileReconnecting({
  attempts,
  canvas,
}: {
  attempts: number;
  canvas: string;
}): Promise<string[]> {
  const status = document.querySelector<HTMLElement>('[data-testid="broker-status"]')!;
  const notice = document.querySelector<HTMLElement>("#notice")!;
  const rect = (selector: string) =>
    JSON.stringify(document.querySelector(selector)!.getBoundingClientRect());
  const stage = rect(canvas);
  const legend = rect("#legend");
  const seen: string[] = [];
  const look = (when: string) => {
    // As Playwright's isVisible: a box, and not visibility: hidden.
    if (notice.getClientRects().length === 0 || getComputedStyle(notice).visibility === "hidden")
      seen.push(`notice hidden ${when}`);
    if (rect(canvas) !== stage) seen.push(`drawing area moved ${when}: ${rect(canvas)}, was ${stage}`);
    if (rect("#legend") !== legend) seen.push(`legend moved ${when}: ${rect("#legend")}, was ${legend}`);
  };
  return new Promise((done) => {
    let state = status.dataset["state"];
    let left = attempts;
    let watching = true;
    const frame = () => {
      look("on a frame");
      if (watching) requestAnimationFrame(frame);
    };
    const observer = new MutationObserver(() => {
      const now = status.dataset["state"];
      look(`as the broker went ${state} -> ${now}`);
      if (state === "connecting" && now === "offline") left--;
      state = now;
      if (left === 0) {
        watching = false;
        observer.disconnect();
        done(seen);
      }
    });
    observer.observe(status, { attributes: true, attributeFilter: ["data-state"] });
    requestAnimationFrame(frame);
  });
}

function stroke0Drawing(strokes: Record<string, unknown>[]): string {
  return strokes[0]!["drawing"] as string;
}

/** A port free on 127.0.0.1 now (the broker must come back on the same one). */
async function freePort(): Promise<number> {
  const server = createServer();
  await new Promise<void>((listening) => server.listen(0, "127.0.0.1", listening));
  const { port } = server.address() as { port: number };
  await new Promise<void>((closed) => server.close(() => closed()));
  return port;
}
