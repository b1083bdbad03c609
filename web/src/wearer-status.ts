/**
 * What a sender does with the wearer's choice, as the sleeve's retained status carries it
 * (`controls`, docs/protocol.md, read by events.ts): paused, an intensity ceiling, "do not
 * disturb" until a time. The wearer's choice always wins
 * over the sender's, so a sender holds its drawing instead of sending it into refusals, and says
 * what the sleeve will play. A status without `controls` (an older sleeve, a last will) means
 * none of them.
 */

import { atClock, untilClock } from "./clock";
import { drivePercent } from "./drive-level";
import { DO_NOT_DISTURB_REASON, PAUSED_REASON, type SleeveControls } from "./events";

/** What a status without `controls` means: not paused, no ceiling, no "do not disturb". */
export const NO_CONTROLS: SleeveControls = {
  paused: false,
  paused_by: null,
  ceiling: null,
  do_not_disturb_until_ms: null,
};

/**
 * Why the sleeve plays nothing now by the wearer's choice. `sinceMs`: when it paused, if known;
 * a pause's `untilMs`: a "do not disturb" that runs under the pause and still holds after a resume.
 */
export type WearerHold =
  | {
      readonly reason: "paused";
      readonly sinceMs: number | null;
      readonly untilMs: number | null;
      /** Paused by the sleeve itself: it could not read its wearer's last choices at start. */
      readonly bySleeve?: true;
    }
  | { readonly reason: "do_not_disturb"; readonly untilMs: number };

/** A status's `paused_by` when the sleeve paused itself (Python `wearer_status.PAUSED_BY_SLEEVE`). */
export const PAUSED_BY_SLEEVE = "sleeve";

/** Who paused, as the notices say it. */
function pausedWho(hold: { readonly bySleeve?: true }): string {
  return hold.bySleeve
    ? "The sleeve paused itself (it could not read its wearer's last choices)"
    : "The wearer paused the sleeve";
}

/**
 * What holds the drawing at `nowMs`, or null. Pausing wins over "do not disturb" (it has no end),
 * and a "do not disturb" whose time has passed holds nothing, whether or not the sleeve has said so.
 */
export function wearerHold(
  controls: SleeveControls,
  nowMs: number,
  sinceMs: number | null = null,
): WearerHold | null {
  const dndUntilMs = controls.do_not_disturb_until_ms;
  const untilMs = dndUntilMs !== null && dndUntilMs > nowMs ? dndUntilMs : null;
  if (controls.paused) {
    return controls.paused_by === PAUSED_BY_SLEEVE
      ? { reason: "paused", sinceMs, untilMs, bySleeve: true }
      : { reason: "paused", sinceMs, untilMs };
  }
  if (untilMs !== null) return { reason: "do_not_disturb", untilMs };
  return null;
}

/** The wearer's hold as a reason of a refusal (`paused`, `do_not_disturb`), or null for another. */
export function isWearerRefusal(reason: string): reason is "paused" | "do_not_disturb" {
  return reason === PAUSED_REASON || reason === DO_NOT_DISTURB_REASON;
}

/** The headline of the notice: what the wearer chose ("The wearer paused the sleeve at 14:02."). */
export function holdHeadline(hold: WearerHold, nowMs: number): string {
  if (hold.reason === "paused") {
    return hold.sinceMs === null
      ? `${pausedWho(hold)}.`
      : `${pausedWho(hold)} ${atClock(hold.sinceMs, nowMs)}.`;
  }
  return `The wearer asked not to be disturbed until ${untilClock(hold.untilMs, nowMs)}.`;
}

/** What the page does about it: the strokes drawn now are kept here, not sent, and until when. */
export function holdDetail(hold: WearerHold, heldStrokes: number, nowMs: number): string {
  const held =
    heldStrokes === 0
      ? "What you draw is held here, not sent"
      : `${heldStrokes} stroke${heldStrokes === 1 ? "" : "s"} held here, not sent`;
  let back: string;
  if (hold.reason === "do_not_disturb") {
    back = `${atClock(hold.untilMs, nowMs)}, when do not disturb ends, or sooner if the wearer ends it`;
  } else if (hold.untilMs === null) {
    back = "when the wearer resumes";
  } else {
    // Resuming alone does not let the strokes through: "do not disturb" runs under the pause.
    back =
      `when the wearer resumes and do not disturb has ended ` +
      `(it runs until ${untilClock(hold.untilMs, nowMs)})`;
  }
  return `${held}: the sleeve would refuse them. The page offers to send them ${back}.`;
}

