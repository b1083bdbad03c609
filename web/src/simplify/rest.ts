/**
 * When a pen rests (the window simplifier's `rest_ms`, both its cores): how near one point it
 * stays. Python `simplify/window.py` (`REST_SHARE`, `REST_SPEED_PX_PER_MS`, `rest_radius`).
 */
import type { CanvasMapping } from "./mapping";
import type { WindowParams } from "./window-params";

/**
 * A pen rests while its samples stay within this share of min_length of one point (never farther
 * than half of max_error, so the point that ends or starts a stroke covers the rest): well below a
 * stroke the sleeve renders, well above a still hand's jitter.
 */
export const REST_SHARE = 0.25;
/**
 * ... and never farther than a pen this slow (canvas pixels per ms) covers in rest_ms: a quarter of
 * a pixel a frame at 60 fps. A pen that stays near one point for all of rest_ms rests; a slow, steady
 * pen does not, as the distance it covers over the whole window tells: at twice this speed (half a
 * pixel a frame) or more, in any direction, it leaves the radius well within rest_ms, even with its
 * samples rounded to whole pixels. In pixels, not grid units: a hand's speed on the screen does not
 * depend on how the canvas maps onto the sleeve (at the default canvas a quarter of min_length is 16
 * pixels, which a pen at 2 pixels a frame took 100 ms to leave).
 */
export const REST_SPEED_PX_PER_MS = 0.015;

/**
 * How near one point a resting pen stays, in grid units: the least of `REST_SHARE` x min_length,
 * half of max_error and the distance a pen at `REST_SPEED_PX_PER_MS` covers in rest_ms, mapped at
 * the canvas's tighter scale (so no more pixels on either axis).
 */
export function restRadius(params: WindowParams, mapping: CanvasMapping): number {
  const px = REST_SPEED_PX_PER_MS * params.rest_ms;
  return Math.min(REST_SHARE * params.min_length, 0.5 * params.max_error, px * mapping.scale);
}
