/**
 * What the page, `up`'s terminal line and the study's summary say after a fault, against what
 * the sleeve felt (its `--record`), on real processes: `feelmysign up` with the simulated sleeve
 * recording every motor change, its Mosquitto killed with SIGKILL in the middle of a drawing, a
 * copy of a played stroke delivered again after the restart, and Stop pressed (Esc) in Chromium
 * while a drawing plays. Every stroke has one fate (fates.ts, Python's feelmysign.fates): the
 * page's counts, `up`'s line and the study's summary must say the same, add up to the strokes
 * drawn, and the strokes the record felt must be exactly those called played or cut short.
 * The felt timeline's caption counts from the same fates as the card, and leaves out strokes
 * never sent; and a stroke held while the broker was away carries the time it was drawn, so
 * one felt late is counted delayed on the page and in `up`'s line alike (or refused as late).
 */
import { spawnSync } from "node:child_process";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { isDelayed, readEvent, type AdjustedEvent, type PlayedEvent } from "../src/events";
import { DrawingFates, type Fate } from "../src/fates";
import { collectUntil, REPO_DIR, type Credentials, type EventWatcher } from "./harness";
import {
  cardCounts,
  drawingArea,
  nextFrame,
  screenshot,
  SUMMARY,
  waitForData,
  waitForEveryStroke,
  type Area,
} from "./page";
import { Processes, type Up } from "./processes";

const CAPTION = '[data-testid="timeline-caption"]';
const PYTHON = join(REPO_DIR, ".venv", "bin", "python");
/** `up` prints a drawing's line once it has been quiet this long (drawing_log.IDLE_S) and more. */
const LINE_TIMEOUT_MS = 40_000;

type Point = readonly [number, number];

/** The card's counts this test compares. */
const PAGE_KEYS = ["sent", "played", "cut", "cancelled", "refused", "dropped", "delayed"] as const;
type PageCounts = Record<(typeof PAGE_KEYS)[number], number>;

/**
 * What the felt timeline's caption says became of the strokes, in the card's terms. Its short
 * form (", as the sleeve played them.") says every stroke was played.
 */
