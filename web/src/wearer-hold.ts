/**
 * The page's side of the wearer's choice: while the wearer has paused the sleeve (or asked not to
 * be disturbed), the strokes drawn are kept on the page instead of being sent into refusals; when
 * the wearer is back, the page offers to send them. No DOM and no clock of its own (times are
 * passed in), so the unit tests drive it as the page does.
 *
 * Held strokes are sent on resume under their own drawing and seq (they were never sent, so the
 * sleeve has no copy of them), stamped `sent_at_ms` when they go out as every stroke is: a drawing
 * held for minutes is then neither `stale` nor `late` by the sleeve's pace rules (docs/protocol.md
 * "Pace"). They play back to back, at once, not at the pace they were drawn.
 */
import type { Stroke } from "./protocol";
import type { SleeveControls } from "./events";
import { NO_CONTROLS, wearerHold, type EndedHold, type WearerHold } from "./wearer-status";

/**
 * A "do not disturb" that ends within this of its time ended by itself, not by the wearer: the
 * sleeve's timer fires at the time, its status a moment later, and two clocks never agree exactly.
 */
const RAN_OUT_SLACK_MS = 1000;

/** What the page's wearer notice shows. `ended`: the hold the wearer (or the time) ended, if seen. */
export type WearerView =
  | { readonly state: "none" }
  | { readonly state: "held"; readonly hold: WearerHold; readonly held: number }
  | { readonly state: "resumed"; readonly held: number; readonly ended: EndedHold | null };

/** What holds the drawing changed, `before` to `after` (null: nothing); for the page's log. */
export interface HoldChange {
  readonly before: WearerHold | null;
  readonly after: WearerHold | null;
  /** A "do not disturb" ended as it reached its time (not ended by the wearer). */
  readonly ranOut: boolean;
}

export class WearerHoldKeeper {
  #controls: SleeveControls = NO_CONTROLS;
  /** When the sleeve paused, when this page saw it happen (the status that said so). */
  #pausedSinceMs: number | null = null;
  #held: Stroke[] = [];
  /** The wearer ended a hold this page saw: shown until the held strokes are sent or dropped. */
  #resumed = false;
  /** The hold that ended last, and how (for the resumed notice's headline). */
  #ended: EndedHold | null = null;
  /** What held the drawing at the last status or tick. */
  #lastHold: WearerHold | null = null;
  /** A status has been read since the page (or the sleeve) started. */
  #seen = false;

  get controls(): SleeveControls {
    return this.#controls;
  }

  get ceiling(): number | null {
    return this.#controls.ceiling;
  }

  /** What holds the drawing at `nowMs`, or null. */
  hold(nowMs: number): WearerHold | null {
    return wearerHold(this.#controls, nowMs, this.#pausedSinceMs);
  }

  /**
   * A status: its `controls` (NO_CONTROLS when it has none), whether it is an online one, and its
   * `at_ms`. An offline status (the last will) carries no controls: the wearer's choice is kept
   * on the sleeve, so the page keeps the last it knew until the sleeve reports again. Returns what
   * changed in what holds the drawing, or null.
   */
  onStatus(controls: SleeveControls, online: boolean, atMs: number | null, nowMs: number): HoldChange | null {
    if (!online) return null;
    if (controls.paused && !this.#controls.paused) {
      // The first status of this page: paused since before it looked, time unknown.
      this.#pausedSinceMs = this.#seen ? atMs : null;
    }
    if (!controls.paused) this.#pausedSinceMs = null;
    this.#controls = controls;
    this.#seen = true;
    return this.#observe(nowMs, atMs);
  }

  /** Time passed: a "do not disturb" may have run out, and the wearer is back. Returns the change, or null. */
  tick(nowMs: number): HoldChange | null {
    return this.#observe(nowMs, null);
  }

  /** What holds the drawing now against what held it when last looked; `atMs`: the status's time. */
  #observe(nowMs: number, atMs: number | null): HoldChange | null {
    const before = this.#lastHold;
    const after = this.hold(nowMs);
    this.#lastHold = after;
    if (sameHold(before, after)) return null;
    let ranOut = false;
    if (after !== null) {
      this.#resumed = false;
    } else if (before !== null) {
      // The sleeve's clock (the status's time) or the page's, whichever is later, reached the end.
      ranOut =
        before.reason === "do_not_disturb" &&
        Math.max(atMs ?? nowMs, nowMs) >= before.untilMs - RAN_OUT_SLACK_MS;
      this.#resumed = true;
      this.#ended = { hold: before, ranOut };
    }
    return { before, after, ranOut };
  }

  /** Another sleeve: nothing is known of its wearer. */
  forgetSleeve(): void {
    this.#controls = NO_CONTROLS;
    this.#pausedSinceMs = null;
    this.#seen = false;
    this.#resumed = false;
    this.#ended = null;
    this.#lastHold = null;
  }

  /** True when `stroke` is kept on the page (held), false when it may be sent. */
  keep(stroke: Stroke, nowMs: number): boolean {
    if (this.hold(nowMs) === null) return false;
    this.#held.push(stroke);
    return true;
  }

  get heldCount(): number {
    return this.#held.length;
  }

  /** The held strokes, in the order drawn, handed over to be sent (or dropped): none are held after. */
  take(): Stroke[] {
    const strokes = this.#held;
    this.#held = [];
    this.#resumed = false;
    return strokes;
  }

  /** Keeps held only the strokes `kept` says to (Undo took a path back); returns the others. */
  release(kept: (stroke: Stroke) => boolean): Stroke[] {
    const gone = this.#held.filter((stroke) => !kept(stroke));
    this.#held = this.#held.filter(kept);
    return gone;
  }

  /** A new drawing: the held strokes of the old one are given back (to count as never sent). */
  newDrawing(): Stroke[] {
    const strokes = this.#held;
    this.#held = [];
    if (strokes.length > 0) this.#resumed = false;
    return strokes;
  }

  /** The resumed notice was read (a stroke was sent with nothing held): it goes. */
  dismissResumed(): void {
    if (this.#held.length === 0) this.#resumed = false;
  }

  view(nowMs: number): WearerView {
    const hold = this.hold(nowMs);
    if (hold !== null) return { state: "held", hold, held: this.#held.length };
    if (this.#resumed || this.#held.length > 0)
      return { state: "resumed", held: this.#held.length, ended: this.#ended };
    return { state: "none" };
  }
}

function sameHold(a: WearerHold | null, b: WearerHold | null): boolean {
  if (a === null || b === null) return a === b;
  return a.reason === b.reason && a.untilMs === b.untilMs;
}
