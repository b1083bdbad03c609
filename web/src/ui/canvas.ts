/**
 * The drawing surface, rendered incrementally so that the cost of a frame
 * does not grow with the drawing (the paper's sketch redrew every stroke on
 * every frame). Three stacked canvases:
 *
 *   grid  the sleeve's actuators, faint; redrawn only when the size or grid changes
 *   ink   finished content: the raw path (faint), strokes waiting for the broker
 *         (dim) and sent ones (solid, drawn over the dim line on PUBACK), dropped
 *         ones (dashed red), strokes the sleeve refused (dotted red, a cross) or that
 *         Stop cancelled or kept from leaving (dotted grey); only the new bits are
 *         drawn each frame, and everything only on a resize or a new drawing
 *   compare  the same paths under the A/B comparison's settings (dashed), when shown
 *   marker   where the brush is on the sleeve now, while a drawing is felt
 *   live  the stroke being drawn, highlighted; cleared and redrawn alone each frame
 *
 * Coordinates: the simplifier sees the drawing's own canvas pixels (fixed when
 * the drawing starts); the screen may be resized since, so they are scaled.
 * Those pixels are always in the sleeve's orientation. On a screen of the
 * other shape (a phone held upright, a landscape sleeve) the area is shown
 * turned a quarter clockwise: the sleeve's top edge on the right, marked there.
 * One transform per canvas does the turn, so every drawing step is the same
 * either way, and `toDrawing` undoes it for the pointer.
 */
import type { Drawing, DrawnSegment } from "../drawing";
import type { Point, Sample } from "../simplify/segment";
import {
  AREA_MARGIN_PX,
  chooseArea,
  gridToCanvas,
  type AreaSize,
  type GridSize,
  type MappingShape,
} from "./geometry";

const COLORS = {
  grid: "rgba(143, 160, 178, 0.13)",
  actuatorFill: "rgba(143, 160, 178, 0.10)",
  actuatorRing: "rgba(143, 160, 178, 0.38)",
  raw: "rgba(231, 237, 243, 0.24)",
  sent: "#ff8a5b",
  waiting: "rgba(255, 138, 91, 0.35)",
  live: "#ffd166",
  compare: "#5ec8ff",
  marker: "#ffd166",
  dropped: "#ff6b6b",
  rejected: "#ff6b6b",
  /** Cancelled by Stop, or never sent: not felt, but nothing went wrong. */
  cancelled: "rgba(143, 160, 178, 0.7)",
  /** Held on the page while the wearer paused: not sent yet, may be sent on resume. */
  held: "#c792ea",
  topEdge: "rgba(255, 138, 91, 0.75)",
  /** The stage's own colour (--surface): a refused stroke is first wiped out with it. */
  erase: "#151d26",
} as const;

const ACTUATOR_RADIUS_PX = 7;
const SENT_WIDTH_PX = 4;
const LIVE_WIDTH_PX = 5;

export type { AreaSize } from "./geometry";

export class DrawingView {
  readonly stage: HTMLElement;
  /** The surface that takes the pointer; carries data-testid="drawing-canvas". */
  readonly surface: HTMLCanvasElement;
  readonly #gridCanvas: HTMLCanvasElement;
  readonly #inkCanvas: HTMLCanvasElement;
  readonly #compareCanvas: HTMLCanvasElement;
  readonly #markerCanvas: HTMLCanvasElement;
  readonly #grid2d: CanvasRenderingContext2D;
  readonly #ink2d: CanvasRenderingContext2D;
  readonly #compare2d: CanvasRenderingContext2D;
  readonly #marker2d: CanvasRenderingContext2D;
  #compareSegments: readonly (readonly [Point, Point])[] | null = null;
  readonly #live2d: CanvasRenderingContext2D;
  #grid: GridSize = { rows: 3, columns: 4 };
  #stretch = false;
  /** The area in the sleeve's orientation: a new drawing's canvas. */
  #area: AreaSize = { width_px: 300, height_px: 200 };
  /** Shown turned a quarter clockwise (the sleeve's top edge on the right). */
  #turned = false;
  #dpr = 1;
  #drawing: Drawing | null = null;
  /** Per path, how many samples are already on the ink canvas. */
  #rawDrawn: number[] = [];
  #rawPathFrom = 0;
  #segmentsDrawn = 0;
  /** Strokes refused since the last flush, to mark over their line. */
  #rejected: DrawnSegment[] = [];
  /** Strokes acknowledged since the last flush, to draw solid over their dim line. */
  #acked: DrawnSegment[] = [];
  #liveShown = false;
  /** Canvas rectangle at the press: pointer moves are converted without a layout read each. */
  #pointerRect: DOMRect | null = null;