/** Why strokes are held, in a few words (the legend, the counts). */
export function holdReason(hold: WearerHold): string {
  if (hold.reason === "paused") return hold.bySleeve ? "the sleeve paused itself" : "the wearer paused";
  return "the wearer asked not to be disturbed";
}

/** A hold that ended: `ranOut` when a "do not disturb" reached its time (not ended by the wearer). */
export interface EndedHold {
  readonly hold: WearerHold;
  readonly ranOut: boolean;
}

/** The headline once nothing holds the drawing any more: who or what ended the hold. */
export function endedHeadline(ended: EndedHold | null, nowMs: number): string {
  if (ended === null) return "Nothing holds the drawing now.";
  if (ended.hold.reason === "paused") return "The wearer resumed the sleeve.";
  return ended.ranOut
    ? `Do not disturb ended ${atClock(ended.hold.untilMs, nowMs)}.`
    : "The wearer ended do not disturb.";
}

/**
 * The log's line for a change of what holds the drawing, `before` to `after` (null: nothing), or
 * null when there is nothing new to say. `ranOut`: a "do not disturb" ended as it reached its time.
 */
export function holdChangeNote(
  before: WearerHold | null,
  after: WearerHold | null,
  ranOut: boolean,
  nowMs: number,
): string | null {
  const sentAgain = "what you draw is sent again.";
  if (after === null) {
    if (before === null) return null;
    if (before.reason === "paused") return `The wearer resumed the sleeve: ${sentAgain}`;
    return ranOut
      ? `Do not disturb ended ${atClock(before.untilMs, nowMs)}: ${sentAgain}`
      : `The wearer ended do not disturb: ${sentAgain}`;
  }
  if (after.reason === "paused") {
    if (before?.reason === "paused") return null;
    return after.untilMs === null
      ? `${pausedWho(after)}: what you draw is held here until the wearer resumes.`
      : `${pausedWho(after)}: what you draw is held here until the wearer resumes and ` +
          `do not disturb has ended (it runs until ${untilClock(after.untilMs, nowMs)}).`;
  }
  const until = untilClock(after.untilMs, nowMs);
  if (before === null) {
    return `The wearer asked not to be disturbed until ${until}: what you draw is held here until then.`;
  }
  if (before.reason === "paused") {
    return `The wearer resumed the sleeve, but asked not to be disturbed until ${until}: what you draw is still held here.`;
  }
  if (before.untilMs === after.untilMs) return null;
  return `The wearer now asks not to be disturbed until ${until}: what you draw is held here until then.`;
}

/** The line for a stroke the sleeve refused `paused` or `do_not_disturb` (its status came late). */
export function wearerRefusalNote(
  label: string,
  reason: "paused" | "do_not_disturb",
  message: string,
): string {
  const what =
    reason === PAUSED_REASON ? "the wearer paused the sleeve" : "the wearer asked not to be disturbed";
  return `${label} not played: ${what}. ${message}`;
}

/**
 * What the ceiling does to the page's intensity: null without a ceiling. `intensity` is the
 * sender's setting (0..1); the sleeve plays min(intensity, ceiling).
 */
export function ceilingNote(ceiling: number | null, intensity: number): string | null {
  if (ceiling === null) return null;
  const capped = intensity > ceiling;
  const plays = capped
    ? `your ${drivePercent(intensity)} plays at ${drivePercent(ceiling)}`
    : `your ${drivePercent(intensity)} plays as set`;
  return `The wearer set a ceiling of ${drivePercent(ceiling)}: ${plays}.`;
}

/** What the sleeve plays for a stroke sent at `intensity` under `ceiling`. */
export function playedIntensity(intensity: number, ceiling: number | null): number {
  return ceiling === null ? intensity : Math.min(intensity, ceiling);
}

/** The notice once the wearer stopped the drawing (their stop or block): not the sender's Stop. */
export const wearerStoppedHeadline = "The wearer stopped this drawing.";
export const wearerStoppedDetail =
  "The sleeve refuses the rest of it, so what you add to it is not felt. Press New drawing to draw again.";
