/**
 * Animation frames from a live pointer: the simplifier is frame based (the
 * paper's Processing sketch saw the mouse once per draw()), so the page feeds
 * it the pointer position held at each animation frame, with the frame's real
 * timestamp. As in `simplify/frames.ts`, the press is the first frame and the
 * release the last. Pure: times come in as arguments.
 */
import type { Sample } from "./simplify/segment";

/**
 * A frame is taken when at least this share of the period has passed since the
 * previous one: animation frames jitter by a fraction of a millisecond, and a
 * 60 Hz display must give every frame at fps = 60, every other one at 30.
 */
const PERIOD_SLACK = 0.75;

export class FrameSampler {
  readonly #minGapMs: number;
  #held: Sample | null = null;
  #lastFrameMs = -Infinity;

  /** `fps` caps the frame rate; the display's refresh rate is the other cap. */
  constructor(fps: number) {
    this.#minGapMs = (1000 / fps) * PERIOD_SLACK;
  }

  get pressed(): boolean {
    return this.#held !== null;
  }

  /** The press: the first frame. */
  press(sample: Sample): Sample {
    this.#held = sample;
    this.#lastFrameMs = sample.t_ms;
    return sample;
  }

  /** A newer pointer reading, held until the next frame. */
  hold(sample: Sample): void {
    if (this.#held !== null) this.#held = sample;
  }

  /** The frame of an animation frame at `tMs`, or null when not pressed or too soon. */
  tick(tMs: number): Sample | null {
    const held = this.#held;
    if (held === null || tMs - this.#lastFrameMs < this.#minGapMs) return null;
    this.#lastFrameMs = tMs;
    return { t_ms: tMs, x: held.x, y: held.y, pressure: held.pressure };
  }

  /** The release: the last frame, never earlier than the frame before it. */
  release(sample: Sample): Sample {
    const t_ms = Math.max(sample.t_ms, this.#lastFrameMs);
    this.#held = null;
    this.#lastFrameMs = -Infinity;
    return { ...sample, t_ms };
  }
}
