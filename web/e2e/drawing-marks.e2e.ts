/**
 * What the drawing area shows, read from its pixels in real Chromium: Esc with
 * the pen down ends the path there; a stroke the sleeve refused stays marked
 * refused, whatever is redrawn; one refused leaves the felt timeline and one the
 * duty-cycle cap kept from playing is marked refused too; the A/B comparison
 * lies on the drawing it is compared with.
 */
import { readFileSync } from "node:fs";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { FakeSleeve, REPO_DIR } from "./harness";
import { drawingArea, moveByClock, nextFrame, screenshot, waitForData } from "./page";
import { DESKTOP, Processes } from "./processes";

const STATUS_ONLINE = { online: true, layout: { rows: 3, columns: 4, spacing_cm: 3.0 }, version: "test" };
const SUMMARY = '[data-testid="played-summary"]';
/** The ink of canvas.ts: a sent stroke, and a refused one. */
const SENT_RGB = [0xff, 0x8a, 0x5b] as const;
const REFUSED_RGB = [0xff, 0x6b, 0x6b] as const;
/** The comparison's dashed line (canvas.ts COLORS.compare). */
const COMPARE_RGB = [0x5e, 0xc8, 0xff] as const;

/** How fast the hand moves: 8 px a frame at 60 frames a second. */
const HAND_PX_PER_MS = (8 * 60) / 1000;

type Point = readonly [number, number];
type Rgb = readonly [number, number, number];

/** An event as the sleeve publishes it (testdata/events/event/<name>.json), about stroke `seq` of `drawing`. */
function sleeveEvent(name: string, drawing: string | null, seq: number): object {
  const path = join(REPO_DIR, "testdata", "events", "event", `${name}.json`);
  const { wire } = JSON.parse(readFileSync(path, "utf8")) as { wire: object };
  return { ...wire, drawing, seq, received_at_ms: Date.now() };
}

