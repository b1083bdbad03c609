/**
 * The sleeve, live: one circle per actuator that glows with the intensity the
 * sleeve's `actuators` telemetry reports, so the sender sees what the wearer
 * feels, when they feel it. Redrawn at most once per animation frame. Turned
 * a quarter, with the sleeve's top marked, whenever the drawing area is (an
 * upright phone), so a touch drawn on the right lights the right of the preview.
 */
import type { ActuatorFrame } from "../telemetry";
import { drawSleeveTop, setSleeveTransform } from "./canvas";
import { FrameRequest, fitToDevicePixels } from "./canvas-frame";
import type { GridSize } from "./geometry";

/** Turned, the strip along the sleeve's top edge (its right on the screen) for its marker. */
const TOP_STRIP_PX = 16;
/** Below this an actuator counts as off (telemetry rounding, a motor spinning down). */
const LIT_THRESHOLD = 0.02;
const GLOW = "255, 138, 91";

export class SleevePreview {
  readonly #canvas: HTMLCanvasElement;
  readonly #caption: HTMLElement;
  readonly #ctx: CanvasRenderingContext2D;
  #grid: GridSize = { rows: 3, columns: 4 };
  #frame: ActuatorFrame | null = null;
  readonly #redraw = new FrameRequest(() => this.#draw());
  #framesSeen = 0;
  #online = false;
  #turned = false;

  constructor(canvas: HTMLCanvasElement, caption: HTMLElement) {
    this.#canvas = canvas;
    this.#caption = caption;
    const ctx = canvas.getContext("2d");
    if (ctx === null) throw new Error("This browser cannot draw on a canvas (no 2D context).");
    this.#ctx = ctx;
    new ResizeObserver(() => this.#redraw.request()).observe(canvas);
    this.#redraw.request();
  }

  /**
   * The grid to show while no telemetry has arrived (the sleeve's status, or the settings), and
   * whether it is shown turned a quarter clockwise, as the drawing area is.
   */
  setGrid(grid: GridSize, turned = this.#turned): void {
    if (grid.rows === this.#grid.rows && grid.columns === this.#grid.columns && turned === this.#turned)
      return;
    this.#grid = grid;
    this.#turned = turned;
    const across = Math.max(turned ? grid.rows : grid.columns, 1);
    const down = Math.max(turned ? grid.columns : grid.rows, 1);
    this.#canvas.style.aspectRatio = `${across} / ${down}`;
    this.#canvas.dataset["turned"] = String(turned);
    this.#redraw.request();
  }

  show(frame: ActuatorFrame): void {
    this.#frame = frame;
    this.#framesSeen++;
    this.setGrid({ rows: frame.rows, columns: frame.columns });
    this.#redraw.request();
  }

  /**
   * The sleeve's state changed: `message` says so (the same as the status chip). Offline,
   * absent or unknown, nothing is felt any more; online, the frames that follow take over.
   */
  reset(message: string, online = false): void {
    if (!online) this.#frame = null;
    this.#online = online;
    this.#caption.textContent = message;
    this.#redraw.request();
  }

  #draw(): void {
    const canvas = this.#canvas;
    const { width, height, dpr } = fitToDevicePixels(canvas);
    if (width === 0 || height === 0) return;
    const ctx = this.#ctx;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, width, height);
    // Drawn in the sleeve's orientation; turned, the canvas's height is the sleeve's width.
    const turned = this.#turned;
    setSleeveTransform(ctx, turned, width, 0, dpr);
    const across = turned ? height : width;
    const down = turned ? width - TOP_STRIP_PX : height;
    const { rows, columns } = this.#grid;
    const cell = Math.min(across / columns, down / rows);
    const radius = cell * 0.26;
    const left = (across - cell * columns) / 2 + cell / 2;
    const top = (turned ? TOP_STRIP_PX : 0) + (down - cell * rows) / 2 + cell / 2;
    if (turned) {
      // Along the grid's top edge, as long as the grid: the marker stays beside the actuators.
      ctx.save();
      ctx.translate(left - cell / 2, 0);
      drawSleeveTop(ctx, cell * columns, top - cell / 2 - TOP_STRIP_PX / 2);
      ctx.restore();
    }
    let lit = 0;
    let strongest = 0;
    for (let row = 0; row < rows; row++) {
      for (let column = 0; column < columns; column++) {
        const value = this.#frame?.intensities[row]?.[column] ?? 0;
        const x = left + column * cell;
        const y = top + row * cell;
        if (value > LIT_THRESHOLD) {
          lit++;
          const glow = ctx.createRadialGradient(x, y, radius * 0.4, x, y, radius * (1.2 + 1.3 * value));
          glow.addColorStop(0, `rgba(${GLOW}, ${0.55 * value})`);
          glow.addColorStop(1, `rgba(${GLOW}, 0)`);
          ctx.fillStyle = glow;
          ctx.fillRect(x - cell / 2, y - cell / 2, cell, cell);
        }
        strongest = Math.max(strongest, value);
        ctx.beginPath();
        ctx.arc(x, y, radius, 0, 2 * Math.PI);
        ctx.fillStyle =
          value > LIT_THRESHOLD ? `rgba(${GLOW}, ${0.25 + 0.75 * value})` : "rgba(143, 160, 178, 0.10)";
        ctx.fill();
        ctx.lineWidth = 1.5;
        ctx.strokeStyle =
          value > LIT_THRESHOLD ? `rgba(255, 200, 170, ${0.5 + 0.5 * value})` : "rgba(143, 160, 178, 0.35)";
        ctx.stroke();
      }
    }
    // For tests and assistive tech: how many actuators are on, and the strongest intensity.
    canvas.dataset["lit"] = String(lit);
    canvas.dataset["maxIntensity"] = strongest.toFixed(3);
    canvas.setAttribute(
      "aria-label",
      lit === 0
        ? "Sleeve preview: all actuators off"
        : `Sleeve preview: ${lit} actuator(s) on, strongest ${Math.round(strongest * 100)}%`,
    );
    if (this.#frame !== null && this.#online) {
      this.#caption.textContent =
        lit === 0
          ? `${rows} × ${columns} actuators · all still`
          : `${rows} × ${columns} actuators · ${lit} vibrating`;
    }
  }

  get framesSeen(): number {
    return this.#framesSeen;
  }
}