  constructor(stage: HTMLElement) {
    this.stage = stage;
    this.#gridCanvas = this.#addCanvas("grid");
    this.#inkCanvas = this.#addCanvas("ink");
    this.#compareCanvas = this.#addCanvas("compare");
    this.#markerCanvas = this.#addCanvas("marker");
    this.surface = this.#addCanvas("live");
    this.surface.dataset["testid"] = "drawing-canvas";
    this.surface.setAttribute("role", "img");
    this.surface.setAttribute("aria-label", "Drawing area: draw with a finger, pen or mouse");
    this.#grid2d = context(this.#gridCanvas);
    this.#ink2d = context(this.#inkCanvas);
    this.#compare2d = context(this.#compareCanvas);
    this.#marker2d = context(this.#markerCanvas);
    this.#live2d = context(this.surface);
  }

  #addCanvas(name: string): HTMLCanvasElement {
    const canvas = document.createElement("canvas");
    canvas.className = name;
    this.stage.append(canvas);
    return canvas;
  }

  /** The drawing area's size in CSS pixels now: a new drawing's canvas. */
  get area(): AreaSize {
    return this.#area;
  }

  get grid(): GridSize {
    return this.#grid;
  }

  /** Sleeve-oriented drawing pixels are shown turned a quarter (see the module's comment). */
  get turned(): boolean {
    return this.#turned;
  }

  /**
   * Sizes the stage to the largest area of the grid's aspect ratio that fits,
   * turned a quarter when that is much larger (a landscape sleeve on an upright phone).
   */
  fit(grid: GridSize, stretch: boolean, availableWidthPx: number, availableHeightPx: number): void {
    const { area, turned } = chooseArea(grid, availableWidthPx, availableHeightPx);
    const dpr = window.devicePixelRatio || 1;
    const same =
      area.width_px === this.#area.width_px &&
      area.height_px === this.#area.height_px &&
      turned === this.#turned &&
      grid.rows === this.#grid.rows &&
      grid.columns === this.#grid.columns &&
      stretch === this.#stretch &&
      dpr === this.#dpr;
    if (same) return;
    this.#grid = grid;
    this.#stretch = stretch;
    this.#area = area;
    this.#turned = turned;
    this.#dpr = dpr;
    const screen = this.#screenArea();
    const widthPx = screen.width_px + 2 * AREA_MARGIN_PX;
    const heightPx = screen.height_px + 2 * AREA_MARGIN_PX;
    this.stage.style.width = `${widthPx}px`;
    this.stage.style.height = `${heightPx}px`;
    const canvases = [
      this.#gridCanvas,
      this.#inkCanvas,
      this.#compareCanvas,
      this.#markerCanvas,
      this.surface,
    ];
    for (const canvas of canvases) {
      // Backing store in device pixels: sharp lines on HiDPI screens.
      canvas.width = Math.round(widthPx * dpr);
      canvas.height = Math.round(heightPx * dpr);
    }
    // Sleeve-oriented area pixels -> device pixels: the margin, the quarter turn, the density.
    const m = AREA_MARGIN_PX;
    for (const ctx of [this.#grid2d, this.#ink2d, this.#compare2d, this.#marker2d, this.#live2d]) {
      setSleeveTransform(ctx, turned, screen.width_px, m, dpr);
      ctx.lineCap = "round";
      ctx.lineJoin = "round";
    }
    const data = this.surface.dataset;
    data["areaLeftPx"] = String(m);
    data["areaTopPx"] = String(m);
    data["areaWidthPx"] = String(screen.width_px);
    data["areaHeightPx"] = String(screen.height_px);
    // How the tests (and anyone reading the page) convert a screen point to the sleeve's grid.
    data["areaTurnDeg"] = turned ? "90" : "0";
    this.stage.dataset["turned"] = String(turned);
    this.surface.setAttribute(
      "aria-label",
      turned
        ? "Drawing area, turned a quarter to fit the screen (the sleeve's top is on the right): draw with a finger, pen or mouse"
        : "Drawing area: draw with a finger, pen or mouse",
    );
    this.#drawGrid();
    this.#redrawInk();
    this.#drawCompare();
    this.#liveShown = true;
    this.clearLive();
  }

  /** The area as laid out on the screen (CSS pixels). */
  #screenArea(): AreaSize {
    const { width_px, height_px } = this.#area;
    return this.#turned ? { width_px: height_px, height_px: width_px } : this.#area;
  }

  /** Shows `drawing` from scratch (a new or cleared drawing, or null for an empty canvas). */
  setDrawing(drawing: Drawing | null): void {
    this.#drawing = drawing;
    this.#rejected = [];
    this.#acked = [];
    this.#redrawInk();
  }

  /** The A/B comparison's strokes (grid units, the drawing's mapping), or null to hide them. */
  setCompare(segments: readonly (readonly [Point, Point])[] | null): void {
    this.#compareSegments = segments;
    this.#drawCompare();
  }

  /** Where the brush is on the sleeve now (grid units), or null. */
  drawMarker(point: Point | null): void {
    const ctx = this.#marker2d;
    clear(ctx);
    const shape = this.#segmentShape();
    this.surface.dataset["marker"] = point === null ? "" : `${point[0].toFixed(2)},${point[1].toFixed(2)}`;
    if (point === null || shape === null) return;
    const [x, y] = this.#gridToCss(point[0], point[1], shape);
    ctx.save();
    ctx.shadowColor = COLORS.marker;
    ctx.shadowBlur = 18;
    ctx.strokeStyle = COLORS.marker;
    ctx.lineWidth = 3;
    ctx.beginPath();
    ctx.arc(x, y, 11, 0, 2 * Math.PI);
    ctx.stroke();
    ctx.restore();
  }

  #drawCompare(): void {
    const ctx = this.#compare2d;
    clear(ctx);
    const shape = this.#segmentShape();
    if (this.#compareSegments === null || shape === null) return;
    ctx.save();
    ctx.strokeStyle = COLORS.compare;
    ctx.lineWidth = 2.5;
    ctx.setLineDash([8, 5]);
    for (const [start, end] of this.#compareSegments) {
      ctx.beginPath();
      ctx.moveTo(...this.#gridToCss(start[0], start[1], shape));
      ctx.lineTo(...this.#gridToCss(end[0], end[1], shape));
      ctx.stroke();
    }
    ctx.restore();
  }

  /** A stroke the broker acknowledged: drawn solid on the next flush. */
  markSent(drawn: DrawnSegment): void {
    this.#acked.push(drawn);
  }

  /**
   * A stroke the sleeve refused (`Drawing.markRefused`), or one held on the page (`Drawing.markHeld`):
   * marked on the next flush, and kept so.
   */
  markRejected(drawn: DrawnSegment): void {
    this.#rejected.push(drawn);
  }

  /** Draws what is new since the last flush: the cost is that of the new bits alone. */
  flush(): void {
    const drawing = this.#drawing;
    if (drawing === null) return;
    const ctx = this.#ink2d;
    // Only paths from the one drawn last can have new samples: earlier ones are finished.
    for (let path = this.#rawPathFrom; path < drawing.paths.length; path++) {
      const samples = drawing.paths[path]!;
      const drawn = this.#rawDrawn[path] ?? 0;
      if (samples.length > drawn) {
        this.#drawRaw(ctx, samples, Math.max(0, drawn - 1));
        this.#rawDrawn[path] = samples.length;
      }
    }
    this.#rawPathFrom = Math.max(0, drawing.paths.length - 1);
    const segments = drawing.segments;
    // Segments drawn before this flush: the new ones are drawn as they stand now.
    const drawnBefore = this.#segmentsDrawn;
    for (; this.#segmentsDrawn < segments.length; this.#segmentsDrawn++) {
      const drawn = segments[this.#segmentsDrawn]!;
      if (drawing.isRefused(drawn) || drawing.isHeld(drawn)) this.#drawRejected(ctx, drawn);
      else this.#drawSegment(ctx, drawn, drawing.isAcked(drawn));
    }
    for (const drawn of this.#acked.splice(0)) {
      // A refused stroke stays marked refused, whenever the broker's acknowledgement comes.
      // A held stroke sent on resume is drawn over its narrower held dashes.
      if (drawn.index < drawnBefore && !drawing.isRefused(drawn)) this.#drawSegment(ctx, drawn, true);
    }
    for (const drawn of this.#rejected.splice(0)) {
      if (drawn.index < drawnBefore) this.#drawRejected(ctx, drawn);
    }
  }

  /** The line being drawn, from its start to the pointer, highlighted. */
  drawLive(lineStart: Sample | null, pointer: Sample | null): void {
    const ctx = this.#live2d;
    this.clearLive();
    if (pointer === null) return;
    const [px, py] = this.#toCss(pointer.x, pointer.y);
    ctx.save();
    if (lineStart !== null) {
      const [sx, sy] = this.#toCss(lineStart.x, lineStart.y);
      ctx.shadowColor = COLORS.live;
      ctx.shadowBlur = 14;
      ctx.strokeStyle = COLORS.live;
      ctx.lineWidth = LIVE_WIDTH_PX;
      ctx.beginPath();
      ctx.moveTo(sx, sy);
      ctx.lineTo(px, py);
      ctx.stroke();
    }
    ctx.fillStyle = COLORS.live;
    ctx.beginPath();
    ctx.arc(px, py, 6, 0, 2 * Math.PI);
    ctx.fill();
    ctx.restore();
    this.#liveShown = true;
  }

  clearLive(): void {
    if (!this.#liveShown) return;
    clear(this.#live2d);
    this.#liveShown = false;
  }

  /** Remembers the surface's position for the pointer conversions of one path. */
  beginPointer(): void {
    this.#pointerRect = this.surface.getBoundingClientRect();
  }

  /** A pointer position (client pixels) in the drawing's canvas pixels (the sleeve's orientation). */
  toDrawing(clientX: number, clientY: number): [number, number] {
    const rect = this.#pointerRect ?? this.surface.getBoundingClientRect();
    const k = this.#drawingScale();
    const u = clientX - rect.left - AREA_MARGIN_PX;
    const v = clientY - rect.top - AREA_MARGIN_PX;
    // The inverse of the quarter turn in `fit`: down the screen is along the sleeve's columns.
    const [x, y] = this.#turned ? [v, this.#area.height_px - u] : [u, v];
    return [x / k, y / k];
  }

  /** CSS pixels per drawing pixel: 1 unless the screen was resized since the drawing began. */
  #drawingScale(): number {
    const width = this.#drawing?.params.canvas_width_px;
    return width === undefined ? 1 : this.#area.width_px / width;
  }

  /** Drawing pixels -> area pixels (the contexts' transform places them on the screen). */
  #toCss(x: number, y: number): [number, number] {
    const k = this.#drawingScale();
    return [x * k, y * k];
  }

  #gridToCss(gx: number, gy: number, shape: MappingShape): [number, number] {
    const [x, y] = gridToCanvas(gx, gy, shape);
    const k = this.#area.width_px / shape.width_px;
    return [x * k, y * k];
  }

  #drawGrid(): void {
    const ctx = this.#grid2d;
    const { rows, columns } = this.#grid;
    clear(ctx);
    const shape: MappingShape = { ...this.#area, rows, columns, stretch: this.#stretch };
    const at = (column: number, row: number) => this.#gridToCss(column, row, shape);
    ctx.strokeStyle = COLORS.grid;
    ctx.lineWidth = 1;
    ctx.beginPath();
    for (let row = 0; row < rows; row++) {
      ctx.moveTo(...at(0, row));
      ctx.lineTo(...at(columns - 1, row));
    }
    for (let column = 0; column < columns; column++) {
      ctx.moveTo(...at(column, 0));
      ctx.lineTo(...at(column, rows - 1));
    }
    ctx.stroke();
    for (let row = 0; row < rows; row++) {
      for (let column = 0; column < columns; column++) {
        const [x, y] = at(column, row);
        ctx.beginPath();
        ctx.arc(x, y, ACTUATOR_RADIUS_PX, 0, 2 * Math.PI);
        ctx.fillStyle = COLORS.actuatorFill;
        ctx.fill();
        ctx.strokeStyle = COLORS.actuatorRing;
        ctx.lineWidth = 1.5;
        ctx.stroke();
      }
    }
    if (this.#turned) drawSleeveTop(ctx, this.#area.width_px, -AREA_MARGIN_PX / 2);
  }

  #redrawInk(): void {
    clear(this.#ink2d);
    this.#rawDrawn = [];
    this.#rawPathFrom = 0;
    this.#segmentsDrawn = 0;
    // Everything is drawn again as the drawing stands: acknowledged solid, refused marked.
    this.#acked = [];
    this.#rejected = [];
    this.flush();
  }

  #drawRaw(ctx: CanvasRenderingContext2D, samples: readonly Sample[], from: number): void {
    const first = samples[from]!;
    ctx.strokeStyle = COLORS.raw;
    ctx.lineWidth = 1.5;
    ctx.setLineDash([]);
    ctx.beginPath();
    ctx.moveTo(...this.#toCss(first.x, first.y));
    if (samples.length - from === 1) {
      ctx.lineTo(...this.#toCss(first.x + 0.01, first.y)); // a dot for a single sample
    }
    for (let i = from + 1; i < samples.length; i++) {
      const sample = samples[i]!;
      ctx.lineTo(...this.#toCss(sample.x, sample.y));
    }
    ctx.stroke();
  }

  #segmentShape(): MappingShape | null {
    const params = this.#drawing?.params;
    if (params === undefined) return null;
    return {
      width_px: params.canvas_width_px,
      height_px: params.canvas_height_px,
      rows: params.rows,
      columns: params.columns,
      stretch: params.stretch,
    };
  }

  #segmentEnds({ segment }: DrawnSegment): [[number, number], [number, number]] | null {
    const shape = this.#segmentShape();
    if (shape === null) return null;
    return [
      this.#gridToCss(segment.start[0], segment.start[1], shape),
      this.#gridToCss(segment.end[0], segment.end[1], shape),
    ];
  }

  #drawSegment(ctx: CanvasRenderingContext2D, drawn: DrawnSegment, sent: boolean): void {
    const ends = this.#segmentEnds(drawn);
    if (ends === null) return;
    const [[x0, y0], [x1, y1]] = ends;
    const color = sent ? COLORS.sent : COLORS.waiting;
    ctx.save();
    if (drawn.segment.dropped === null) {
      ctx.strokeStyle = color;
      ctx.lineWidth = SENT_WIDTH_PX;
    } else {
      ctx.strokeStyle = COLORS.dropped;
      ctx.lineWidth = 2;
      ctx.setLineDash([5, 5]);
    }
    ctx.beginPath();
    ctx.moveTo(x0, y0);
    ctx.lineTo(x1, y1);
    ctx.stroke();
    if (drawn.segment.dropped === null) {
      // The joints: where one stroke hands over to the next.
      ctx.fillStyle = color;
      for (const [x, y] of ends) {
        ctx.beginPath();
        ctx.arc(x, y, SENT_WIDTH_PX * 0.9, 0, 2 * Math.PI);
        ctx.fill();
      }
    }
    ctx.restore();
  }

  /** Paints the stage's own colour over a stroke: what is drawn next replaces its mark. */
  #wipe(ctx: CanvasRenderingContext2D, drawn: DrawnSegment): void {
    const ends = this.#segmentEnds(drawn);
    if (ends === null) return;
    const [[x0, y0], [x1, y1]] = ends;
    ctx.save();
    ctx.strokeStyle = COLORS.erase;
    ctx.lineWidth = SENT_WIDTH_PX + 2;
    ctx.beginPath();
    ctx.moveTo(x0, y0);
    ctx.lineTo(x1, y1);
    ctx.stroke();
    ctx.restore();
  }

  #drawRejected(ctx: CanvasRenderingContext2D, drawn: DrawnSegment): void {
    const ends = this.#segmentEnds(drawn);
    if (ends === null) return;
    const [[x0, y0], [x1, y1]] = ends;
    const refused = this.#drawing?.unfelt(drawn) === "refused";
    this.#wipe(ctx, drawn);
    ctx.save();
    // Held while the wearer paused: violet dashes, as the legend's "held, not sent". Cancelled
    // by Stop or never sent: dotted grey, no cross (the sleeve refused nothing).
    const [color, width, dash] = refused
      ? [COLORS.rejected, SENT_WIDTH_PX, [2, 7]]
      : this.#drawing?.isHeld(drawn) === true
        ? [COLORS.held, SENT_WIDTH_PX - 1, [9, 6]]
        : [COLORS.cancelled, SENT_WIDTH_PX - 1, [2, 6]];
    ctx.strokeStyle = color;
    ctx.lineWidth = width;
    ctx.setLineDash(dash);
    ctx.beginPath();
    ctx.moveTo(x0, y0);
    ctx.lineTo(x1, y1);
    ctx.stroke();
    if (!refused) {
      ctx.restore();
      return;
    }
    // A cross at the middle: refused, not merely thin.
    const mx = (x0 + x1) / 2;
    const my = (y0 + y1) / 2;
    ctx.setLineDash([]);
    ctx.lineWidth = 2.5;
    ctx.beginPath();
    ctx.moveTo(mx - 6, my - 6);
    ctx.lineTo(mx + 6, my + 6);
    ctx.moveTo(mx + 6, my - 6);
    ctx.lineTo(mx - 6, my + 6);
    ctx.stroke();
    ctx.restore();
  }
}

