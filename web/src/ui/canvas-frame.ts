/** What the page's drawn panels (preview, timeline) share: one redraw a frame, sharp on any screen. */

/** Coalesces redraw requests: however often `request` is called, `draw` runs once in the next animation frame. */
export class FrameRequest {
  readonly #draw: () => void;
  #scheduled = false;

  constructor(draw: () => void) {
    this.#draw = draw;
  }

  request(): void {
    if (this.#scheduled) return;
    this.#scheduled = true;
    requestAnimationFrame(() => {
      this.#scheduled = false;
      this.#draw();
    });
  }
}

/**
 * Gives the canvas one backing pixel per device pixel of its CSS size (resizing it only when that
 * changed, which clears it) and returns the CSS size and the device pixel ratio to draw with.
 */
export function fitToDevicePixels(canvas: HTMLCanvasElement): { width: number; height: number; dpr: number } {
  const dpr = window.devicePixelRatio || 1;
  const width = canvas.clientWidth;
  const height = canvas.clientHeight;
  if (canvas.width !== Math.round(width * dpr) || canvas.height !== Math.round(height * dpr)) {
    canvas.width = Math.round(width * dpr);
    canvas.height = Math.round(height * dpr);
  }
  return { width, height, dpr };
}
