/**
 * What the window simplifier guarantees about the strokes a drawing is sent
 * as, checked against the path the test drew; the bounds come from the page's
 * own settings, so a test asserts the guarantee, not what one machine happened
 * to produce.
 *
 * The guarantees (src/simplify/window.ts):
 * - every stroke starts and ends at a drawn sample, or within LINE_SHARE x
 *   max_error of one: where a line the latency cap cut goes on along the line
 *   of the stroke before, its end is its sample projected onto that line, so a
 *   straight line stays straight (src/simplify/window.ts);
 * - every drawn sample lies within max_error of its piece of the path (sent
 *   or dropped), and the pieces join end to start, from the press to the
 *   release: so within max_error of the chain press -> strokes -> release;
 * - a dropped piece is shorter than min_length (the latency cap never cuts one
 *   off, and samples a frame apart make none too brief), so the first stroke
 *   starts within min_length of the press and the last ends within min_length
 *   (a dropped piece) or LINE_SHARE x max_error (a line going on) of the release;
 * - a corner of the drawn path is within max_error of a stroke's end: the
 *   window cuts at the sample farthest from its chord, the corner, unless the
 *   latency cap cut just before it, and the cap cuts there only when the
 *   stroke bends by less than half max_error, which leaves the corner at most
 *   0.71 max_error from the nearer end.
 * Not guaranteed: where along the path the latency cap cuts (it depends on
 * the machine's speed), so how many strokes, and how near a corner the cut is.
 */
import type { Page } from "playwright-core";
import { expect } from "vitest";
import { loadSettings, STORAGE_KEY } from "../src/settings";
import { LINE_SHARE } from "../src/simplify/window";
import { drawingArea, drawWithMouse, nextFrame, toGrid, walk, type Area } from "./page";

type Point = readonly [number, number];

/** The pointer coordinates the page reads may be rounded to the pixel: drawn points move that much. */
const POINTER_SLACK_PX = 1;

export interface StrokeBounds {
  /** The page's max_error, grid units. */
  readonly maxError: number;
  /** The page's min_length, grid units: the longest gap a dropped piece leaves. */
  readonly minLength: number;
  /** POINTER_SLACK_PX in grid units. */
  readonly slack: number;
  /** How far a stroke's end may lie from its drawn sample: LINE_SHARE x max_error. */
  readonly moved: number;
}

/** The bounds the page's window simplifier keeps, from the settings it has stored (or its defaults). */
export async function strokeBounds(page: Page, area: Area): Promise<StrokeBounds> {
  const stored = await page.evaluate((key) => localStorage.getItem(key), STORAGE_KEY);
  const { settings } = loadSettings({ getItem: () => stored }, null);
  if (settings.algorithm !== "window") {
    throw new Error(`these checks hold for the window simplifier; the page uses '${settings.algorithm}'`);
  }
  const [x0, y0] = toGrid(area, area.left, area.top);
  const [x1, y1] = toGrid(area, area.left + POINTER_SLACK_PX, area.top + POINTER_SLACK_PX);
  return {
    maxError: settings.max_error,
    minLength: settings.min_length,
    slack: Math.hypot(x1 - x0, y1 - y0),
    moved: LINE_SHARE * settings.max_error,
  };
}

/** Distance from a point to the segment a -> b. */
export function segmentDistance(point: Point, a: Point, b: Point): number {
  const [dx, dy] = [b[0] - a[0], b[1] - a[1]];
  const lengthSq = dx * dx + dy * dy;
  const t =
    lengthSq === 0
      ? 0
      : Math.min(Math.max(((point[0] - a[0]) * dx + (point[1] - a[1]) * dy) / lengthSq, 0), 1);
  return Math.hypot(point[0] - a[0] - t * dx, point[1] - a[1] - t * dy);
}

