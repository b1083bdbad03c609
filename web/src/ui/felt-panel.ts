/**
 * The felt drawing, kept in step with the sleeve: the current drawing's
 * strokes placed in time (felt.ts) from the sleeve's `played` and `cancelled`
 * events (its own estimate until they come), the timeline with a cursor
 * moving at the moment being felt, a marker on the canvas where the brush is,
 * and an A/B comparison with the same paths simplified under other settings.
 */
import type { Drawing } from "../drawing";
import type { CancelledEvent, AdjustedEvent, PlayedEvent } from "../events";
import {
  brushAt,
  placeStrokes,
  playingAt,
  totalMs,
  type FeltStroke,
  type Grid,
  type PlacedStroke,
} from "../felt";
import { simplifyPaths, type SimplifierParams } from "../simplify/registry";
import type { Point } from "../simplify/segment";
import type { DrawingView } from "./canvas";
import type { TimelineView } from "./timeline";

/** How the drawing's strokes reach the sleeve: as they were drawn, or all at once (Play again). */
export type Arrival = "as-drawn" | "at-once";

export class FeltPanel {
  readonly #timeline: TimelineView;
  readonly #view: DrawingView;
  #drawing: Drawing | null = null;
  #arrival: Arrival = "as-drawn";
  #grid: Grid = { rows: 3, columns: 4 };
  /** seq -> when the sleeve started it, on the sleeve's wall clock. */
  readonly #startedAt = new Map<number, number>();
  /** seq -> ms into the stroke at which a cancel cut it (0: dropped before it started). */
  readonly #cut = new Map<number, number>();
  #b: { params: SimplifierParams; placed: PlacedStroke[]; segments: [Point, Point][] } | null = null;
  #placed: PlacedStroke[] = [];
  /** The cursor runs from `t_ms` at `at` (performance.now()). */
  #anchor: { t_ms: number; at: number } | null = null;
  #running = false;

  constructor(timeline: TimelineView, view: DrawingView) {
    this.#timeline = timeline;
    this.#view = view;
  }

  /** A new current drawing (or none): the cursor stops, the sleeve's reports are forgotten. */
  setDrawing(drawing: Drawing | null, grid: Grid, arrival: Arrival = "as-drawn"): void {
    this.#drawing = drawing;
    this.#grid = grid;
    this.#arrival = arrival;
    this.#startedAt.clear();
    this.#cut.clear();
    this.#anchor = null;
    this.#b = null;
    this.#view.setCompare(null);
    this.refresh();
  }

  /** The drawing gained or lost strokes: placed again. */
  refresh(): void {
    this.#placed = this.#place();
    this.#timeline.show(this.#grid, this.#placed, this.#b?.placed ?? null);
    const count = this.#placed.length;
    const seconds = (totalMs(this.#placed) / 1000).toFixed(1);
    const reported = this.#placed.filter((s) => s.reported).length;
    this.#timeline.setCaption(
      count === 0
        ? "Each lane is one actuator (row, column); draw to see where and when the touch is felt."
        : `${count} stroke${count === 1 ? "" : "s"}, ${seconds} s` +
            (reported === count
              ? ", as the sleeve played them."
              : reported > 0
                ? `; ${reported} as the sleeve played them, the rest as it would.`
                : ": what would be felt, played back to back as the sleeve does."),
    );
  }

  /** The sleeve played a stroke of this drawing: its real start, and the cursor from there. */
  played(event: PlayedEvent | AdjustedEvent): void {
    if (event.seq === null) return;
    this.#startedAt.set(event.seq, event.start_at_ms);
    this.refresh();
    const stroke = this.#placed.find((s) => s.seq === event.seq);
    if (stroke === undefined) return;
    // Time since the sleeve started it: its report took a moment to arrive.
    const lag = Math.max(0, Math.min(event.latency_ms, stroke.duration_ms));
    this.#anchor = { t_ms: stroke.start_ms + lag, at: performance.now() };
    this.#run();
  }

  cancelled(event: CancelledEvent): void {
    if (event.seq === null) return;
    const started = this.#startedAt.get(event.seq);
    this.#cut.set(event.seq, event.started && started !== undefined ? event.cancelled_at_ms - started : 0);
    this.refresh();
  }

  /** Stop pressed: the cursor stops where it is. */
  stopCursor(): void {
    this.#anchor = null;
  }

  /** Compares with the same paths under `params` (null: no comparison). */
  compare(params: SimplifierParams | null): number {
    const drawing = this.#drawing;
    if (params === null || drawing === null) {
      this.#b = null;
      this.#view.setCompare(null);
      this.refresh();
      return 0;
    }
    const pieces = simplifyPaths(params, drawing.paths).filter((p) => p.segment.dropped === null);
    const origin = drawing.paths[0]?.[0]?.t_ms ?? 0;
    const strokes: FeltStroke[] = pieces.map(({ segment }, seq) => ({
      seq,
      start: segment.start,
      end: segment.end,
      duration_ms: segment.duration_ms,
      intensity: drawing.strokes[0]?.intensity ?? 0.8,
      arrives_ms: this.#arrival === "at-once" ? 0 : segment.end_ms - origin,
    }));
    const segments = pieces.map(({ segment }) => [segment.start, segment.end] as [Point, Point]);
    this.#b = { params, placed: placeStrokes(strokes), segments };
    this.#view.setCompare(segments);
    this.refresh();
    return pieces.length;
  }

  #place(): PlacedStroke[] {
    const drawing = this.#drawing;
    if (drawing === null) return [];
    const origin = drawing.paths[0]?.[0]?.t_ms ?? 0;
    const strokes: FeltStroke[] = drawing.segments.flatMap(({ segment, stroke }) =>
      stroke === null || stroke.seq == null
        ? []
        : [
            {
              seq: stroke.seq,
              start: stroke.start,
              end: stroke.end,
              duration_ms: stroke.duration_ms,
              intensity: stroke.intensity ?? 0.8,
              arrives_ms: this.#arrival === "at-once" ? 0 : segment.end_ms - origin,
            },
          ],
    );
    // The timeline starts with the first stroke, not with the first touch of the pen.
    const start = Math.min(...strokes.map((s) => s.arrives_ms));
    const shifted = strokes.map((s) => ({ ...s, arrives_ms: s.arrives_ms - start }));
    const estimate = placeStrokes(shifted, new Map(), this.#cut);
    // The sleeve's clock -> the timeline's: anchored on the first stroke it reported.
    const first = estimate.find((s) => this.#startedAt.has(s.seq));
    if (first === undefined) return estimate;
    const offset = this.#startedAt.get(first.seq)! - first.start_ms;
    const reported = new Map([...this.#startedAt].map(([seq, at]) => [seq, at - offset]));
    return placeStrokes(shifted, reported, this.#cut);
  }

  #run(): void {
    if (this.#running) return;
    this.#running = true;
    const step = () => {
      const anchor = this.#anchor;
      const total = totalMs(this.#placed);
      const t = anchor === null ? null : anchor.t_ms + (performance.now() - anchor.at);
      if (t === null || t > total + 300) {
        this.#running = false;
        this.#timeline.setCursor(null);
        this.#view.drawMarker(null);
        return;
      }
      this.#timeline.setCursor(t);
      const now = playingAt(this.#placed, t);
      this.#view.drawMarker(now === null ? null : brushAt(now.stroke, now.into_ms));
      requestAnimationFrame(step);
    };
    requestAnimationFrame(step);
  }
}
