/**
 * When a drawing's strokes queue, the sender is told how the sleeve caught up, on real processes:
 * `feelmysign up` with the simulated sleeve, the page in Chromium. Play again sends a drawing at
 * once: the sleeve plays the strokes that queue faster, down to its floor, and the "Sleeve says"
 * card and `up`'s line say how many and how much shorter in all, as the sleeve's `played` events
 * say (their `compressed_ms`). A stall on the way (the broker frozen while the pen draws on) sends
 * a backlog at once: the sleeve skips what it is too late for, and the card and `up` say those
 * skipped as late apart from other refusals, each stroke still counted once, and each note in
 * the card's log says "Stroke N skipped as late: ...".
 *
 * The sleeve slows (reports `adjusted`) only a stroke briefer than its floor (73.701 ms, in its
 * status). The page sends none: a piece that could not merge (mid-path, or the one left at
 * release that could not merge back into the stroke before it, window.ts `Merger.end`) is sent
 * to last the floor. A pen resting mid-path (as the drawing pauses while the test freezes the
 * broker) lends a held piece the floor: before it lasted `start + floor - start`, which rounds
 * to 73.70099999999911 ms from 15000.1 ms and was slowed.
 */
import { spawnSync } from "node:child_process";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { durationWords } from "../src/fates";
import type { EventWatcher } from "./harness";
import {
  drawingArea,
  nextFrame,
  screenshot,
  setLeastSquares,
  SUMMARY,
  waitForData,
  waitForEveryStroke,
  type Area,
} from "./page";
import { Processes, type Up } from "./processes";

const CARD = 'section.card:has([data-testid="played-summary"])';
/** events.ts NOTABLE_ADJUSTMENT: a stroke shortened by less than this share is not said. */
const NOTABLE = 0.05;
const LINE_TIMEOUT_MS = 40_000;

type Point = readonly [number, number];

/** The card's counts this test reads. */
const CARD_KEYS = [
  "sent",
  "played",
  "cut",
  "cancelled",
  "refused",
  "dropped",
  "compressed",
  "compressedMs",
  "slowed",
  "lengthened",
  "late",
] as const;

/** The strokes the sleeve slowed: none, as the page sends no stroke briefer than the floor. */
function slowedStrokes(events: readonly Record<string, unknown>[]): string[] {
  return events
    .filter((event) => event["type"] === "adjusted")
    .map((event) => `seq ${String(event["seq"])}: ${String(event["requested_duration_ms"])} ms`);
}

/**
 * What the sleeve's own events say, counted here from the wire (each event once): strokes played
 * faster by a share a person could feel and how much shorter in all, and strokes skipped as late.
 */
function fromEvents(events: readonly Record<string, unknown>[]): {
  compressed: number;
  compressedMs: number;
  slowed: number;
  late: number;
} {
  const seen = new Set<string>();
  let compressed = 0;
  let compressedMs = 0;
  let slowed = 0;
  const late = new Set<number>();
  for (const event of events) {
    const text = JSON.stringify(event);
    if (seen.has(text)) continue;
    seen.add(text);
    if (event["type"] === "rejected" && event["reason"] === "late") late.add(event["seq"] as number);
    if (event["type"] === "adjusted") {
      const asked = event["requested_duration_ms"] as number;
      if (Math.abs((event["duration_ms"] as number) - asked) >= NOTABLE * asked) slowed++;
    }
    const shorter = event["compressed_ms"];
    if ((event["type"] !== "played" && event["type"] !== "adjusted") || typeof shorter !== "number") continue;
    if (shorter > 0 && shorter >= NOTABLE * ((event["duration_ms"] as number) + shorter)) {
      compressed++;
      compressedMs += shorter;
    }
  }
  return { compressed, compressedMs, slowed, late: late.size };
}

/** The span the sleeve played a drawing's strokes over, by its own times: first start to last end. */
function spanOf(events: readonly Record<string, unknown>[]): number {
  let first = Infinity;
  let last = -Infinity;
  for (const event of events) {
    if (event["type"] !== "played" && event["type"] !== "adjusted") continue;
    const start = event["start_at_ms"] as number;
    first = Math.min(first, start);
    last = Math.max(last, start + (event["duration_ms"] as number));
  }
  return last - first;
}

