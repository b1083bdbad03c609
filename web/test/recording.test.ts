/**
 * Recordings: the format `feelmysign simplify` reads, and a replay of the
 * recorded frames through the simplifier gives back exactly the strokes sent.
 */
import { describe, expect, it } from "vitest";
import { Drawing } from "../src/drawing";
import { buildRecording, recordingFileName } from "../src/recording";
import { AngleSimplifier } from "../src/simplify/angle";
import { DEFAULT_ANGLE_PARAMS } from "../src/simplify/params";
import type { Sample } from "../src/simplify/segment";

const params = { ...DEFAULT_ANGLE_PARAMS, canvas_width_px: 600, canvas_height_px: 400 };

/** An L drawn at 60 frames per second starting at t = 5000 ms (a page's clock). */
function drawL(drawing: Drawing): void {
  const simplifier = new AngleSimplifier(params);
  drawing.beginPath("mouse");
  const frames: Sample[] = [];
  for (let k = 0; k <= 60; k++) frames.push({ t_ms: 5000 + k * 16.5, x: 100, y: 300 - k * 4, pressure: 0.5 });
  for (let k = 1; k <= 60; k++) frames.push({ t_ms: 6000 + k * 16.5, x: 100 + k * 6, y: 60, pressure: 0.5 });
  for (const frame of frames) {
    drawing.addSample(frame);
    drawing.addFrame(frame);
    for (const segment of simplifier.push(frame)) drawing.addSegment(segment, 0.8);
  }
  for (const segment of simplifier.end()) drawing.addSegment(segment, 0.8);
}

describe("recording", () => {
  const drawing = new Drawing("d-1", params);
  drawL(drawing);
  const recording = JSON.parse(JSON.stringify(buildRecording(drawing, new Date("2024-11-22T10:30:05Z"))));

  it("has the keys and shapes of docs/research.md", () => {
    expect(recording.canvas).toEqual({ width_px: 600, height_px: 400 });
    expect(recording.sleeve).toEqual({ rows: 3, columns: 4 });
    expect(recording.simplifier.algorithm).toBe("angle");
    expect(recording.simplifier.params).toMatchObject({ check_frames: 5, max_angle_deg: 20, recover: true });
    expect(recording.paths).toHaveLength(1);
    expect(recording.paths[0][0]).toEqual({ t_ms: 0, x: 100, y: 300, pressure: 0.5 });
    for (const sample of recording.paths[0]) {
      expect(Object.keys(sample).sort()).toEqual(["pressure", "t_ms", "x", "y"]);
    }
  });

  it("keeps the strokes sent, with their seq, and replaying its frames gives them back", () => {
    expect(recording.strokes.map((s: { seq: number }) => s.seq)).toEqual([0, 1]);
    const simplifier = new AngleSimplifier({ ...params, ...recording.simplifier.params });
    const replayed = recording.frames[0].flatMap((frame: Sample) => simplifier.push(frame));
    replayed.push(...simplifier.end());
    const kept = replayed.filter((segment: { dropped: string | null }) => segment.dropped === null);
    expect(kept.map((s: { start: number[]; end: number[] }) => [s.start, s.end])).toEqual(
      recording.strokes.map((s: { start: number[]; end: number[] }) => [s.start, s.end]),
    );
  });

  it("names files so that they sort by time", () => {
    expect(recordingFileName(new Date("2024-11-22T10:30:05Z"))).toBe(
      "feelmysign-drawing-2024-11-22T10-30-05.json",
    );
  });
});

describe("drawing", () => {
  it("numbers the sent strokes from 0 and finds them by seq", () => {
    const drawing = new Drawing("d-2", params);
    drawL(drawing);
    expect(drawing.strokeCount).toBe(2);
    expect(drawing.bySeq(1)?.stroke?.seq).toBe(1);
    expect(drawing.bySeq(2)).toBeUndefined();
  });

  it("averages the pressure of the frames a segment spans", () => {
    const drawing = new Drawing("d-3", params);
    drawing.beginPath("pen");
    [0.2, 0.4, 0.9].forEach((pressure, k) => drawing.addFrame({ t_ms: k * 10, x: 0, y: 0, pressure }));
    expect(drawing.meanPressure(10, 20)).toBeCloseTo(0.65);
    expect(drawing.meanPressure(0, 0)).toBeCloseTo(0.2);
  });

  it("keeps recorded times from going back", () => {
    const drawing = new Drawing("d-4", params);
    drawing.beginPath("touch");
    drawing.addSample({ t_ms: 10, x: 0, y: 0, pressure: 1 });
    drawing.addSample({ t_ms: 9, x: 1, y: 0, pressure: 1 });
    expect(drawing.paths[0]!.map((s) => s.t_ms)).toEqual([10, 10]);
  });
});