/** Distance from a point to a polyline (its nearest segment). */
function polylineDistance(point: Point, polyline: readonly Point[]): number {
  if (polyline.length === 1) return Math.hypot(point[0] - polyline[0]![0], point[1] - polyline[0]![1]);
  let nearest = Infinity;
  for (let i = 1; i < polyline.length; i++) {
    nearest = Math.min(nearest, segmentDistance(point, polyline[i - 1]!, polyline[i]!));
  }
  return nearest;
}

function describe(point: Point): string {
  return `(${point[0].toFixed(3)}, ${point[1].toFixed(3)})`;
}

/**
 * Asserts the guarantees above for `strokes`, sent for the path drawn through
 * `pathPx` (viewport pixels: the press, the corners, the release) in steps of
 * `stepPx`, as `drawWithMouse` and `drawWithTouch` draw it.
 */
export function expectStrokesFollow(
  strokes: readonly Record<string, unknown>[],
  pathPx: readonly Point[],
  area: Area,
  bounds: StrokeBounds,
  stepPx = 5,
): void {
  expect(strokes.length, "strokes sent").toBeGreaterThan(0);
  const grid = (point: Point): Point => toGrid(area, point[0], point[1]);
  const path = pathPx.map(grid);
  const samples = [pathPx[0]!, ...walk(pathPx, stepPx)].map(grid);
  const ends = strokes.flatMap((stroke) => [stroke["start"] as Point, stroke["end"] as Point]);

  for (const [i, end] of ends.entries()) {
    const off = polylineDistance(end, path);
    expect(
      off,
      `stroke ${i >> 1}'s ${i % 2 ? "end" : "start"} ${describe(end)} is at a drawn sample`,
    ).toBeLessThanOrEqual(bounds.moved + bounds.slack);
  }

  const press = path[0]!;
  const release = path.at(-1)!;
  const first = ends[0]!;
  const last = ends.at(-1)!;
  const gap = bounds.minLength + bounds.slack;
  expect(
    Math.hypot(first[0] - press[0], first[1] - press[1]),
    `first start ${describe(first)} at the press`,
  ).toBeLessThan(gap);
  expect(
    Math.hypot(last[0] - release[0], last[1] - release[1]),
    `last end ${describe(last)} at the release`,
  ).toBeLessThan(Math.max(bounds.minLength, bounds.moved) + bounds.slack);

  const chain = [press, ...ends, release];
  const farthest = Math.max(...samples.map((sample) => polylineDistance(sample, chain)));
  expect(farthest, "farthest drawn sample from the strokes sent").toBeLessThanOrEqual(
    bounds.maxError + bounds.slack,
  );

  for (const corner of path.slice(1, -1)) {
    const nearest = Math.min(...ends.map(([x, y]) => Math.hypot(x - corner[0], y - corner[1])));
    expect(nearest, `corner ${describe(corner)}: nearest stroke end`).toBeLessThanOrEqual(
      bounds.maxError + bounds.slack,
    );
  }
}

/** A square in the middle of the area, 0.6 of its height a side: the press, its four corners and back. */
export function squarePath(area: Area): Point[] {
  const side = area.height * 0.6;
  const left = area.left + (area.width - side) / 2;
  const top = area.top + (area.height - side) / 2;
  const corners: Point[] = [
    [left, top],
    [left + side, top],
    [left + side, top + side],
    [left, top + side],
  ];
  return [...corners, corners[0]!];
}

/**
 * Draws `squarePath` with the mouse and resolves, a frame after the release (every stroke
 * leaves on release at the latest), with the area, the path and how many strokes the page
 * sent: four or more, checked, as a long side may be cut by the latency cap.
 */
export async function drawSquare(
  page: Page,
  options: Parameters<typeof drawWithMouse>[2] = {},
): Promise<{ area: Area; path: Point[]; sent: number }> {
  const area = await drawingArea(page);
  const path = squarePath(area);
  await drawWithMouse(page, path, options);
  await nextFrame(page);
  const sent = Number(await page.locator('[data-testid="played-summary"]').getAttribute("data-sent"));
  expect(sent, "strokes sent for the square's four sides").toBeGreaterThanOrEqual(4);
  return { area, path, sent };
}
