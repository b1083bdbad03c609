/**
 * The felt drawing, whole: one lane per actuator (row, column) against time,
 * each stroke's touch drawn as the intensity it gives each actuator
 * (felt.ts), with a cursor at the moment being felt. An A/B comparison
 * overlays a second drawing's lanes as outlines. Redrawn at most once per
 * animation frame; the cursor alone is cheap (a second canvas). The lanes'
 * picture is kept between frames (felt-raster.ts) and only what a new stroke
 * or report moved is painted again: a frame's cost does not grow with the drawing.
 */
import { totalMs, type Grid, type PlacedStroke } from "../felt";
import type { FeltPlacement } from "../felt-placement";
import { FrameRequest, fitToDevicePixels } from "./canvas-frame";
import { PlacementRaster, type LaneRaster } from "./felt-raster";

const LABEL_WIDTH_PX = 34;
const AXIS_HEIGHT_PX = 16;
const MIN_LABEL_GAP_PX = 44;
const COLORS = {
  a: "255, 138, 91",
  b: "94, 200, 255",
  lane: "rgba(143, 160, 178, 0.08)",
  label: "rgba(143, 160, 178, 0.8)",
  cursor: "#ffd166",
} as const;

export class TimelineView {
  readonly #canvas: HTMLCanvasElement;
  readonly #cursorCanvas: HTMLCanvasElement;
  readonly #caption: HTMLElement;
  readonly #ctx: CanvasRenderingContext2D;
  readonly #cursorCtx: CanvasRenderingContext2D;
  #grid: Grid = { rows: 3, columns: 4 };
  readonly #a = new PlacementRaster((stroke, intensity) => (stroke.reported ? 0.3 : 0.15) + 0.7 * intensity);
  readonly #b = new PlacementRaster((_stroke, intensity) => 0.25 + 0.6 * intensity);
  #bShown: readonly PlacedStroke[] | null = null;
  #aTotalMs = 0;
  #bTotalMs = 0;
  /** One row per lane, one pixel per column: the lanes as drawn, stretched to their height. */
  readonly #rows = document.createElement("canvas");
  #column = new Float32Array(0);
  #image: ImageData | null = null;
  #cursorMs: number | null = null;
  readonly #redraw = new FrameRequest(() => {
    this.#draw();
    this.#drawCursor();
  });

  constructor(canvas: HTMLCanvasElement, cursor: HTMLCanvasElement, caption: HTMLElement) {
    this.#canvas = canvas;
    this.#cursorCanvas = cursor;
    this.#caption = caption;
    this.#ctx = context(canvas);
    this.#cursorCtx = context(cursor);
    new ResizeObserver(() => this.#redraw.request()).observe(canvas);
  }

  /** The drawing to show (A), and the one to compare it with (B) or null. */
  show(grid: Grid, a: FeltPlacement, b: readonly PlacedStroke[] | null = null): void {
    this.#grid = grid;
    this.#a.sync(a, grid);
    this.#aTotalMs = a.totalMs;
    if (b !== this.#bShown) {
      this.#bShown = b;
      if (b !== null) this.#b.paintAll(b, grid);
      this.#bTotalMs = b === null ? 0 : totalMs(b);
    }
    this.#canvas.dataset["grid"] = `${grid.rows}x${grid.columns}`;
    this.#canvas.dataset["strokes"] = String(a.placed.length);
    this.#canvas.dataset["compare"] = b === null ? "off" : String(b.length);
    this.#canvas.dataset["totalMs"] = String(Math.round(this.totalMs));
    this.#redraw.request();
  }

  get totalMs(): number {
    return Math.max(this.#aTotalMs, this.#bShown === null ? 0 : this.#bTotalMs);
  }

  /** The moment being felt (ms on the timeline), or null to hide the cursor. */
  setCursor(t_ms: number | null): void {
    if (t_ms === this.#cursorMs) return;
    this.#cursorMs = t_ms;
    this.#canvas.dataset["cursorMs"] = t_ms === null ? "" : String(Math.round(t_ms));
    this.#drawCursor();
  }

  setCaption(text: string): void {
    this.#caption.textContent = text;
  }

  #lane(row: number, column: number, height: number): { top: number; height: number } {
    const lanes = this.#grid.rows * this.#grid.columns;
    const laneHeight = (height - AXIS_HEIGHT_PX) / Math.max(lanes, 1);
    return { top: (row * this.#grid.columns + column) * laneHeight, height: laneHeight };
  }

  #draw(): void {
    const { width, height, dpr } = fitToDevicePixels(this.#canvas);
    if (width === 0 || height === 0) return;
    const ctx = this.#ctx;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, width, height);
    const { rows, columns } = this.#grid;
    const total = Math.max(this.totalMs, 1);
    const plotWidth = width - LABEL_WIDTH_PX;
    ctx.font = "10px system-ui, sans-serif";
    ctx.textBaseline = "middle";
    for (let row = 0; row < rows; row++) {
      for (let column = 0; column < columns; column++) {
        const lane = this.#lane(row, column, height);
        ctx.fillStyle = (row * columns + column) % 2 === 0 ? COLORS.lane : "transparent";
        ctx.fillRect(LABEL_WIDTH_PX, lane.top, plotWidth, lane.height);
        if (lane.height >= 9) {
          ctx.fillStyle = COLORS.label;
          ctx.fillText(`${row},${column}`, 4, lane.top + lane.height / 2);
        }
      }
    }
    // Device pixels across: as sharp as the rectangles per 10 ms once drawn.
    const pixels = Math.max(1, Math.round(plotWidth * dpr));
    const lanes = (raster: LaneRaster, rgb: string, outline: boolean) =>
      this.#paintLanes(ctx, raster, rgb, outline, total, pixels, plotWidth, height);
    lanes(this.#a.raster, COLORS.a, false);
    if (this.#bShown !== null) lanes(this.#b.raster, COLORS.b, true);
    // The time axis: whole seconds (or tenths for a short drawing).
    ctx.fillStyle = COLORS.label;
    // Labels at least MIN_LABEL_GAP_PX apart, on a round step (0.1, 0.2, 0.5, 1, 2, 5... s).
    const steps = [100, 200, 500, 1000, 2000, 5000, 10_000, 20_000, 60_000];
    const tick = steps.find((step) => (step / total) * plotWidth >= MIN_LABEL_GAP_PX) ?? 120_000;
    for (let t = 0; t <= total; t += tick) {
      const x = LABEL_WIDTH_PX + (t / total) * plotWidth;
      ctx.fillRect(x, height - AXIS_HEIGHT_PX, 1, 4);
      // The last label would be cut at the right edge: its tick alone says enough.
      if (x + MIN_LABEL_GAP_PX <= width)
        ctx.fillText(`${(t / 1000).toFixed(tick >= 1000 ? 0 : 1)} s`, x + 2, height - 6);
    }
  }

  /** Every lane of `raster` from its bins, one row of pixels each, stretched to the lane. */
  #paintLanes(
    ctx: CanvasRenderingContext2D,
    raster: LaneRaster,
    rgb: string,
    outline: boolean,
    total: number,
    columns: number,
    plotWidth: number,
    height: number,
  ): void {
    const { rows, columns: gridColumns } = this.#grid;
    const lanes = rows * gridColumns;
    if (lanes === 0 || raster.lanes !== lanes) return;
    if (this.#rows.width !== columns || this.#rows.height !== lanes) {
      this.#rows.width = columns;
      this.#rows.height = lanes;
    }
    if (this.#column.length < columns) this.#column = new Float32Array(columns);
    const rowsCtx = this.#rows.getContext("2d");
    if (rowsCtx === null) return;
    // One image kept for every frame of this size: no allocation per frame.
    if (this.#image === null || this.#image.width !== columns || this.#image.height !== lanes) {
      this.#image = rowsCtx.createImageData(columns, lanes);
    }
    const image = this.#image;
    image.data.fill(0);
    const [r, g, b] = rgb.split(",").map((part) => Number(part.trim())) as [number, number, number];
    for (let lane = 0; lane < lanes; lane++) {
      raster.columns(lane, total, columns, this.#column);
      let at = lane * columns * 4;
      for (let column = 0; column < columns; column++, at += 4) {
        const value = this.#column[column]!;
        if (value === 0) continue;
        image.data[at] = r;
        image.data[at + 1] = g;
        image.data[at + 2] = b;
        image.data[at + 3] = Math.round(Math.min(value, 1) * 255);
      }
    }
    rowsCtx.putImageData(image, 0, 0);
    ctx.save();
    ctx.imageSmoothingEnabled = false;
    for (let row = 0; row < rows; row++) {
      for (let column = 0; column < gridColumns; column++) {
        const lane = this.#lane(row, column, height);
        const top = outline ? lane.top + lane.height * 0.7 : lane.top + 1;
        const laneHeight = lane.height * (outline ? 0.25 : 0.62);
        const index = row * gridColumns + column;
        ctx.drawImage(this.#rows, 0, index, columns, 1, LABEL_WIDTH_PX, top, plotWidth, laneHeight);
      }
    }
    ctx.restore();
  }

  #drawCursor(): void {
    const { width, height, dpr } = fitToDevicePixels(this.#cursorCanvas);
    const ctx = this.#cursorCtx;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, width, height);
    if (this.#cursorMs === null || width === 0) return;
    const total = Math.max(this.totalMs, 1);
    const x = LABEL_WIDTH_PX + (Math.min(this.#cursorMs, total) / total) * (width - LABEL_WIDTH_PX);
    ctx.fillStyle = COLORS.cursor;
    ctx.fillRect(x - 1, 0, 2, height - AXIS_HEIGHT_PX);
  }
}

function context(canvas: HTMLCanvasElement): CanvasRenderingContext2D {
  const ctx = canvas.getContext("2d");
  if (ctx === null) throw new Error("This browser cannot draw on a canvas (no 2D context).");
  return ctx;
}
