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

export function attachPointer(view: DrawingView, handlers: PointerHandlers): () => void {
  const surface = view.surface;
  let activeId: number | null = null;
  let lastPressure = 0.5;

  const sample = (event: PointerEvent): Sample => {
    const [x, y] = view.toDrawing(event.clientX, event.clientY);
    const pressure = Number.isFinite(event.pressure) ? Math.min(Math.max(event.pressure, 0), 1) : 0.5;
    lastPressure = pressure;
    return { t_ms: event.timeStamp, x, y, pressure };
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
    view.beginPointer();
    handlers.press(() => sample(event), kindOf(event));
  };

  const onMove = (event: PointerEvent): void => {
    if (event.pointerId !== activeId) return;
    const batch = typeof event.getCoalescedEvents === "function" ? event.getCoalescedEvents() : [];
    handlers.move((batch.length > 0 ? batch : [event]).map(sample));
  };

  const onUp = (event: PointerEvent): void => {
    if (event.pointerId !== activeId) return;
    activeId = null;
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
    for (const [type, listener] of listeners) surface.removeEventListener(type, listener as EventListener);
    surface.removeEventListener("contextmenu", noMenu);
  };
}
