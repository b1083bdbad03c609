/**
 * A drawing as a recording file: the format `feelmysign simplify RECORDING`
 * reads (docs/research.md, "Recordings"), so any drawing can be simplified
 * again with other parameters. Beside the required keys it carries what this
 * page actually did, for exact checks: the animation frames it fed the
 * simplifier (`frames`), the strokes it sent and the segments it dropped.
 * Times start at 0 at the drawing's first sample.
 */
import type { Drawing } from "./drawing";
import type { Algorithm } from "./simplify/registry";
import type { Sample } from "./simplify/segment";

export interface RecordedSample {
  readonly t_ms: number;
  readonly x: number;
  readonly y: number;
  readonly pressure: number;
}

export interface RecordedSegment {
  readonly path: number;
  readonly start: readonly [number, number];
  readonly end: readonly [number, number];
  readonly start_ms: number;
  readonly end_ms: number;
  readonly duration_ms: number;
}

export interface Recording {
  readonly canvas: { readonly width_px: number; readonly height_px: number };
  readonly paths: RecordedSample[][];
  readonly sleeve: { readonly rows: number; readonly columns: number };
  readonly simplifier: { readonly algorithm: Algorithm; readonly params: Record<string, number | boolean> };
  readonly drawing: string;
  readonly recorded_at: string;
  readonly frames: RecordedSample[][];
  readonly strokes: (RecordedSegment & { readonly seq: number; readonly intensity: number | null })[];
  readonly dropped: (RecordedSegment & { readonly reason: string })[];
}

/** The parameters a recording keeps: the sender's, without the canvas and grid (kept beside them). */
const NOT_RECORDED: ReadonlySet<string> = new Set([
  "algorithm",
  "rows",
  "columns",
  "canvas_width_px",
  "canvas_height_px",
]);

export function buildRecording(drawing: Drawing, recordedAt: Date): Recording {
  const origin = drawing.paths[0]?.[0]?.t_ms ?? 0;
  const shift = (sample: Sample): RecordedSample => ({
    t_ms: sample.t_ms - origin,
    x: sample.x,
    y: sample.y,
    pressure: sample.pressure,
  });
  const { params } = drawing;
  const strokes: Recording["strokes"] = [];
  const dropped: Recording["dropped"] = [];
  for (const { path, segment, stroke } of drawing.segments) {
    const common: RecordedSegment = {
      path,
      start: segment.start,
      end: segment.end,
      start_ms: segment.start_ms - origin,
      end_ms: segment.end_ms - origin,
      duration_ms: segment.duration_ms,
    };
    if (stroke !== null && stroke.seq != null) {
      strokes.push({ ...common, seq: stroke.seq, intensity: stroke.intensity ?? null });
    } else if (segment.dropped !== null) {
      dropped.push({ ...common, reason: segment.dropped });
    }
  }
  return {
    canvas: { width_px: params.canvas_width_px, height_px: params.canvas_height_px },
    // A path needs at least one sample to be valid; an empty one (a cancelled press) is left out.
    paths: drawing.paths.filter((path) => path.length > 0).map((path) => path.map(shift)),
    sleeve: { rows: params.rows, columns: params.columns },
    simplifier: {
      algorithm: params.algorithm,
      params: Object.fromEntries(Object.entries(params).filter(([name]) => !NOT_RECORDED.has(name))),
    },
    drawing: drawing.id,
    recorded_at: recordedAt.toISOString(),
    frames: drawing.frames.filter((frames) => frames.length > 0).map((frames) => frames.map(shift)),
    strokes,
    dropped,
  };
}

/** A file name that sorts by time: feelmysign-drawing-2024-11-22T10-30-05.json. */
export function recordingFileName(recordedAt: Date): string {
  const stamp = recordedAt.toISOString().slice(0, 19).replace(/:/g, "-");
  return `feelmysign-drawing-${stamp}.json`;
}