describe("the sender is told how the sleeve caught up with a drawing", () => {
  const processes = new Processes();
  let up: Up;
  let page: Page;
  let area: Area;
  let watcher: EventWatcher;
  let output = "";
  const at = (fx: number, fy: number): Point => [area.left + area.width * fx, area.top + area.height * fy];

  /** A zigzag of `legs` legs, 250 ms a leg with the pen down; `beforeLeg(i)` runs before leg i. */
  async function drawZigzag(legs: number, beforeLeg: (leg: number) => void = () => {}): Promise<string> {
    const corners: Point[] = [];
    for (let i = 0; i <= legs; i++) corners.push(at(0.06 + (0.88 * i) / legs, i % 2 === 0 ? 0.2 : 0.8));
    await page.mouse.move(...corners[0]!);
    await page.mouse.down();
    await nextFrame(page);
    for (let i = 1; i < corners.length; i++) {
      beforeLeg(i);
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

  /** `up`'s last line about `drawing` once it counts `answered` strokes (played and refused). */
  async function upLine(drawing: string, answered: number): Promise<string> {
    const pattern = new RegExp(`Drawing ${drawing.slice(0, 8)}( \\(updated\\))?: [^\\n]*\\n`, "g");
    const count = (line: string, what: RegExp) => Number(what.exec(line)?.[1] ?? 0);
    const deadline = Date.now() + LINE_TIMEOUT_MS;
    for (;;) {
      const line = output.match(pattern)?.at(-1);
      if (line !== undefined) {
        const told =
          count(line, /: (\d+) strokes? played/) +
          count(line, /(\d+) skipped as late/) +
          count(line, /(\d+) rejected/) +
          count(line, /(\d+) cut short/) +
          count(line, /(\d+) cancelled/);
        if (told === answered) return line;
      }
      if (Date.now() > deadline) throw new Error(`up printed no whole line for ${drawing}:\n${output}`);
      await new Promise((wake) => setTimeout(wake, 200));
    }
  }

  /** The Mosquitto `up` runs (its child). */
  function mosquittoOf(): number {
    const found = spawnSync("pgrep", ["-P", String(up.child.pid), "mosquitto"], { encoding: "utf8" });
    const pids = found.stdout.split(/\s+/).filter(Boolean).map(Number);
    if (pids.length !== 1) throw new Error(`expected one mosquitto under up, found ${JSON.stringify(pids)}`);
    return pids[0]!;
  }

  beforeAll(async () => {
    up = await processes.up("catch-up");
    up.child.stdout?.on("data", (chunk: Buffer) => (output += chunk.toString()));
    watcher = await processes.watch(up.credentials);
    page = await processes.onlinePage(up.url);
    area = await drawingArea(page);
  });

  afterAll(() => processes.stop());

  /**
   * Waits for the sleeve's answer to each of the `sent` strokes of `drawing`; what they say. The
   * page sends no stroke the sleeve must slow, mid-path or at a path's end.
   */
  async function answersOf(drawing: string, sent: number): Promise<ReturnType<typeof fromEvents>> {
    await watcher.waitFor("an event for every stroke", () => watcher.of(drawing).length >= sent, 60_000);
    const events = watcher.of(drawing);
    expect(slowedStrokes(events)).toEqual([]);
    const said = fromEvents(events);
    expect(said.slowed).toBe(0);
    return said;
  }

  it(
    "Play again sends the drawing at once: the card and up's line say how many strokes the sleeve played faster, and how much shorter in all",
    { timeout: 180_000 },
    async () => {
      // The chord core: its strokes last up to the latency cap, so most can play faster. The
      // least squares send most at or near the sleeve's floor, which no stroke plays below, and
      // how many of those lie above it depends on how fast a loaded machine draws.
      await setLeastSquares(page, false);
      const drawn = await drawZigzag(10);
      expect(drawn).not.toBe("");
      await waitForEveryStroke(page, CARD_KEYS);
      // Play again: every stroke at once, each queued behind the one before it.
      await page.locator('[data-testid="replay-button"]').click();
      const drawing = await page.evaluate(() => window.feelmysign?.drawingId ?? "");
      expect(drawing).not.toBe(drawn);
      const card = await waitForEveryStroke(page, CARD_KEYS);
      const said = await answersOf(drawing, card.sent);
      // The sleeve caught up: most strokes of a drawing sent at once play faster, none skipped.
      expect(said.compressed).toBeGreaterThanOrEqual(card.sent / 2);
      expect(said.late).toBe(0);
      // The card says what the sleeve's events say, the caught-up among the played.
      expect(card.played).toBe(card.sent);
      expect({
        compressed: card.compressed,
        compressedMs: card.compressedMs,
        slowed: card.slowed,
        late: card.late,
      }).toEqual({
        compressed: said.compressed,
        compressedMs: Math.round(said.compressedMs),
        slowed: said.slowed,
        late: 0,
      });
      // (A stroke slowed would be said after a ";".)
      const slowed = said.slowed === 0 ? "" : `; ${said.slowed} slowed to the sleeve's floor`;
      // The page's own: strokes drawn faster than the sleeve plays, sent at its floor.
      const lengthened =
        card.lengthened === 0
          ? ""
          : `; ${card.lengthened} drawn faster than the sleeve can play, sent at its floor`;
      // No pen to catch up with: the card says the strokes were played back to back, over the span
      // the sleeve's own times give, and how much shorter than the drawing took to draw.
      const spanMs = spanOf(watcher.of(drawing));
      const drawnMs = Number(await page.locator(SUMMARY).getAttribute("data-drawn-ms"));
      expect(drawnMs).toBeGreaterThan(spanMs);
      const summary = await page.locator(SUMMARY).innerText();
      expect(summary).toBe(
        `${card.sent} of ${card.sent} strokes played (back to back in ${durationWords(spanMs)}, ` +
          `${durationWords(drawnMs - spanMs)} shorter than drawn: the pauses left out and ` +
          `${said.compressed} strokes played faster${slowed}${lengthened}).`,
      );
      await expect(page.locator('[data-testid="event-log"]').innerText()).resolves.toContain(
        `Played again: ${card.sent} strokes sent all at once.`,
      );
      // up's line says the sleeve's catch-up in its own words.
      const words = `${said.compressed} faster to catch up, ${durationWords(said.compressedMs)} shorter in all${slowed}`;
      const line = await upLine(drawing, card.sent);
      expect(line).toContain(`: ${card.sent} strokes played (${words})`);
      console.log(`card: ${summary}\nup: ${line.trim()}`);
      const full = await screenshot(page, "catch-up-play-again");
      await page.locator(CARD).screenshot({ path: full.replace(/\.png$/, "-card.png") });
    },
  );

  it(
    "a stall on the way sends a backlog at once: the strokes skipped as late are said apart, each stroke once",
    { timeout: 180_000 },
    async () => {
      await page.locator('[data-testid="new-button"]').click();
      await setLeastSquares(page, true); // the default core again
      // Every note the card's log adds, also those it no longer shows (it keeps the latest few).
      await page.evaluate(() => {
        const notes: string[] = [];
        (window as unknown as { notes: string[] }).notes = notes;
        new MutationObserver((changes) => {
          for (const change of changes)
            for (const node of change.addedNodes) notes.push(node.textContent ?? "");
        }).observe(document.querySelector('[data-testid="event-log"]')!, { childList: true });
      });
      // The broker frozen for 3 s while the pen draws on: what the page sends meanwhile waits on
      // the way, then reaches the sleeve at once, long after it was drawn.
      let broker = 0;
      const drawing = await drawZigzag(20, (leg) => {
        if (leg === 4) {
          broker = mosquittoOf();
          process.kill(broker, "SIGSTOP");
          processes.add(() => void spawnSync("kill", ["-CONT", String(broker)])); // whatever fails
        }
        if (leg === 16) process.kill(broker, "SIGCONT");
      });
      expect(broker).toBeGreaterThan(0);
      const card = await waitForEveryStroke(page, CARD_KEYS);
      // Nothing slowed (answersOf): the rest while the broker froze lends the stroke before it
      // the floor, to the last bit.
      const said = await answersOf(drawing, card.sent);
      expect(said.late).toBeGreaterThan(0);
      expect(card.late).toBe(said.late);
      expect(card.compressed).toBe(said.compressed);
      expect(card.compressedMs).toBe(Math.round(said.compressedMs));
      expect(card.slowed).toBe(said.slowed);
      // Each stroke once: the late among the refused, the caught-up among the played.
      expect(card.played + card.cut + card.cancelled + card.refused + card.dropped).toBe(card.sent);
      const summary = await page.locator(SUMMARY).innerText();
      expect(summary).toContain(`, ${card.late} skipped as late`);
      const otherwise = card.refused - card.late;
      if (otherwise === 0) expect(summary).not.toContain("refused");
      else expect(summary).toContain(`${otherwise} refused`);
      if (card.compressed > 0) expect(summary).toContain(`(${card.compressed} faster to catch up, `);
      // The felt timeline's caption says them as the card does: off the timeline.
      // Each stroke skipped is said so in the card's log (every note, not only those it still
      // shows), as the summary says it, and none as refused.
      const notes = await page.evaluate(() => (window as unknown as { notes: string[] }).notes);
      const skipped = new Set(
        watcher
          .of(drawing, "rejected")
          .filter((e) => e["reason"] === "late")
          .map((e) => e["seq"] as number),
      );
      for (const seq of skipped) {
        // The card names strokes from 1: seq 0 is "Stroke 1".
        const about = notes.filter((note) => note.startsWith(`Stroke ${seq + 1} `));
        expect(about.length, `notes of stroke ${seq}`).toBeGreaterThan(0);
        for (const note of about)
          expect(note).toMatch(/^Stroke \d+ skipped as late: the stroke would start /);
      }
      const caption = await page.locator('[data-testid="timeline-caption"]').innerText();
      expect(caption).toContain(`${card.late} skipped as late (not on the timeline)`);
      const line = await upLine(drawing, card.sent);
      expect(line).toContain(`${card.late} skipped as late`);
      expect(line).not.toMatch(/rejected \([^)]*late/);
      console.log(`card: ${summary}\ncaption: ${caption}\nup: ${line.trim()}`);
      const full = await screenshot(page, "catch-up-after-a-stall");
      await page.locator(CARD).screenshot({ path: full.replace(/\.png$/, "-card.png") });
      await waitForData(page, '[data-testid="broker-status"]', "state", "connected");
    },
  );
});
