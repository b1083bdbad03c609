/**
 * A saved recording (recording.ts) back into a drawing: its paths, frames and
 * the segments the page made of them, each sent stroke with its seq and
 * intensity, so the page shows what would be felt and Play again sends the
 * same strokes. A file that is not a recording gives a sentence saying what is
 * wrong, never an exception.
 */
import { Drawing } from "./drawing";
import type { Recording, RecordedSample } from "./recording";
import type { SimplifierParams } from "./simplify/registry";
import type { DropReason, Segment } from "./simplify/segment";

function isObject(value: unknown): value is Record<string, unknown> {
  return typeof value === "object" && value !== null && !Array.isArray(value);
}

function isSample(value: unknown): value is RecordedSample {
  return (
    isObject(value) &&
    ["t_ms", "x", "y", "pressure"].every(
      (key) => typeof value[key] === "number" && Number.isFinite(value[key]),
    )
  );
}

function isPoint(value: unknown): value is [number, number] {
  return (
    Array.isArray(value) &&
    value.length === 2 &&
    value.every((v) => typeof v === "number" && Number.isFinite(v))
  );
}

function isSegment(value: unknown): boolean {
  return (
    isObject(value) &&
    Number.isInteger(value["path"]) &&
    isPoint(value["start"]) &&
    isPoint(value["end"]) &&
    typeof value["start_ms"] === "number" &&
    typeof value["end_ms"] === "number"
  );
}

/** The recording in `text`, or what is wrong with it (a sentence to show). */
export function parseRecording(text: string): Recording | string {
  let data: unknown;
  try {
    data = JSON.parse(text);
  } catch {
    return "This file is not JSON: choose a recording saved by this page (feelmysign-drawing-*.json).";
  }
  if (!isObject(data)) return "This file is not a recording: it holds no JSON object.";
  const canvas = data["canvas"];
  const sleeve = data["sleeve"];
  const simplifier = data["simplifier"];
  if (
    !isObject(canvas) ||
    typeof canvas["width_px"] !== "number" ||
    typeof canvas["height_px"] !== "number"
  ) {
    return 'This recording has no "canvas" size: it was not saved by this page.';
  }
  if (!isObject(sleeve) || !Number.isInteger(sleeve["rows"]) || !Number.isInteger(sleeve["columns"])) {
    return 'This recording has no "sleeve" grid (rows and columns).';
  }
  if (!isObject(simplifier) || !isObject(simplifier["params"])) {
    return 'This recording has no "simplifier" parameters.';
  }
  const paths = data["paths"];
  if (!Array.isArray(paths) || !paths.every((path) => Array.isArray(path) && path.every(isSample))) {
    return 'This recording\'s "paths" are not lists of samples (t_ms, x, y, pressure).';
  }
  for (const key of ["strokes", "dropped"]) {
    const list = data[key];
    if (list !== undefined && !(Array.isArray(list) && list.every(isSegment))) {
      return `This recording's "${key}" are not segments (path, start, end, start_ms, end_ms).`;
    }
  }
  if (!Array.isArray(data["strokes"])) {
    return 'This recording has no "strokes": it was saved by another tool; simplify it with feelmysign simplify.';
  }
  return data as unknown as Recording;
}

function segmentOf(recorded: Recording["strokes"][number] | Recording["dropped"][number]): Segment {
  const dropped = "reason" in recorded ? (recorded.reason as DropReason) : null;
  return {
    start: recorded.start,
    end: recorded.end,
    start_ms: recorded.start_ms,
    end_ms: recorded.end_ms,
    // As sent (a stroke drawn briefer than the sleeve's floor lasts the floor), else as drawn.
    duration_ms:
      Number.isFinite(recorded.duration_ms) && recorded.duration_ms > 0
        ? recorded.duration_ms
        : recorded.end_ms - recorded.start_ms,
    emitted_at_ms: recorded.end_ms,
    dropped,
  };
}

/** The recording as a drawing with id `id` (a new id: the sleeve would refuse the old seqs again). */
export function drawingFromRecording(recording: Recording, id: string, intensity: number): Drawing {
  const params = {
    ...recording.simplifier.params,
    algorithm: recording.simplifier.algorithm,
    rows: recording.sleeve.rows,
    columns: recording.sleeve.columns,
    canvas_width_px: recording.canvas.width_px,
    canvas_height_px: recording.canvas.height_px,
  } as unknown as SimplifierParams;
  const drawing = new Drawing(id, params);
  const pieces = [
    ...recording.strokes.map((s) => ({ recorded: s, intensity: s.intensity ?? intensity })),
    ...(recording.dropped ?? []).map((s) => ({ recorded: s, intensity })),
  ].sort((a, b) => a.recorded.path - b.recorded.path || a.recorded.start_ms - b.recorded.start_ms);
  recording.paths.forEach((samples, path) => {
    drawing.beginPath("mouse");
    for (const sample of samples) drawing.addSample(sample);
    for (const frame of recording.frames?.[path] ?? []) drawing.addFrame(frame);
    for (const piece of pieces) {
      if (piece.recorded.path === path) drawing.addSegment(segmentOf(piece.recorded), piece.intensity);
    }
  });
  return drawing;
}
