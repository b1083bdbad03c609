/**
 * One drawing in progress, without a browser: pointer samples in, strokes out to the sender,
 * ink to a stand-in for the canvas, animation frames run by hand.
 */
import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";
import type { Drawing, DrawnSegment } from "../src/drawing";
import type { Stroke } from "../src/protocol";
import { DEFAULT_SETTINGS, type Settings } from "../src/settings";
import type { Sample } from "../src/simplify/segment";
import { DrawingSession, type SessionView } from "../src/ui/drawing-session";

/** What the canvas was asked to do. */
class FakeView implements SessionView {
  readonly area = { width_px: 300, height_px: 200 };
  shown: Drawing | null = null;
  sent: DrawnSegment[] = [];
  rejected: DrawnSegment[] = [];
  flushes = 0;
  live: Sample | null = null;
  setDrawing(drawing: Drawing | null): void {
    this.shown = drawing;
    this.sent = [];
    this.rejected = [];
  }
  flush(): void {
    this.flushes++;
  }
  clearLive(): void {
    this.live = null;
  }
  drawLive(_lineStart: Sample | null, pointer: Sample | null): void {
    this.live = pointer;
  }
  markSent(drawn: DrawnSegment): void {
    this.sent.push(drawn);
  }
  markRejected(drawn: DrawnSegment): void {
    this.rejected.push(drawn);
  }
}

/** requestAnimationFrame by hand: `frame()` runs what is waiting, at the next 60 fps time. */
let waiting: FrameRequestCallback[] = [];
let nowMs = 0;
function frame(): void {
  nowMs += 1000 / 60;
  for (const callback of waiting.splice(0)) callback(nowMs);
}

beforeEach(() => {
  waiting = [];
  nowMs = 0;
  vi.stubGlobal("requestAnimationFrame", (callback: FrameRequestCallback) => {
    waiting.push(callback);
    return waiting.length;
  });
});
afterEach(() => {
  vi.unstubAllGlobals();
});

function setup(overrides: Partial<Settings> = {}) {
  const settings: Settings = { ...DEFAULT_SETTINGS, ...overrides };
  const view = new FakeView();
  const sent: Stroke[] = [];
  const changes: (Drawing | null)[] = [];
  let released = 0;
  const session = new DrawingSession(view, {
    settings: () => settings,
    grid: () => ({ rows: settings.rows, columns: settings.columns }),
    send: (stroke) => sent.push(stroke),
    changed: (drawing) => changes.push(drawing),
    released: () => released++,
  });
  return { session, view, sent, changes, released: () => released };
}

/** Samples every 5 px along the polyline, one every 16 ms from `t0Ms`. */
function along(points: readonly (readonly [number, number])[], t0Ms = 0): Sample[] {
  const out: Sample[] = [];
  let t = t0Ms;
  const [x0, y0] = points[0]!;
  out.push({ t_ms: t, x: x0, y: y0, pressure: 0.5 });
  for (let i = 1; i < points.length; i++) {
    const [ax, ay] = points[i - 1]!;
    const [bx, by] = points[i]!;
    const steps = Math.max(1, Math.round(Math.hypot(bx - ax, by - ay) / 5));
    for (let k = 1; k <= steps; k++) {
      t += 16;
      out.push({ t_ms: t, x: ax + ((bx - ax) * k) / steps, y: ay + ((by - ay) * k) / steps, pressure: 0.5 });
    }
  }
  return out;
}

/** An L: along the top, then down the right side. */
const L: readonly (readonly [number, number])[] = [
  [20, 20],
  [280, 20],
  [280, 180],
];
/** A second line, drawn after L into the same drawing. */
const DIAGONAL: readonly (readonly [number, number])[] = [
  [20, 180],
  [150, 100],
];

/** Presses at the first sample, moves through the rest a frame each, and (unless told) releases. */
function drawPath(session: DrawingSession, samples: readonly Sample[], release = true): void {
  session.press(() => samples[0]!, "mouse");
  for (const sample of samples.slice(1, -1)) {
    session.move([sample]);
    frame();
  }
  if (release) session.release(samples[samples.length - 1]!);
}

