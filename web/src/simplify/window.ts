/**
 * The window simplifier: an error-bounded online simplifier (plain opening
 * window, "before opening window" form; Meratnia & de By 2004), ported from
 * the Python reference `feelmysign/simplify/window.py`, which it reproduces
 * exactly on the shared vectors in `testdata/window/`.
 *
 * A stroke grows one frame at a time from its anchor; when the next frame
 * would put a frame since the anchor farther than `max_error` (grid units)
 * from the stroke, the stroke ends at the previous frame and is emitted now,
 * and that frame anchors the next. A stroke is cut at the current frame when
 * it covers `max_window` frames after its anchor, bounding the work per frame.
 * Too short or too brief strokes are dropped with their reason, as by the
 * angle simplifier. The float operations follow the reference's order.
 */
import { CanvasMapping } from "./mapping";
import { finishSegment, type Point, type Sample, type Segment } from "./segment";
import { checkWindowParams, type WindowParams } from "./window-params";

interface Frame {
  readonly sample: Sample;
  /** The frame in grid units. */
  readonly point: Point;
}

export class WindowSimplifier {
  readonly params: WindowParams;
  readonly #maxErrorSq: number;
  readonly #mapping: CanvasMapping;
  /** The frames of the stroke being drawn: its anchor first, then every frame since. */
  #window: Frame[] = [];
  #pointer: Sample | null = null;
  #emittedInPath = false;

  constructor(params: WindowParams) {
    checkWindowParams(params);
    this.params = params;
    this.#maxErrorSq = params.max_error * params.max_error;
    this.#mapping = new CanvasMapping({
      width_px: params.canvas_width_px,
      height_px: params.canvas_height_px,
      columns: params.columns,
      rows: params.rows,
      stretch: params.stretch,
    });
  }

  /** True between the first frame of a path and `end`. */
  get drawing(): boolean {
    return this.#window.length > 0;
  }

  /** Where the stroke being drawn starts (canvas pixels), for showing it; null between paths. */
  get lineStart(): Sample | null {
    return this.#window[0]?.sample ?? null;
  }

  /** One animation frame while the pointer is down; the first frame of a path is the press. */
  push(frame: Sample): Segment[] {
    this.#pointer = frame;
    const current: Frame = { sample: frame, point: this.#mapping.toGrid(frame.x, frame.y) };
    let window = this.#window;
    if (window.length === 0) {
      this.#window = [current];
      this.#emittedInPath = false;
      return [];
    }
    const out: Segment[] = [];
    if (!this.#fits(window, current.point)) {
      const previous = window[window.length - 1]!;
      out.push(this.#finish(window[0]!, previous));
      window = this.#window = [previous];
    }
    window.push(current);
    if (window.length - 1 >= this.params.max_window) {
      out.push(this.#finish(window[0]!, current));
      this.#window = [current];
    }
    return out;
  }

  /** Release: the rest of the path as one stroke (a tap gives one, dropped, of length 0). */
  end(): Segment[] {
    const window = this.#window;
    this.#window = [];
    const first = window[0];
    const last = window[window.length - 1];
    if (first === undefined || last === undefined) return [];
    // The last frame already ends a stroke (a cut at the window cap).
    if (window.length === 1 && this.#emittedInPath) return [];
    return [this.#finish(first, last)];
  }

  /** Whether every frame after the anchor lies within max_error of anchor -> end. */
  #fits(window: readonly Frame[], end: Point): boolean {
    const [ax, ay] = window[0]!.point;
    const dx = end[0] - ax;
    const dy = end[1] - ay;
    const lengthSq = dx * dx + dy * dy;
    for (let i = 1; i < window.length; i++) {
      const point = window[i]!.point;
      let qx = point[0] - ax;
      let qy = point[1] - ay;
      if (lengthSq > 0) {
        // The nearest point of the segment: the projection, clamped onto it.
        const t = Math.min(Math.max((qx * dx + qy * dy) / lengthSq, 0), 1);
        qx = qx - t * dx;
        qy = qy - t * dy;
      }
      if (qx * qx + qy * qy > this.#maxErrorSq) return false;
    }
    return true;
  }

  #finish(start: Frame, end: Frame): Segment {
    this.#emittedInPath = true;
    return finishSegment(
      start.point,
      end.point,
      start.sample.t_ms,
      end.sample.t_ms,
      this.#pointer ? this.#pointer.t_ms : end.sample.t_ms,
      this.params,
    );
  }
}