function captionCounts(caption: string, sent: number): Omit<PageCounts, "sent" | "delayed"> {
  const count = (pattern: RegExp) => [...caption.matchAll(pattern)].reduce((n, m) => n + Number(m[1]), 0);
  const all = /^\d+ strokes?, [\d.]+ s, as the sleeve played them\.$/.test(caption);
  return {
    played: all ? sent : count(/(\d+) (?:as the sleeve played them|played \()/g),
    cut: count(/(\d+) cut short/g),
    cancelled: count(/(\d+) cancelled by Stop/g),
    refused: count(/(\d+) (?:refused by the sleeve|skipped as late|not felt \(the sleeve's duty-cycle cap)/g),
    dropped: count(/(\d+) never sent/g),
  };
}

/** What `up` printed about `drawing`: its last "Drawing" line (the whole drawing). */
function upCounts(line: string): Record<"played" | "cut" | "cancelled" | "refused", number> {
  const count = (pattern: RegExp) => Number(pattern.exec(line)?.[1] ?? 0);
  return {
    played: count(/: (\d+) strokes? played/),
    cut: count(/(\d+) cut short/),
    cancelled: count(/(\d+) cancelled/),
    // Skipped as late is said apart from the other refusals; both are refused.
    refused: count(/(\d+) rejected/) + count(/(\d+) skipped as late/),
  };
}

/** How many strokes `up`'s line calls delayed on the way. */
function upDelayed(line: string): number {
  return Number(/(\d+) delayed on the way/.exec(line)?.[1] ?? 0);
}

/** The study's summary of a send (study/runner.py events_summary) over these events. */
function studySummary(events: readonly Record<string, unknown>[], strokes: number): Record<string, unknown> {
  const code =
    "import json, sys\nfrom feelmysign.study.runner import events_summary\n" +
    "events = json.load(sys.stdin)\nprint(json.dumps(events_summary(events, int(sys.argv[1]))))";
  const run = spawnSync(PYTHON, ["-c", code, String(strokes)], {
    input: JSON.stringify(events),
    encoding: "utf8",
  });
  if (run.status !== 0) throw new Error(`events_summary failed: ${run.stderr}`);
  return JSON.parse(run.stdout) as Record<string, unknown>;
}

/** The seqs of `drawing` whose commands moved a motor, by the sleeve's own record. */
function recordedSeqs(recordPath: string, drawing: string): Set<number> {
  const seqs = new Set<number>();
  for (const line of readFileSync(recordPath, "utf8").split("\n")) {
    if (line.trim() === "") continue;
    const change = JSON.parse(line) as { drawing: string | null; seq: number | null };
    if (change.drawing === drawing && change.seq !== null) seqs.add(change.seq);
  }
  return seqs;
}

function fatesOf(events: readonly Record<string, unknown>[]): DrawingFates {
  const fates = new DrawingFates();
  const seen = new Set<string>();
  for (const wire of events) {
    const text = JSON.stringify(wire);
    if (seen.has(text)) continue; // a copy of an event after the restart: the page drops it too
    seen.add(text);
    const event = readEvent(wire);
    if (event !== null) fates.add(event);
  }
  return fates;
}

/** The Mosquitto `up` runs: none while it is starting one again. */
function mosquittosOf(up: Up): number[] {
  const found = spawnSync("pgrep", ["-P", String(up.child.pid), "mosquitto"], { encoding: "utf8" });
  return found.stdout.split(/\s+/).filter(Boolean).map(Number);
}

function mosquittoOf(up: Up): number {
  const pids = mosquittosOf(up);
  if (pids.length !== 1) throw new Error(`expected one mosquitto under up, found ${JSON.stringify(pids)}`);
  return pids[0]!;
}

/** The played events among `events`, each once. */
function playedOf(events: readonly Record<string, unknown>[]): (PlayedEvent | AdjustedEvent)[] {
  const seen = new Set<string>();
  const played: (PlayedEvent | AdjustedEvent)[] = [];
  for (const wire of events) {
    const event = readEvent(wire);
    const text = JSON.stringify(wire);
    if (event === null || seen.has(text) || (event.type !== "played" && event.type !== "adjusted")) continue;
    seen.add(text);
    played.push(event);
  }
  return played;
}

/**
 * Strokes held while the broker was away carry the time they were drawn: the first drawn offline
 * reaches the sleeve over a second after its `sent_at_ms` (whether it then played or was refused).
 */
function expectHeldStrokesKeepTheirDrawnTime(events: readonly Record<string, unknown>[]): void {
  const ages = events
    .filter((e) => typeof e["sent_at_ms"] === "number" && typeof e["received_at_ms"] === "number")
    .map((e) => (e["received_at_ms"] as number) - (e["sent_at_ms"] as number));
  expect(Math.max(...ages), `ages ${JSON.stringify(ages)}`).toBeGreaterThan(1000);
}

describe("honest after faults: the page, up and the study agree with what the sleeve felt", () => {
  const processes = new Processes();
  let up: Up;
  let page: Page;
  let area: Area;
  let watcher: EventWatcher;
  let recordPath: string;
  let output = "";
  const at = (fx: number, fy: number): Point => [area.left + area.width * fx, area.top + area.height * fy];

  /**
   * A zigzag of `legs` legs between heights `low` and `high` (fractions of the area), 250 ms a
   * leg with the pen down (every corner cuts a stroke); `beforeLeg(i)` runs before leg i.
   * Returns the drawing's id.
   */
  async function drawZigzag(
    legs: number,
    [left, right, low, high]: [number, number, number, number],
    beforeLeg: (leg: number) => Promise<void> | void = () => {},
  ): Promise<string> {
    const corners: Point[] = [];
    for (let i = 0; i <= legs; i++)
      corners.push(at(left + ((right - left) * i) / legs, i % 2 === 0 ? low : high));
    await page.mouse.move(...corners[0]!);
    await page.mouse.down();
    await nextFrame(page);
    for (let i = 1; i < corners.length; i++) {
      await beforeLeg(i);
      const [ax, ay] = corners[i - 1]!;
      const [bx, by] = corners[i]!;
      const startMs = performance.now();
      for (let done = 0; done < 1;) {
        done = Math.min(1, (performance.now() - startMs) / 250);
        await page.mouse.move(ax + (bx - ax) * done, ay + (by - ay) * done);
        await nextFrame(page);
      }
    }
    await page.mouse.up();
    return page.evaluate(() => window.feelmysign?.drawingId ?? "");
  }

  beforeAll(async () => {
    recordPath = join(processes.dir("honest-record"), "felt.jsonl");
    up = await processes.up("honest", { args: ["--record", recordPath] });
    up.child.stdout?.on("data", (chunk: Buffer) => (output += chunk.toString()));
    up.child.stderr?.on("data", (chunk: Buffer) => (output += chunk.toString()));
    watcher = await processes.watch(up.credentials);
    page = await processes.onlinePage(up.url);
    area = await drawingArea(page);
  });

  afterAll(() => processes.stop());

  /** `up`'s line about `drawing` (the last one: it has all of it). */
  async function upLine(drawing: string): Promise<string> {
    const pattern = new RegExp(`Drawing ${drawing.slice(0, 8)}( \\(updated\\))?: [^\\n]*\\n`, "g");
    const deadline = Date.now() + LINE_TIMEOUT_MS;
    for (;;) {
      const lines = output.match(pattern);
      if (lines !== null) return lines[lines.length - 1]!;
      if (Date.now() > deadline) throw new Error(`up printed no line for ${drawing}:\n${output}`);
      await new Promise((wake) => setTimeout(wake, 200));
    }
  }

  /** The page's counts, up's line, the study's summary and the sleeve's record, compared. */
  async function expectAllAgree(drawing: string, counts: PageCounts): Promise<Record<Fate, number>> {
    // The sleeve's events, as any reader gets them (the study stores these with a trial).
    await watcher.waitFor(
      "an event for every stroke sent",
      () => fatesOf(watcher.of(drawing)).fates().size >= counts.sent - counts.dropped,
    );
    const events = watcher.of(drawing);
    const fates = fatesOf(events);
    const byFate = fates.counts();
    // Each stroke drawn once, under one fate: the page's parts add up to what it drew.
    expect(byFate.played + byFate.cut + byFate.cancelled + byFate.refused + counts.dropped).toBe(counts.sent);
    expect({
      played: counts.played,
      cut: counts.cut,
      cancelled: counts.cancelled,
      refused: counts.refused,
    }).toEqual(byFate);
    // up's terminal line, from the same rule: its last about the drawing (a line printed while
    // strokes were still to come is printed again, "(updated)", with all of it).
    let line = await upLine(drawing);
    const deadline = Date.now() + LINE_TIMEOUT_MS;
    while (JSON.stringify(upCounts(line)) !== JSON.stringify(byFate) && Date.now() < deadline) {
      await new Promise((wake) => setTimeout(wake, 500));
      line = await upLine(drawing);
    }
    expect(upCounts(line), `${line}\n${output}`).toEqual(byFate);
    console.log(`page: ${JSON.stringify(counts)}\nup: ${line.trim()}`);
    // Delayed on the way, by one definition (events.ts isDelayed): the page and up name the same.
    const delayed = playedOf(events).filter((event) => isDelayed(event)).length;
    expect(counts.delayed).toBe(delayed);
    expect(upDelayed(line), line).toBe(delayed);
    // The felt timeline's caption says what the card says.
    const caption = await page.locator(CAPTION).innerText();
    const { sent, delayed: _delayed, ...card } = counts;
    expect(captionCounts(caption, sent), caption).toEqual(card);
    expect(caption).not.toContain("the rest"); // every stroke has its fate
    console.log(`caption: ${caption}`);
    // The study's summary of the same events.
    const study = studySummary(events, counts.sent);
    console.log(`study: ${JSON.stringify(study)}`);
    expect({
      played: study["played"],
      cut: study["cut_short"],
      cancelled: study["cancelled"],
      refused: (study["rejected"] as unknown[]).length,
    }).toEqual(byFate);
    // What the sleeve felt: a motor moved for exactly the strokes called played or cut short.
    const felt = [...fates.fates()].filter(([, fate]) => fate === "played" || fate === "cut").map(([s]) => s);
    expect([...recordedSeqs(recordPath, drawing)].sort((a, b) => a - b)).toEqual(felt);
    console.log(
      `record: ${felt.length} strokes moved a motor; page summary: ${await page.locator(SUMMARY).innerText()}`,
    );
    return byFate;
  }

  it(
    "a drawing interrupted by a broker restart: a copy of a played stroke stays played, once",
    { timeout: 240_000 },
    async () => {
      // A zigzag: every corner cuts a stroke; the broker dies after the fifth leg, pen down.
      const drawing = await drawZigzag(12, [0.06, 0.94, 0.2, 0.8], (leg) => {
        if (leg === 6) process.kill(mosquittoOf(up), "SIGKILL");
      });
      expect(drawing).not.toBe("");
      await collectUntil(up.child, /Back: the broker is running again/, "up after the kill", 60_000).catch(
        (error: unknown) => {
          // It may have printed it already, before this listener was added.
          if (!output.includes("Back: the broker is running again")) throw error;
        },
      );
      await waitForData(page, '[data-testid="broker-status"]', "state", "connected", 60_000);
      // Every stroke answered first: the page's log keeps its last few notes, and strokes held
      // in the outbox through the outage, played after the copy, would push its note out.
      const before = await waitForEveryStroke(page, PAGE_KEYS);
      // The broker delivers a stroke again that the sleeve has played (its acknowledgement lost
      // with the broker): here sent again by hand, so that it happens on every run.
      await watcher.waitFor("a played stroke", () => watcher.of(drawing, "played").length > 0, 60_000);
      const playedSeq = Number(watcher.of(drawing, "played")[0]!["seq"]);
      await watcher.client.publishAsync(
        `feelmysign/${(up.credentials as Credentials).sleeve.id}/strokes`,
        JSON.stringify({ v: 1, drawing, seq: playedSeq, start: [0, 0], end: [0, 1], duration_ms: 200 }),
        { qos: 1 },
      );
      const copy = await watcher.waitFor(
        "the copy's refusal",
        () => watcher.of(drawing, "rejected").some((e) => e["reason"] === "duplicate"),
        30_000,
      );
      const duplicate = copy.find((e) => e["drawing"] === drawing && e["reason"] === "duplicate")!;
      expect(duplicate["original_played"]).toBe(true);
      // The page hears the refusal after the watcher does: its note is waited for, then read.
      const cameAgain = `Stroke ${playedSeq + 1} came again`;
      await page
        .waitForFunction(
          (text) => document.querySelector('[data-testid="event-log"]')?.textContent?.includes(text) === true,
          cameAgain,
          { timeout: 30_000 },
        )
        .catch(() => undefined); // the assertion below then shows the log as it is
      const counts = await waitForEveryStroke(page, PAGE_KEYS);
      // The copy changed no count: each stroke still counts once.
      expect(counts).toEqual(before);
      const byFate = await expectAllAgree(drawing, counts);
      expect(byFate.played).toBeGreaterThan(0);
      expectHeldStrokesKeepTheirDrawnTime(watcher.of(drawing));
      const log = await page.locator('[data-testid="event-log"]').innerText();
      expect(log).toContain(cameAgain);
      expect(log).not.toContain(`Stroke ${playedSeq + 1} refused`);
      // The copy counted nothing: the stroke it copies is played, once (checked against up, the
      // study and the record above); refusals are only those of other strokes (late, after the outage).
      expect(fatesOf(watcher.of(drawing)).fate(playedSeq)).toBe("played");
      await screenshot(page, "honest-after-broker-restart");
    },
  );

  it(
    "a long drawing through repeated broker restarts, Drop late: the caption counts as the card, strokes never sent off the timeline",
    { timeout: 300_000 },
    async () => {
      // Drop late: a stroke the page could not send within 2 s is dropped, never sent.
      await page.locator('[data-testid="settings-button"]').click();
      await page.getByText("Drop late").click();
      await page.locator('[data-testid="settings-save"]').click();
      await page.locator('[data-testid="settings-panel"]').waitFor({ state: "hidden" });
      await page.locator('[data-testid="new-button"]').click();
      // A zigzag of 28 legs (7 s); the broker is killed three times, pen down: at the first leg
      // from 3, 12 and 21 on at which up runs one (not while it is starting the next).
      const killFrom = [3, 12, 21];
      let kills = 0;
      const drawing = await drawZigzag(28, [0.04, 0.96, 0.2, 0.8], (leg) => {
        const pids = mosquittosOf(up);
        if (kills < killFrom.length && leg >= killFrom[kills]! && pids.length === 1) {
          process.kill(pids[0]!, "SIGKILL");
          kills++;
        }
      });
      expect(kills).toBeGreaterThanOrEqual(2); // repeated, whatever the machine's pace
      // The broker back for good, the sleeve connected to it, and the page too.
      const deadline = Date.now() + 60_000;
      const back = () =>
        output.lastIndexOf("Back: the broker is running again") >
        Math.max(output.lastIndexOf("The broker stopped"), output.lastIndexOf("The sleeve lost the broker"));
      while (mosquittosOf(up).length !== 1 || !back()) {
        if (Date.now() > deadline) throw new Error(`the broker did not come back:\n${output}`);
        await new Promise((wake) => setTimeout(wake, 200));
      }
      await waitForData(page, '[data-testid="broker-status"]', "state", "connected", 60_000);
      const counts = await waitForEveryStroke(page, PAGE_KEYS);
      console.log(`${kills} broker kills`);
      await expectAllAgree(drawing, counts);
      expectHeldStrokesKeepTheirDrawnTime(watcher.of(drawing));
      // Strokes never sent, and refused on arrival, are not on the timeline: the rest are.
      const onTimeline = Number(await page.locator('[data-testid="timeline"]').getAttribute("data-strokes"));
      expect(onTimeline).toBe(counts.sent - counts.dropped - counts.refused);
      await screenshot(page, "honest-after-repeated-restarts");
      // Send late again, as the other tests expect.
      await page.locator('[data-testid="settings-button"]').click();
      await page.getByText("Send late").click();
      await page.locator('[data-testid="settings-save"]').click();
      await page.locator('[data-testid="settings-panel"]').waitFor({ state: "hidden" });
    },
  );

  it(
    "a drawing cut by Stop: played, cut short and cancelled add up, and the caption says so",
    { timeout: 180_000 },
    async () => {
      // Play again sends the whole drawing at once: the sleeve queues it, and Stop comes mid-way.
      await page.locator('[data-testid="replay-button"]').click();
      const drawing = await page.evaluate(() => window.feelmysign?.drawingId ?? "");
      await page.waitForFunction(
        (selector) => Number((document.querySelector(selector) as HTMLElement).dataset["played"]) >= 3,
        SUMMARY,
        { timeout: 30_000 },
      );
      await page.keyboard.press("Escape");
      const counts = await waitForEveryStroke(page, PAGE_KEYS);
      const byFate = await expectAllAgree(drawing, counts);
      expect(byFate.cancelled).toBeGreaterThan(0);
      const summary = await page.locator(SUMMARY).innerText();
      expect(summary).toContain(`${byFate.cancelled} cancelled by Stop`);
      const caption = await page.locator('[data-testid="timeline-caption"]').innerText();
      expect(caption).not.toContain("the rest as it would");
      expect(caption).toContain("cancelled by Stop");
      await screenshot(page, "honest-after-stop");
    },
  );
  it(
    "Esc while still drawing, the pen moving on: nothing more is sent, and every stroke is told once",
    { timeout: 180_000 },
    async () => {
      await page.locator('[data-testid="new-button"]').click();
      let sentAtStop = 0;
      const drawing = await drawZigzag(10, [0.06, 0.94, 0.25, 0.75], async (leg) => {
        if (leg === 5) {
          await page.keyboard.press("Escape"); // Stop, the pen still down
          sentAtStop = (await cardCounts(page, PAGE_KEYS)).sent;
        }
      });
      const counts = await waitForEveryStroke(page, PAGE_KEYS);
      // The pen moving on after Stop drew nothing more: no stroke was made, none sent.
      expect(counts.sent).toBe(sentAtStop);
      await expectAllAgree(drawing, counts);
      const caption = await page.locator('[data-testid="timeline-caption"]').innerText();
      expect(caption).not.toContain("the rest as it would");
      await screenshot(page, "honest-esc-while-drawing");
    },
  );
});