describe("a drawing session", () => {
  it("sends a path's strokes in order, numbered from 0, as they are drawn", () => {
    const { session, sent, changes, released } = setup();
    drawPath(session, along(L));
    const drawing = session.drawing!;
    expect(sent.length).toBeGreaterThanOrEqual(2);
    expect(sent.map((stroke) => stroke.seq)).toEqual(sent.map((_, i) => i));
    expect(new Set(sent.map((stroke) => stroke.drawing))).toEqual(new Set([drawing.id]));
    expect(drawing.strokes).toEqual(sent);
    expect(drawing.paths).toHaveLength(1);
    expect(changes[0]).toBe(drawing);
    expect(released()).toBe(1);
    expect(session.pressed).toBe(false);
  });

  it("runs the animation loop only while the pointer is down", () => {
    const { session } = setup();
    const samples = along(L);
    drawPath(session, samples, false);
    expect(waiting.length).toBe(1);
    session.release(samples[samples.length - 1]!);
    frame();
    expect(waiting.length).toBe(0);
  });

  it("adds the next path to the same drawing, or starts a new one after close", () => {
    const { session, sent } = setup();
    drawPath(session, along(L));
    const first = session.drawing!;
    const count = sent.length;
    drawPath(session, along(DIAGONAL, 5000));
    expect(session.drawing).toBe(first);
    expect(first.paths).toHaveLength(2);
    expect(sent[count]!.seq).toBe(count);
    session.close();
    drawPath(session, along(DIAGONAL, 9000));
    const second = session.drawing!;
    expect(second).not.toBe(first);
    const fresh = sent.filter((stroke) => stroke.drawing === second.id);
    expect(fresh.length).toBeGreaterThan(0);
    expect(fresh.map((stroke) => stroke.seq)).toEqual(fresh.map((_, i) => i));
  });

  it("draws an acknowledged stroke solid, and only its own drawing's", () => {
    const { session, view, sent } = setup();
    drawPath(session, along(L));
    session.acked(sent[1]!);
    session.acked({ ...sent[0]!, drawing: "another" });
    expect(view.sent.map((drawn) => drawn.stroke?.seq)).toEqual([1]);
    expect(session.drawing!.isAcked(view.sent[0]!)).toBe(true);
    // Drawn at the next frame, once.
    const before = view.flushes;
    frame();
    expect(view.flushes).toBe(before + 1);
  });

  it("marks a refused stroke by its seq, and ignores a seq it never sent", () => {
    const { session, view } = setup();
    drawPath(session, along(L));
    session.refused(1);
    session.refused(999);
    expect(view.rejected.map((drawn) => drawn.stroke?.seq)).toEqual([1]);
  });

  it("keeps a refused stroke refused: after a later path is undone, and whenever its ack comes", () => {
    const { session, view, sent } = setup();
    drawPath(session, along(L));
    const drawing = session.drawing!;
    drawPath(session, along(DIAGONAL, 5000));
    session.refused(0);
    session.acked(sent[0]!);
    const first = drawing.bySeq(0)!;
    expect(drawing.isRefused(first)).toBe(true);
    expect(drawing.isRefused(drawing.bySeq(1)!)).toBe(false);
    // Undo redraws the drawing from scratch: the canvas reads the refusal from the drawing.
    expect(session.undo()).toBe(true);
    expect(view.shown).toBe(drawing);
    expect(drawing.isRefused(first)).toBe(true);
  });

  it("takes back the last path, and clears the canvas with the first", () => {
    const { session, changes } = setup();
    drawPath(session, along(L));
    drawPath(session, along(DIAGONAL, 5000));
    expect(session.undo()).toBe(true);
    expect(session.drawing!.paths).toHaveLength(1);
    expect(session.undo()).toBe(true);
    expect(session.drawing).toBeNull();
    expect(changes[changes.length - 1]).toBeNull();
    expect(session.undo()).toBe(false);
  });

  it("ends the path under way at Stop: nothing more is drawn or sent until the next press", () => {
    const { session, sent, view, released } = setup();
    const samples = along(L);
    const corner = samples.findIndex((sample) => sample.x === 280);
    // Pressed, along the top to the corner, then Stop with the pointer still down.
    drawPath(session, samples.slice(0, corner + 1), false);
    const drawing = session.drawing!;
    const sentAtStop = sent.length;
    const samplesAtStop = drawing.paths[0]!.length;
    session.endPath();
    expect(session.pressed).toBe(false);
    expect(released()).toBe(1);
    expect(view.live).toBeNull();
    // The hand goes on down the side and lifts: none of it is drawn or sent.
    for (const sample of samples.slice(corner + 1)) {
      session.move([sample]);
      frame();
    }
    session.release(samples[samples.length - 1]!);
    expect(sent).toHaveLength(sentAtStop);
    expect(drawing.paths[0]).toHaveLength(samplesAtStop);
    expect(released()).toBe(1);
    expect(waiting).toHaveLength(0);
    // The next press draws again, into the same drawing (Stop's close() is the page's to call).
    drawPath(session, along(DIAGONAL, 9000));
    expect(session.drawing).toBe(drawing);
    expect(drawing.paths).toHaveLength(2);
    expect(sent.length).toBeGreaterThan(sentAtStop);
    expect(sent.map((stroke) => stroke.seq)).toEqual(sent.map((_, i) => i));
  });

  it("neither clears nor undoes while the pointer is down", () => {
    const { session } = setup();
    drawPath(session, along(L), false);
    session.clear();
    expect(session.undo()).toBe(false);
    expect(session.drawing).not.toBeNull();
  });

  it("cuts the paths again under new settings as a new drawing, not sent", () => {
    const settings = { ...DEFAULT_SETTINGS, algorithm: "angle" as const };
    const { session, sent } = setup(settings);
    drawPath(session, along(L));
    const first = session.drawing!;
    const count = sent.length;
    const again = session.recut()!;
    expect(again.id).not.toBe(first.id);
    expect(again.paths).toEqual(first.paths);
    expect(again.strokes.length).toBeGreaterThan(0);
    expect(session.drawing).toBe(again);
    expect(sent).toHaveLength(count);
  });

  it("has nothing to cut again without a drawing", () => {
    const { session } = setup();
    expect(session.recut()).toBeNull();
  });
});
