/**
 * Where things sit on the stage: the drawing area (the sleeve's aspect ratio)
 * inside a margin that leaves room for the outer actuators' dots, and grid
 * points back to canvas pixels (the inverse of `CanvasMapping.toGrid`).
 */

export interface AreaSize {
  readonly width_px: number;
  readonly height_px: number;
}

export interface GridSize {
  readonly rows: number;
  readonly columns: number;
}

/** CSS pixels around the drawing area, so the actuators on its edge are drawn whole. */
export const AREA_MARGIN_PX = 28;
/** A 1-row or 1-column sleeve has no height or width; its area is drawn this flat at most. */
const MAX_ASPECT = 6;

/** Width / height of the drawing area: (columns - 1) : (rows - 1), kept drawable. */
export function areaAspect(grid: GridSize): number {
  const x = grid.columns - 1;
  const y = grid.rows - 1;
  if (x <= 0 && y <= 0) return 1;
  if (y <= 0) return MAX_ASPECT;
  if (x <= 0) return 1 / MAX_ASPECT;
  return Math.min(Math.max(x / y, 1 / MAX_ASPECT), MAX_ASPECT);
}

/** The largest area of the grid's aspect that fits, with its margin, in width x height. */
export function fitArea(
  grid: GridSize,
  availableWidthPx: number,
  availableHeightPx: number,
): { width_px: number; height_px: number } {
  const aspect = areaAspect(grid);
  const width = Math.max(40, availableWidthPx - 2 * AREA_MARGIN_PX);
  const height = Math.max(40, availableHeightPx - 2 * AREA_MARGIN_PX);
  const widthPx = Math.floor(Math.min(width, height * aspect));
  return { width_px: widthPx, height_px: Math.floor(widthPx / aspect) };
}

/**
 * Turned a quarter, the area must be this many times larger to be chosen: a
 * near-square window keeps the sleeve upright instead of flipping at every resize.
 */
export const TURN_GAIN = 1.3;

/**
 * The drawing area for the space given, in the sleeve's orientation, and
 * whether to show it turned a quarter: a landscape sleeve on an upright phone
 * gets about twice the area turned (2:3 instead of 3:2 across the phone's width).
 */
export function chooseArea(
  grid: GridSize,
  availableWidthPx: number,
  availableHeightPx: number,
): { area: AreaSize; turned: boolean } {
  const upright = fitArea(grid, availableWidthPx, availableHeightPx);
  // Laid out turned: the grid's rows across the screen, its columns down it.
  const across = fitArea({ rows: grid.columns, columns: grid.rows }, availableWidthPx, availableHeightPx);
  if (across.width_px * across.height_px > TURN_GAIN * upright.width_px * upright.height_px) {
    return { area: { width_px: across.height_px, height_px: across.width_px }, turned: true };
  }
  return { area: upright, turned: false };
}

export interface MappingShape {
  readonly width_px: number;
  readonly height_px: number;
  readonly rows: number;
  readonly columns: number;
  readonly stretch: boolean;
}

/** Canvas pixel of a grid point under the same mapping the simplifier used. */
export function gridToCanvas(gx: number, gy: number, shape: MappingShape): [number, number] {
  const xExtent = shape.columns - 1;
  const yExtent = shape.rows - 1;
  if (shape.stretch) {
    return [
      xExtent > 0 ? (gx * shape.width_px) / xExtent : shape.width_px / 2,
      yExtent > 0 ? (gy * shape.height_px) / yExtent : shape.height_px / 2,
    ];
  }
  const scales: number[] = [];
  if (xExtent > 0) scales.push(xExtent / shape.width_px);
  if (yExtent > 0) scales.push(yExtent / shape.height_px);
  if (scales.length === 0) return [shape.width_px / 2, shape.height_px / 2];
  const scale = Math.min(...scales);
  return [
    (gx - (xExtent - shape.width_px * scale) / 2) / scale,
    (gy - (yExtent - shape.height_px * scale) / 2) / scale,
  ];
}
