/**
 * From canvas pixels to the sleeve's grid units (port of `simplify/mapping.py`).
 *
 * By default the aspect ratio is kept (a circle drawn stays a circle on the
 * skin): one scale for both axes, the canvas centred on the grid. The paper
 * stretched each axis to fill the grid; `stretch` does the same.
 */
import type { Point } from "./segment";

export interface CanvasMappingOptions {
  readonly width_px: number;
  readonly height_px: number;
  readonly columns: number;
  readonly rows: number;
  readonly stretch: boolean;
}

export class CanvasMapping {
  /** Grid units per pixel when the aspect ratio is kept (the tighter axis decides). */
  readonly scale: number;
  // What gridX and gridY read, taken out of the options once: they run for every pointer sample.
  readonly #stretch: boolean;
  readonly #widthPx: number;
  readonly #heightPx: number;
  readonly #xExtent: number;
  readonly #yExtent: number;
  /** Where pixel 0 lands on each axis when the aspect ratio is kept, computed once (the same value). */
  readonly #offsetX: number;
  readonly #offsetY: number;

  constructor(options: CanvasMappingOptions) {
    const scales: number[] = [];
    if (options.columns - 1 > 0) scales.push((options.columns - 1) / options.width_px);
    if (options.rows - 1 > 0) scales.push((options.rows - 1) / options.height_px);
    this.scale = scales.length > 0 ? Math.min(...scales) : 0;
    this.#stretch = options.stretch;
    this.#widthPx = options.width_px;
    this.#heightPx = options.height_px;
    this.#xExtent = options.columns - 1;
    this.#yExtent = options.rows - 1;
    this.#offsetX = (this.#xExtent - options.width_px * this.scale) / 2;
    this.#offsetY = (this.#yExtent - options.height_px * this.scale) / 2;
  }

  /** The mapping a simplifier's parameters ask for (their canvas, grid and stretch). */
  static fromParams(params: {
    readonly canvas_width_px: number;
    readonly canvas_height_px: number;
    readonly columns: number;
    readonly rows: number;
    readonly stretch: boolean;
  }): CanvasMapping {
    return new CanvasMapping({
      width_px: params.canvas_width_px,
      height_px: params.canvas_height_px,
      columns: params.columns,
      rows: params.rows,
      stretch: params.stretch,
    });
  }

  /** Grid point (x = column, y = row) of a canvas pixel, clamped onto the grid. */
  toGrid(xPx: number, yPx: number): Point {
    return [this.gridX(xPx), this.gridY(yPx)];
  }

  /** The grid column of a canvas pixel's x, clamped onto the grid (`toGrid`'s x, no tuple made). */
  gridX(xPx: number): number {
    const xExtent = this.#xExtent;
    // Same operation order as the reference, so results agree to the last bit.
    const x = this.#stretch ? (xPx * xExtent) / this.#widthPx : this.#offsetX + xPx * this.scale;
    return Math.min(Math.max(x, 0), xExtent);
  }

  /** The grid row of a canvas pixel's y, clamped onto the grid (`toGrid`'s y, no tuple made). */
  gridY(yPx: number): number {
    const yExtent = this.#yExtent;
    const y = this.#stretch ? (yPx * yExtent) / this.#heightPx : this.#offsetY + yPx * this.scale;
    return Math.min(Math.max(y, 0), yExtent);
  }
}
