/** Drawings of several paths: Undo, Play again's copy, a saved recording loaded back, the outbox. */
import { describe, expect, it } from "vitest";
import { Drawing } from "../src/drawing";
import { Outbox } from "../src/outbox";
import { buildRecording } from "../src/recording";
import { drawingFromRecording, parseRecording } from "../src/recording-load";
import { AngleSimplifier } from "../src/simplify/angle";
import { DEFAULT_ANGLE_PARAMS } from "../src/simplify/params";
import type { Sample } from "../src/simplify/segment";
import { detailLevel, detailParams, detailValues } from "../src/ui/detail";

const params = { ...DEFAULT_ANGLE_PARAMS, canvas_width_px: 600, canvas_height_px: 400 };

/** A path of straight legs through `corners`, 60 frames a second, 40 frames a leg. */
function drawPath(drawing: Drawing, corners: [number, number][], t0: number): void {
  const simplifier = new AngleSimplifier(params);
  drawing.beginPath("mouse");
  let t = t0;
  for (let i = 1; i < corners.length; i++) {
    const [ax, ay] = corners[i - 1]!;
    const [bx, by] = corners[i]!;
    for (let k = i === 1 ? 0 : 1; k <= 40; k++) {
      const frame: Sample = {
        t_ms: t,
        x: ax + ((bx - ax) * k) / 40,
        y: ay + ((by - ay) * k) / 40,
        pressure: 0.5,
      };
      t += 1000 / 60;
      drawing.addSample(frame);
      drawing.addFrame(frame);
      for (const segment of simplifier.push(frame)) drawing.addSegment(segment, 0.8);
    }
  }
  for (const segment of simplifier.end()) drawing.addSegment(segment, 0.8);
}

function zAndSquare(): Drawing {
  const drawing = new Drawing("d-1", params);
  drawPath(
    drawing,
    [
      [50, 50],
      [250, 50],
      [50, 350],
      [250, 350],
    ],
    0,
  );
  drawPath(
    drawing,
    [
      [350, 100],
      [550, 100],
      [550, 300],
      [350, 300],
      [350, 100],
    ],
    5000,
  );
  return drawing;
}

describe("a drawing of several paths", () => {
  it("numbers the strokes of every path in one sequence", () => {
    const drawing = zAndSquare();
    expect(drawing.paths).toHaveLength(2);
    expect(drawing.strokes.map((s) => s.seq)).toEqual([...Array(drawing.strokes.length).keys()]);
    expect(drawing.strokes.length).toBeGreaterThanOrEqual(7);
    expect(drawing.keptStrokeCount).toBe(drawing.strokes.length);
  });

  it("Undo takes back the last path; its seqs are not used again", () => {
    const drawing = zAndSquare();
    const zStrokes = drawing.segments.filter((s) => s.path === 0 && s.stroke !== null).length;
    const numbered = drawing.strokeCount;
    expect(drawing.removeLastPath()).toBe(true);
    expect(drawing.paths).toHaveLength(1);
    expect(drawing.strokes).toHaveLength(zStrokes);
    expect(drawing.keptStrokeCount).toBe(zStrokes);
    expect(drawing.strokeCount).toBe(numbered);
    expect(drawing.bySeq(numbered - 1)).toBeUndefined();
    expect(drawing.removeLastPath()).toBe(true);
    expect(drawing.keptStrokeCount).toBe(0);
    expect(drawing.removeLastPath()).toBe(false);
  });

  it("Play again's copy has the same strokes, a new id, seqs from 0", () => {
    const drawing = zAndSquare();
    const copy = drawing.copyAs("d-2");
    expect(copy.id).toBe("d-2");
    const strip = (d: Drawing) =>
      d.strokes.map(({ start, end, duration_ms, intensity }) => ({ start, end, duration_ms, intensity }));
    expect(strip(copy)).toEqual(strip(drawing));
    expect(copy.strokes.map((s) => [s.drawing, s.seq])).toEqual(copy.strokes.map((_, i) => ["d-2", i]));
  });

  it("a saved recording loads back as the same drawing", () => {
    const drawing = zAndSquare();
    const text = JSON.stringify(buildRecording(drawing, new Date("2024-11-22T10:30:05Z")));
    const recording = parseRecording(text);
    if (typeof recording === "string") throw new Error(recording);
    const loaded = drawingFromRecording(recording, "d-3", 0.5);
    expect(loaded.paths).toHaveLength(2);
    expect(loaded.strokes.map(({ start, end }) => [start, end])).toEqual(
      drawing.strokes.map(({ start, end }) => [start, end]),
    );
    expect(loaded.strokes.map((s) => s.intensity)).toEqual(drawing.strokes.map(() => 0.8));
    expect(loaded.segments.filter((s) => s.segment.dropped !== null)).toHaveLength(
      drawing.segments.filter((s) => s.segment.dropped !== null).length,
    );
  });

  it.each([
    ["not JSON", "{", /not JSON/],
    ["an array", "[]", /no JSON object/],
    ["no canvas", '{"sleeve":{}}', /no "canvas"/],
    [
      "points without times",
      '{"canvas":{"width_px":1,"height_px":1},"sleeve":{"rows":3,"columns":4},"simplifier":{"params":{}},"paths":[[{"x":1}]]}',
      /"paths"/,
    ],
  ])("refuses %s with a sentence", (_what, text, message) => {
    expect(parseRecording(text)).toMatch(message);
  });
});

