/**
 * The window simplifier in the page: its settings (validated with the
 * reference's ranges, locked to the chosen algorithm), the parameters a
 * drawing gets, and a recording that names it and replays to the same strokes.
 */
import { describe, expect, it } from "vitest";
import { Drawing } from "../src/drawing";
import { buildRecording } from "../src/recording";
import {
  DEFAULT_SETTINGS,
  loadSettings,
  simplifierParams,
  STORAGE_KEY,
  validateSettings,
} from "../src/settings";
import { makeSimplifier } from "../src/simplify/registry";
import type { Sample } from "../src/simplify/segment";
import { WindowSimplifier } from "../src/simplify/window";
import { windowParamSpec, type WindowParams } from "../src/simplify/window-params";

const GRID = { rows: 3, columns: 4 };
const CANVAS = { width_px: 600, height_px: 400 };

describe("window settings", () => {
  it("makes the window simplifier the default, with its own defaults", () => {
    expect(DEFAULT_SETTINGS.algorithm).toBe("window");
    expect(DEFAULT_SETTINGS.max_error).toBe(windowParamSpec("max_error").default);
    expect(DEFAULT_SETTINGS.max_window).toBe(windowParamSpec("max_window").default);
    expect(DEFAULT_SETTINGS.max_stroke_ms).toBe(windowParamSpec("max_stroke_ms").default);
    expect(makeSimplifier(simplifierParams(DEFAULT_SETTINGS, GRID, CANVAS))).toBeInstanceOf(WindowSimplifier);
  });

  it("validates max error and the window cap with the reference's ranges", () => {
    const errors = validateSettings({ ...DEFAULT_SETTINGS, max_error: 0, max_window: 2.5, algorithm: "dp" });
    expect(errors.max_error).toBe("Max error must be a number from 0.001 to 100.");
    expect(errors.max_window).toBe("Window cap must be a whole number from 1 to 10000.");
    expect(errors.algorithm).toBe("Simplifier must be a listed choice.");
  });

  it("persists the choice", () => {
    const stored = { algorithm: "window", max_error: 0.05, max_window: 10 };
    const storage = { getItem: (key: string) => (key === STORAGE_KEY ? JSON.stringify(stored) : null) };
    expect(loadSettings(storage, null).settings).toMatchObject(stored);
  });

  it("gives a drawing the window simplifier when chosen", () => {
    const settings = { ...DEFAULT_SETTINGS, algorithm: "window" as const, max_error: 0.05, max_window: 10 };
    const params = simplifierParams(settings, GRID, CANVAS) as WindowParams;
    expect(params).toMatchObject({ max_error: 0.05, max_window: 10, rows: 3, canvas_width_px: 600 });
    expect(makeSimplifier(params)).toBeInstanceOf(WindowSimplifier);
  });
});

describe("a window recording", () => {
  const settings = { ...DEFAULT_SETTINGS, algorithm: "window" as const, max_error: 0.02 };
  const params = simplifierParams(settings, GRID, CANVAS);
  const drawing = new Drawing("d-1", params);
  const simplifier = makeSimplifier(params);
  drawing.beginPath("mouse");
  for (let k = 0; k <= 120; k++) {
    const angle = (k / 120) * Math.PI;
    const frame: Sample = {
      t_ms: 1000 + k * 16.5,
      x: 300 + 150 * Math.cos(angle),
      y: 200 + 150 * Math.sin(angle),
      pressure: 0.5,
    };
    drawing.addSample(frame);
    drawing.addFrame(frame);
    for (const segment of simplifier.push(frame)) drawing.addSegment(segment, 0.8);
  }
  for (const segment of simplifier.end()) drawing.addSegment(segment, 0.8);
  const recording = buildRecording(drawing, new Date("2024-11-22T10:30:05Z"));

  it("names the algorithm and its parameters, without the canvas and grid", () => {
    expect(recording.simplifier.algorithm).toBe("window");
    expect(recording.simplifier.params).toMatchObject({ max_error: 0.02, max_window: 256 });
    expect(Object.keys(recording.simplifier.params)).not.toContain("fps");
    expect(Object.keys(recording.simplifier.params)).not.toContain("rows");
  });

  it("replays its frames to the strokes sent", () => {
    const again = new WindowSimplifier({ ...params, ...recording.simplifier.params } as WindowParams);
    const segments = recording.frames[0]!.flatMap((frame) => again.push(frame));
    segments.push(...again.end());
    const sent = segments.filter((segment) => segment.dropped === null);
    expect(sent.length).toBe(recording.strokes.length);
    expect(sent.length).toBeGreaterThan(3);
    sent.forEach((segment, i) => {
      expect(segment.start).toEqual(recording.strokes[i]!.start);
      expect(segment.end).toEqual(recording.strokes[i]!.end);
    });
  });
});