describe("the drawing area's marks", () => {
  const processes = new Processes();
  let sleeve: FakeSleeve;
  let page: Page;

  beforeAll(async () => {
    const { broker, url } = await processes.brokerAndPage();
    sleeve = await FakeSleeve.connect(broker.credentials);
    processes.add(() => sleeve.close());
    page = await (await processes.browser({ ...DESKTOP, deviceScaleFactor: 1 })).newPage();
    await page.goto(url);
    await waitForData(page, '[data-testid="broker-status"]', "state", "connected");
    await sleeve.publish("status", STATUS_ONLINE, true);
    await waitForData(page, '[data-testid="sleeve-status"]', "state", "online");
  });

  afterAll(() => processes.stop());

  /** A point of the drawing area, as shares of its width and height. */
  async function at(u: number, v: number): Promise<Point> {
    const area = await drawingArea(page);
    return [area.left + u * area.width, area.top + v * area.height];
  }

  async function press(point: Point): Promise<void> {
    await page.mouse.move(...point);
    await page.mouse.down();
    await nextFrame(page);
  }

  /**
   * Moves along the polyline from its first point as a quiet machine did a step of 8 px a frame
   * (60 a second), but by the clock: a loaded machine, giving frames slowly, gets fewer and
   * longer steps, and a path lasts as long (a stroke as many of the latency cap's 200 ms), where
   * 8 px a frame took minutes.
   */
  async function moveAlong(points: readonly Point[]): Promise<void> {
    await moveByClock(page, points, ([ax, ay], [bx, by]) => Math.hypot(bx - ax, by - ay) / HAND_PX_PER_MS);
  }

  async function draw(points: readonly Point[]): Promise<void> {
    await press(points[0]!);
    await moveAlong(points);
    await page.mouse.up();
    await nextFrame(page);
  }

  const drawingId = () => page.evaluate(() => window.feelmysign!.drawingId);
  const sentCount = async () => Number(await page.locator(SUMMARY).getAttribute("data-sent"));
  const sleeveStrokes = (drawing: string | null) =>
    sleeve.strokes().filter((stroke) => stroke["drawing"] === drawing);

  /** Waits until the sleeve has every stroke the page sent of the drawing, and the broker acknowledged them. */
  async function allSent(drawing: string | null): Promise<number> {
    const sent = await sentCount();
    const deadline = Date.now() + 30_000;
    while (sleeveStrokes(drawing).length < sent) {
      if (Date.now() > deadline)
        throw new Error(`the sleeve has ${sleeveStrokes(drawing).length} of ${sent}`);
      await new Promise((wake) => setTimeout(wake, 50));
    }
    await waitForData(page, '[data-testid="unsent-count"]', "count", "0");
    await nextFrame(page);
    await nextFrame(page);
    return sent;
  }

  /** A new drawing of one line across the middle, from `u0` to `u1` of the width, sent: its ends. */
  async function newLine(u0: number, u1: number): Promise<[Point, Point]> {
    await page.locator('[data-testid="new-button"]').click();
    const ends: [Point, Point] = [await at(u0, 0.5), await at(u1, 0.5)];
    await draw(ends);
    await allSent(await drawingId());
    return ends;
  }

  /**
   * Along the row at viewport y `y`, from x0 to x1: how many pixel columns of the ink canvas show
   * the colour `rgb` within two pixels of the row.
   */
  async function columnsOf(layer: string, rgb: Rgb, y: number, x0: number, x1: number): Promise<number> {
    return page.evaluate(
      ({ layer, rgb, y, x0, x1 }) => {
        const canvas = document.querySelector<HTMLCanvasElement>(`#stage canvas.${layer}`)!;
        const rect = canvas.getBoundingClientRect();
        const scale = canvas.width / rect.width;
        const top = Math.round((y - rect.top) * scale) - 2;
        const data = canvas.getContext("2d")!.getImageData(0, top, canvas.width, 5).data;
        const near = (i: number) =>
          Math.abs(data[i]! - rgb[0]) <= 10 &&
          Math.abs(data[i + 1]! - rgb[1]) <= 12 &&
          Math.abs(data[i + 2]! - rgb[2]) <= 12 &&
          data[i + 3]! > 200;
        let count = 0;
        for (let x = Math.round((x0 - rect.left) * scale); x <= Math.round((x1 - rect.left) * scale); x++) {
          let hit = false;
          for (let row = 0; row < 5; row++) hit ||= near((row * canvas.width + x) * 4);
          if (hit) count++;
        }
        return count;
      },
      { layer, rgb, y, x0, x1 },
    );
  }

  it("ends the path at Esc with the pen still down: what the hand draws after is neither drawn nor sent", async () => {
    const [a, b, c, d] = [await at(0.1, 0.2), await at(0.9, 0.2), await at(0.9, 0.8), await at(0.1, 0.8)];
    const halfway: Point = [(b[0] + c[0]) / 2, (b[1] + c[1]) / 2];
    await press(a);
    await moveAlong([a, b, halfway]);
    const drawing = await drawingId();
    await page.keyboard.press("Escape");
    const sentAtEsc = await sentCount();
    expect(sentAtEsc).toBeGreaterThan(0);
    // The hand goes on around two more corners, then lifts: every corner would be a stroke.
    await moveAlong([halfway, c, d, a]);
    await page.mouse.up();
    await nextFrame(page);
    expect(await drawingId()).toBe(drawing);
    expect(await sentCount()).toBe(sentAtEsc);
    // The next path starts a new drawing; once its strokes are at the sleeve, so would be any
    // the first sent after Esc (one connection, published in order).
    await draw([await at(0.3, 0.5), await at(0.6, 0.5)]);
    const next = await drawingId();
    expect(next).not.toBe(drawing);
    await allSent(next);
    expect(sleeveStrokes(drawing).map((stroke) => stroke["seq"])).toEqual([...Array(sentAtEsc).keys()]);
  });

  it("keeps a refused stroke marked refused when the drawing is redrawn (Undo)", async () => {
    await page.locator('[data-testid="new-button"]').click();
    const [left, right] = [await at(0.15, 0.3), await at(0.6, 0.3)];
    await draw([left, right]);
    const drawing = await drawingId();
    const firstPath = await allSent(drawing);
    await draw([await at(0.8, 0.2), await at(0.8, 0.8)]);
    await allSent(drawing);
    // The middle of the first path, clear of the joints at its strokes' ends.
    const [x0, x1] = [left[0] + 0.1 * (right[0] - left[0]), left[0] + 0.9 * (right[0] - left[0])];
    const span = x1 - x0;
    const y = left[1];
    expect(await columnsOf("ink", SENT_RGB, y, x0, x1)).toBeGreaterThan(0.8 * span);

    const now = Date.now();
    for (let seq = 0; seq < firstPath; seq++) {
      await sleeve.publish("events", {
        type: "rejected",
        drawing,
        seq,
        received_at_ms: now,
        reason: "duration_too_long",
        message: "duration_ms is 12000; this sleeve plays strokes of at most 10000 ms.",
      });
    }
    await waitForData(page, SUMMARY, "refused", String(firstPath));
    await nextFrame(page);
    await nextFrame(page);
    expect(await columnsOf("ink", SENT_RGB, y, x0, x1)).toBeLessThan(0.2 * span);
    expect(await columnsOf("ink", REFUSED_RGB, y, x0, x1)).toBeGreaterThan(0);

    await page.locator('[data-testid="undo-button"]').click();
    await nextFrame(page);
    await screenshot(page, "refused-after-undo");
    expect(await columnsOf("ink", SENT_RGB, y, x0, x1)).toBeLessThan(0.2 * span);
    expect(await columnsOf("ink", REFUSED_RGB, y, x0, x1)).toBeGreaterThan(0);
  });

  it("takes a refused stroke out of the felt timeline, and marks one the duty-cycle cap kept from playing", async () => {
    const [left, right] = await newLine(0.1, 0.9);
    // Played again: every stroke reaches the sleeve at once, so the timeline plays them back to back.
    await page.locator('[data-testid="replay-button"]').click();
    const drawing = await drawingId();
    const strokes = await allSent(drawing);
    expect(strokes, "a line long enough for three strokes or more").toBeGreaterThanOrEqual(3);
    const durationMs = new Map(
      sleeveStrokes(drawing).map((stroke) => [stroke["seq"] as number, stroke["duration_ms"] as number]),
    );
    const timeline = '[data-testid="timeline"]';
    const totalMs = async () => Number(await page.locator(timeline).getAttribute("data-total-ms"));
    const before = await totalMs();
    const red = () => columnsOf("ink", REFUSED_RGB, left[1], left[0], right[0]);
    // Bits too short to feel, dropped by the simplifier, are dashed red already.
    const dropped = await red();

    // Refused: never in the sleeve's queue, so never felt, and the strokes after it move up.
    await sleeve.publish("events", sleeveEvent("rejected", drawing, 0));
    await waitForData(page, SUMMARY, "refused", "1");
    await waitForData(page, timeline, "strokes", String(strokes - 1));
    // No longer, and shorter by at most the refused stroke's duration: the strokes after it catch
    // up less (when they were caught up by as much as it lasted, the total stays the same).
    const after = await totalMs();
    expect(after).toBeLessThanOrEqual(before + 1);
    expect(before - after).toBeLessThanOrEqual(durationMs.get(0)! + 1);
    await nextFrame(page);
    const refusedColumns = await red();
    expect(refusedColumns).toBeGreaterThan(dropped);

    // Kept from playing by the duty-cycle cap when its turn came: marked refused on the canvas and
    // counted so; its turn passed in silence, so the strokes after it stay where they were.
    await sleeve.publish("events", sleeveEvent("safety-duty-cycle", drawing, 1));
    await waitForData(page, SUMMARY, "refused", "2");
    await nextFrame(page);
    await nextFrame(page);
    expect(await red()).toBeGreaterThan(refusedColumns);
    expect(await page.locator(timeline).getAttribute("data-strokes")).toBe(String(strokes - 1));
    expect(Math.abs((await totalMs()) - after)).toBeLessThanOrEqual(1);
    await expect(page.locator('[data-testid="event-log"] li').first().innerText()).resolves.toContain(
      "Stroke 2 refused by the duty-cycle cap",
    );
    await expect(page.locator('[data-testid="timeline-caption"]').innerText()).resolves.toContain(
      "1 not felt (the sleeve's duty-cycle cap kept it from playing)",
    );
    await screenshot(page, "refused-and-capped");
  });

  it("lays the A/B comparison on the drawing it compares: a straight line on itself", async () => {
    const [left, right] = await newLine(0.15, 0.85);
    await page.locator('[data-testid="compare-toggle"]').check();
    await nextFrame(page);
    // Every layer of the stage covers it exactly.
    const boxes = await page.evaluate(() =>
      [...document.querySelectorAll<HTMLCanvasElement>("#stage canvas")].map((canvas) => {
        const { left, top, width, height } = canvas.getBoundingClientRect();
        return { layer: canvas.className, left, top, width, height };
      }),
    );
    const live = boxes.find((box) => box.layer === "live")!;
    for (const box of boxes) expect(box, box.layer).toEqual({ ...live, layer: box.layer });

    // And on the screen: the dashed B line is centred on the solid A line (the same straight stroke).
    const path = await screenshot(page, "compare-aligned");
    const rows = await page.evaluate(
      async ({ png, x0, x1, y, sent, compare }) => {
        const image = new Image();
        image.src = `data:image/png;base64,${png}`;
        await image.decode();
        const canvas = document.createElement("canvas");
        canvas.width = image.width;
        canvas.height = image.height;
        const ctx = canvas.getContext("2d")!;
        ctx.drawImage(image, 0, 0);
        const near = (d: Uint8ClampedArray, i: number, rgb: readonly number[]) =>
          Math.abs(d[i]! - rgb[0]!) <= 16 &&
          Math.abs(d[i + 1]! - rgb[1]!) <= 16 &&
          Math.abs(d[i + 2]! - rgb[2]!) <= 16;
        const mean = (rgb: readonly number[]) => {
          let sum = 0;
          let count = 0;
          for (let row = Math.round(y) - 20; row <= Math.round(y) + 20; row++) {
            const d = ctx.getImageData(Math.round(x0), row, Math.round(x1 - x0), 1).data;
            for (let i = 0; i < d.length; i += 4) {
              if (near(d, i, rgb)) {
                sum += row;
                count++;
              }
            }
          }
          return count === 0 ? null : sum / count;
        };
        return { a: mean(sent), b: mean(compare) };
      },
      {
        png: readFileSync(path).toString("base64"),
        x0: left[0] + 0.1 * (right[0] - left[0]),
        x1: left[0] + 0.9 * (right[0] - left[0]),
        y: left[1],
        sent: SENT_RGB,
        compare: COMPARE_RGB,
      },
    );
    expect(rows.a).not.toBeNull();
    expect(rows.b).not.toBeNull();
    expect(Math.abs(rows.b! - rows.a!), `B's row ${rows.b} against A's ${rows.a}`).toBeLessThanOrEqual(1);
    await page.locator('[data-testid="compare-toggle"]').uncheck();
  });
});
