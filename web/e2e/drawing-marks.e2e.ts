/**
 * What the drawing area does, in real Chromium: Esc with the pen down ends
 * the path there.
 */
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { FakeSleeve } from "./harness";
import { drawingArea, nextFrame, waitForData, walk } from "./page";
import { DESKTOP, Processes } from "./processes";

const STATUS_ONLINE = { online: true, layout: { rows: 3, columns: 4, spacing_cm: 3.0 }, version: "test" };
const SUMMARY = '[data-testid="played-summary"]';

type Point = readonly [number, number];

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

  /** Moves along the polyline from its first point, a step a frame. */
  async function moveAlong(points: readonly Point[]): Promise<void> {
    for (const [x, y] of walk(points, 8)) {
      await page.mouse.move(x, y);
      await nextFrame(page);
    }
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
});