describe("the detail control", () => {
  it("goes from coarse to fine for both simplifiers and finds its own levels again", () => {
    for (let level = 1; level <= 5; level++) {
      expect(detailLevel("window", detailValues(level))).toBe(level);
      expect(detailLevel("angle", detailValues(level))).toBe(level);
    }
    expect(detailValues(1).max_error!).toBeGreaterThan(detailValues(5).max_error!);
    expect(detailValues(1).max_angle_deg!).toBeGreaterThan(detailValues(5).max_angle_deg!);
    expect(detailParams(params, 5)).toMatchObject({
      algorithm: "angle",
      max_angle_deg: detailValues(5).max_angle_deg,
    });
  });
});

describe("the outbox", () => {
  it("drops queued strokes of a cancelled drawing, and those waiting too long", () => {
    const outbox = new Outbox<{ drawing: string }>();
    outbox.add({ drawing: "a" }, 0);
    outbox.add({ drawing: "b" }, 0);
    outbox.add({ drawing: "a" }, 5000);
    expect(outbox.dropQueued((item) => item.drawing === "b")).toEqual([{ drawing: "b" }]);
    expect(outbox.dropQueued((_item, entry) => 6000 - entry.added_ms > 2000)).toEqual([{ drawing: "a" }]);
    expect(outbox.size).toBe(1);
  });
});

describe("strokes drawn faster than the sleeve can play", () => {
  it("are counted as the drawing grows and as paths are undone, and kept by Play again's copy", () => {
    const drawing = new Drawing("d-2", params);
    const piece = (startMs: number, endMs: number, durationMs: number) => ({
      start: [0, 0] as [number, number],
      end: [1, 0] as [number, number],
      start_ms: startMs,
      end_ms: endMs,
      duration_ms: durationMs,
      emitted_at_ms: endMs,
      dropped: null,
    });
    drawing.beginPath("mouse");
    drawing.addSegment(piece(0, 120, 120), 0.8);
    drawing.addSegment(piece(120, 150, 73.701), 0.8); // drawn in 30 ms, sent at the floor
    drawing.beginPath("mouse");
    drawing.addSegment(piece(400, 420, 73.701), 0.8);
    expect(drawing.lengthenedCount).toBe(2);
    expect(drawing.strokes.map((s) => s.duration_ms)).toEqual([120, 73.701, 73.701]);
    expect(drawing.copyAs("d-3").lengthenedCount).toBe(2);
    expect(drawing.removeLastPath()).toBe(true);
    expect(drawing.lengthenedCount).toBe(1);
  });
});
