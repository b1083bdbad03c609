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
  readonly #options: CanvasMappingOptions;
  /** Grid units per pixel when the aspect ratio is kept (the tighter axis decides). */
  readonly scale: number;
  /** Where pixel 0 lands on each axis when the aspect ratio is kept, computed once (the same value). */
  readonly #offsetX: number;
  readonly #offsetY: number;

  constructor(options: CanvasMappingOptions) {
    this.#options = options;
    const scales: number[] = [];
    if (options.columns - 1 > 0) scales.push((options.columns - 1) / options.width_px);
    if (options.rows - 1 > 0) scales.push((options.rows - 1) / options.height_px);
    this.scale = scales.length > 0 ? Math.min(...scales) : 0;
    this.#offsetX = (options.columns - 1 - options.width_px * this.scale) / 2;
    this.#offsetY = (options.rows - 1 - options.height_px * this.scale) / 2;
  }

  /** Grid point (x = column, y = row) of a canvas pixel, clamped onto the grid. */
  toGrid(xPx: number, yPx: number): Point {
    return [this.gridX(xPx), this.gridY(yPx)];
  }

  /** The grid column of a canvas pixel's x, clamped onto the grid (`toGrid`'s x, no tuple made). */
  gridX(xPx: number): number {
    const { width_px, columns, stretch } = this.#options;
    const xExtent = columns - 1;
    // Same operation order as the reference, so results agree to the last bit.
    const x = stretch ? (xPx * xExtent) / width_px : this.#offsetX + xPx * this.scale;
    return Math.min(Math.max(x, 0), xExtent);
  }

  /** The grid row of a canvas pixel's y, clamped onto the grid (`toGrid`'s y, no tuple made). */
  gridY(yPx: number): number {
    const { height_px, rows, stretch } = this.#options;
    const yExtent = rows - 1;
    const y = stretch ? (yPx * yExtent) / height_px : this.#offsetY + yPx * this.scale;
    return Math.min(Math.max(y, 0), yExtent);
  }
}