/** Clears the whole canvas, whatever the context's transform. */
function clear(ctx: CanvasRenderingContext2D): void {
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.clearRect(0, 0, ctx.canvas.width, ctx.canvas.height);
  ctx.restore();
}

function context(canvas: HTMLCanvasElement): CanvasRenderingContext2D {
  const ctx = canvas.getContext("2d");
  if (ctx === null) throw new Error("This browser cannot draw on a canvas (no 2D context).");
  return ctx;
}

/**
 * Sleeve-oriented pixels -> device pixels on `ctx`: shifted by `marginPx`, scaled by `dpr`, and
 * turned a quarter clockwise when `turned` (the sleeve's top edge then on the right of an area
 * `screenWidthPx` wide). The drawing area and the preview turn alike through this one transform.
 */
export function setSleeveTransform(
  ctx: CanvasRenderingContext2D,
  turned: boolean,
  screenWidthPx: number,
  marginPx: number,
  dpr: number,
): void {
  const m = marginPx;
  const [a, b, c, d, e, f] = turned ? [0, 1, -1, 0, m + screenWidthPx, m] : [1, 0, 0, 1, m, m];
  ctx.setTransform(a * dpr, b * dpr, c * dpr, d * dpr, e * dpr, f * dpr);
}

/**
 * The sleeve's top edge marked along sleeve-oriented y = `y`, `widthPx` long: drawn on a turned
 * canvas it shows on the right, so the sender sees which way is up.
 */
const SLEEVE_TOP = "SLEEVE TOP";

export function drawSleeveTop(ctx: CanvasRenderingContext2D, widthPx: number, y: number): void {
  ctx.save();
  ctx.strokeStyle = COLORS.topEdge;
  ctx.fillStyle = COLORS.topEdge;
  ctx.lineWidth = 2;
  ctx.font = "600 11px system-ui, sans-serif";
  const gap = ctx.measureText(SLEEVE_TOP).width / 2 + 8;
  ctx.beginPath();
  ctx.moveTo(0, y);
  ctx.lineTo(Math.max(0, widthPx * 0.5 - gap), y);
  ctx.moveTo(Math.min(widthPx, widthPx * 0.5 + gap), y);
  ctx.lineTo(widthPx, y);
  ctx.stroke();
  ctx.textAlign = "center";
  ctx.textBaseline = "middle";
  ctx.fillText(SLEEVE_TOP, widthPx * 0.5, y);
  ctx.restore();
}
