/**
 * Pointer Events in, samples out: mouse, touch and pen alike. One pointer at a
 * time draws (a second finger is ignored), the pointer is captured so a path
 * that leaves the canvas goes on, and the coalesced events a browser batches
 * between two frames are all kept, with their pressure.
 */
import type { PointerKind } from "../drawing";
import type { Sample } from "../simplify/segment";
import type { DrawingView } from "./canvas";

export interface PointerHandlers {
  /**
   * `sample` is read only after the handler has chosen the drawing (a press may start a
   * new one, whose canvas size converts the position).
   */
  press(sample: () => Sample, kind: PointerKind): void;
  move(samples: Sample[]): void;
  release(sample: Sample): void;
}

function kindOf(event: PointerEvent): PointerKind {
  return event.pointerType === "pen" || event.pointerType === "touch" ? event.pointerType : "mouse";
}

/**
 * A pointer held still sends no events. After this long without one (ms, two frames) the page
 * samples it where it is, and again as often while it stays: the simplifier's rest rule then
 * sees the rest, and a stop mid-path is not played as a stroke as long as the stop.
 */
export const STILL_SAMPLE_MS = 32;

export function attachPointer(view: DrawingView, handlers: PointerHandlers): () => void {
  const surface = view.surface;
  let activeId: number | null = null;
  let lastPressure = 0.5;
  /** The last sample of the pointer down (real or sampled still), and the timer that samples it. */
  let last: Sample | null = null;
  let still: ReturnType<typeof setInterval> | null = null;

  const sample = (event: PointerEvent): Sample => {
    const [x, y] = view.toDrawing(event.clientX, event.clientY);
    const pressure = Number.isFinite(event.pressure) ? Math.min(Math.max(event.pressure, 0), 1) : 0.5;
    lastPressure = pressure;
    // An event handled after a still sample may be older than it: never back in time.
    const t = last !== null && event.timeStamp < last.t_ms ? last.t_ms : event.timeStamp;
    last = { t_ms: t, x, y, pressure };
    return last;
  };

  // Event times and performance.now() share one clock (the page's time origin).
  const sampleStill = (): void => {
    const now = performance.now();
    if (activeId === null || last === null || now - last.t_ms < STILL_SAMPLE_MS) return;
    last = { t_ms: now, x: last.x, y: last.y, pressure: last.pressure };
    handlers.move([last]);
  };
  const stopStill = (): void => {
    if (still !== null) clearInterval(still);
    still = null;
    last = null;
  };

  const onDown = (event: PointerEvent): void => {
    if (activeId !== null || (event.pointerType === "mouse" && event.button !== 0)) return;
    event.preventDefault();
    activeId = event.pointerId;
    try {
      surface.setPointerCapture(event.pointerId);
    } catch {
      // A pointer that is already gone cannot be captured; the path still works inside the canvas.
    }
    stopStill();
    view.beginPointer();
    handlers.press(() => sample(event), kindOf(event));
    still = setInterval(sampleStill, STILL_SAMPLE_MS / 2);
  };

  const onMove = (event: PointerEvent): void => {
    if (event.pointerId !== activeId) return;
    const batch = typeof event.getCoalescedEvents === "function" ? event.getCoalescedEvents() : [];
    handlers.move((batch.length > 0 ? batch : [event]).map(sample));
  };

  const onUp = (event: PointerEvent): void => {
    if (event.pointerId !== activeId) return;
    activeId = null;
    stopStill();
    // A lifted pointer reports pressure 0; the release point was drawn with the last pressure.
    const pressure = lastPressure;
    handlers.release({ ...sample(event), pressure });
  };

  const listeners: [string, (event: PointerEvent) => void][] = [
    ["pointerdown", onDown],
    ["pointermove", onMove],
    ["pointerup", onUp],
    // The browser took the pointer (a system gesture, a palm): the path ends where it was.
    ["pointercancel", onUp],
    ["lostpointercapture", onUp],
  ];
  for (const [type, listener] of listeners) surface.addEventListener(type, listener as EventListener);
  const noMenu = (event: Event) => event.preventDefault();
  surface.addEventListener("contextmenu", noMenu);
  return () => {
    stopStill();
    for (const [type, listener] of listeners) surface.removeEventListener(type, listener as EventListener);
    surface.removeEventListener("contextmenu", noMenu);
  };
}
