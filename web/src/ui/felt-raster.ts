/**
 * The felt timeline's picture, kept between frames: per actuator lane, the
 * strongest touch in each time bin. A new stroke or a sleeve report paints
 * only the strokes it moved, and drawing the timeline reads a bounded number
 * of bins whatever the drawing's length (the bins grow coarser, two merged
 * into one, when the drawing outgrows them), so the timeline's cost per frame
 * does not grow with the drawing. Pure: no DOM.
 */
import { brushAt, funnel, type Grid, type PlacedStroke } from "../felt";
import type { FeltPlacement } from "../felt-placement";

/** Time resolution of the touch along a stroke: finer than a frame, coarse enough to stay cheap. */
export const STEP_MS = 10;
/** Bins per lane: the most the timeline reads per frame (about the plot's device pixels). */
const CAPACITY_BINS = 1024;

/** Per lane, the largest value painted into each time bin (0: nothing). */
export class LaneRaster {
  readonly lanes: number;
  readonly capacity: number;
  #values: Float32Array;
  #msPerBin: number;
  /** Bins up to the last one painted. */
  #usedBins = 0;

  constructor(lanes: number, capacity = CAPACITY_BINS, msPerBin = STEP_MS) {
    this.lanes = lanes;
    this.capacity = capacity;
    this.#msPerBin = msPerBin;
    this.#values = new Float32Array(lanes * capacity);
  }

  get msPerBin(): number {
    return this.#msPerBin;
  }

  value(lane: number, bin: number): number {
    return this.#values[lane * this.capacity + bin] ?? 0;
  }

  /** `value` (kept if larger) over the bins that [fromMs, toMs) touches on `lane`. */
  paint(lane: number, fromMs: number, toMs: number, value: number): void {
    if (lane < 0 || lane >= this.lanes || !(toMs > fromMs) || fromMs < 0) return;
    while (toMs > this.capacity * this.#msPerBin) this.#coarsen();
    const first = Math.floor(fromMs / this.#msPerBin);
    const last = Math.min(Math.ceil(toMs / this.#msPerBin), this.capacity);
    const row = lane * this.capacity;
    for (let bin = first; bin < last; bin++) {
      if (value > this.#values[row + bin]!) this.#values[row + bin] = value;
    }
    this.#usedBins = Math.max(this.#usedBins, last);
  }

  /** Empties every lane from the bin holding `tMs` on; returns where that bin starts (ms). */
  clearFrom(tMs: number): number {
    const first = Math.max(0, Math.floor(tMs / this.#msPerBin));
    if (first < this.#usedBins) {
      for (let lane = 0; lane < this.lanes; lane++) {
        this.#values.fill(0, lane * this.capacity + first, lane * this.capacity + this.#usedBins);
      }
      this.#usedBins = first;
    }
    return first * this.#msPerBin;
  }

  /**
   * Lane `lane` shown `columns` wide for `totalMs`: each column the largest value of the bins under
   * it, and every painted bin at least one column wide. Cost: the bins used plus the columns.
   */
  columns(lane: number, totalMs: number, columns: number, out: Float32Array): void {
    out.fill(0, 0, columns);
    if (totalMs <= 0 || columns <= 0) return;
    const perBin = (this.#msPerBin / totalMs) * columns;
    const row = lane * this.capacity;
    for (let bin = 0; bin < this.#usedBins; bin++) {
      const value = this.#values[row + bin]!;
      if (value === 0) continue;
      const x0 = bin * perBin;
      const from = Math.min(Math.floor(x0), columns - 1);
      const to = Math.min(Math.max(from + 1, Math.ceil(x0 + perBin)), columns);
      for (let column = from; column < to; column++) if (value > out[column]!) out[column] = value;
    }
  }

  /** Twice the time per bin: two bins become one, the larger value kept. */
  #coarsen(): void {
    const half = Math.ceil(this.capacity / 2);
    for (let lane = 0; lane < this.lanes; lane++) {
      const row = lane * this.capacity;
      for (let bin = 0; bin < half; bin++) {
        const a = this.#values[row + 2 * bin] ?? 0;
        const b = 2 * bin + 1 < this.capacity ? this.#values[row + 2 * bin + 1]! : 0;
        this.#values[row + bin] = Math.max(a, b);
      }
      this.#values.fill(0, row + half, row + this.capacity);
    }
    this.#msPerBin *= 2;
    this.#usedBins = Math.ceil(this.#usedBins / 2);
  }
}

/** The actuator lanes of one drawing's touch, as the timeline draws them. */
export function laneOf(grid: Grid, row: number, column: number): number {
  return row * grid.columns + column;
}

/**
 * Paints `stroke`'s touch: every STEP_MS along it, the actuators that render the brush there
 * (funneling), each with `alpha(stroke, intensity)`.
 */
export function paintStroke(
  raster: LaneRaster,
  grid: Grid,
  stroke: PlacedStroke,
  alpha: (stroke: PlacedStroke, intensity: number) => number,
): void {
  for (let t = 0; t < stroke.played_ms; t += STEP_MS) {
    const from = stroke.start_ms + t;
    const to = from + Math.min(STEP_MS, stroke.played_ms - t);
    for (const drive of funnel(brushAt(stroke, t), stroke.intensity, grid)) {
      raster.paint(laneOf(grid, drive.row, drive.column), from, to, alpha(stroke, drive.intensity));
    }
  }
}

/** A placement's picture, brought up to date with what changed since the last sync. */
export class PlacementRaster {
  readonly #alpha: (stroke: PlacedStroke, intensity: number) => number;
  #raster: LaneRaster = new LaneRaster(0);
  #grid: Grid = { rows: 0, columns: 0 };
  #source: FeltPlacement | null = null;

  constructor(alpha: (stroke: PlacedStroke, intensity: number) => number) {
    this.#alpha = alpha;
  }

  get raster(): LaneRaster {
    return this.#raster;
  }

  /** Repaints what `placement` changed since the last sync (all of it for another placement or grid). */
  sync(placement: FeltPlacement, grid: Grid): void {
    const dirty = placement.takeDirty();
    const sameGrid = grid.rows === this.#grid.rows && grid.columns === this.#grid.columns;
    if (placement !== this.#source || !sameGrid || dirty === "all") {
      this.#source = placement;
      this.#grid = grid;
      this.#raster = new LaneRaster(grid.rows * grid.columns);
      for (const stroke of placement.placed) paintStroke(this.#raster, grid, stroke, this.#alpha);
      return;
    }
    if (dirty === null) return;
    // Every stroke still ending after the cleared bins is painted again: values keep the larger,
    // so painting one twice changes nothing.
    const cleared = this.#raster.clearFrom(dirty);
    const placed = placement.placed;
    for (let i = placement.firstEndingAfter(cleared); i < placed.length; i++) {
      paintStroke(this.#raster, grid, placed[i]!, this.#alpha);
    }
  }

  /** A list of placed strokes that never changes (the A/B comparison's), painted whole. */
  paintAll(placed: readonly PlacedStroke[], grid: Grid): void {
    this.#source = null;
    this.#grid = grid;
    this.#raster = new LaneRaster(grid.rows * grid.columns);
    for (const stroke of placed) paintStroke(this.#raster, grid, stroke, this.#alpha);
  }
}
