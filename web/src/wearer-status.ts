/**
 * What a sender does with the wearer's choice, as the sleeve's retained status carries it
 * (`controls`, docs/protocol.md, read by events.ts): paused, an intensity ceiling, "do not
 * disturb" until a time. The wearer's choice always wins
 * over the sender's, so a sender holds its drawing instead of sending it into refusals, and says
 * what the sleeve will play. A status without `controls` (an older sleeve, a last will) means
 * none of them.
 */

import { DO_NOT_DISTURB_REASON, PAUSED_REASON, type SleeveControls } from "./events";

/** What a status without `controls` means: not paused, no ceiling, no "do not disturb". */
export const NO_CONTROLS: SleeveControls = {
  paused: false,
  paused_by: null,
  ceiling: null,
  do_not_disturb_until_ms: null,
};

/** Why the sleeve plays nothing now by the wearer's choice; `sinceMs`: when it paused, if known. */
export type WearerHold =
  | { readonly reason: "paused"; readonly sinceMs: number | null }
  | { readonly reason: "do_not_disturb"; readonly untilMs: number };

/**
 * What holds the drawing at `nowMs`, or null. Pausing wins over "do not disturb" (it has no end),
 * and a "do not disturb" whose time has passed holds nothing, whether or not the sleeve has said so.
 */
export function wearerHold(
  controls: SleeveControls,
  nowMs: number,
  sinceMs: number | null = null,
): WearerHold | null {
  if (controls.paused) return { reason: "paused", sinceMs };
  const untilMs = controls.do_not_disturb_until_ms;
  if (untilMs !== null && untilMs > nowMs) return { reason: "do_not_disturb", untilMs };
  return null;
}

/** The wearer's hold as a reason of a refusal (`paused`, `do_not_disturb`), or null for another. */
export function isWearerRefusal(reason: string): reason is "paused" | "do_not_disturb" {
  return reason === PAUSED_REASON || reason === DO_NOT_DISTURB_REASON;
}

/** A wall-clock time as the page shows it: "14:30", the browser's time zone. */
export function clockTime(ms: number): string {
  const at = new Date(ms);
  return `${pad(at.getHours())}:${pad(at.getMinutes())}`;
}

/** The headline of the notice: what the wearer chose ("The wearer paused the sleeve at 14:02."). */
export function holdHeadline(hold: WearerHold): string {
  if (hold.reason === "paused") {
    return hold.sinceMs === null
      ? "The wearer paused the sleeve."
      : `The wearer paused the sleeve at ${clockTime(hold.sinceMs)}.`;
  }
  return `The wearer asked not to be disturbed until ${clockTime(hold.untilMs)}.`;
}

/** What the page does about it: the strokes drawn now are kept here, not sent. */
export function holdDetail(hold: WearerHold, heldStrokes: number): string {
  const held =
    heldStrokes === 0
      ? "What you draw is held here, not sent"
      : `${heldStrokes} stroke${heldStrokes === 1 ? "" : "s"} held here, not sent`;
  const back =
    hold.reason === "paused"
      ? "the wearer resumes"
      : `${clockTime(hold.untilMs)}, or when the wearer ends it`;
  return `${held}: the sleeve would refuse them. The page offers to send them when ${back}.`;
}

/** Why strokes are held, in a few words (the legend, the counts). */
export function holdReason(hold: WearerHold): string {
  return hold.reason === "paused" ? "the wearer paused" : "the wearer asked not to be disturbed";
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
    ? `your ${percent(intensity)} plays at ${percent(ceiling)}`
    : `your ${percent(intensity)} plays as set`;
  return `The wearer set a ceiling of ${percent(ceiling)}: ${plays}.`;
}

/** What the sleeve plays for a stroke sent at `intensity` under `ceiling`. */
export function playedIntensity(intensity: number, ceiling: number | null): number {
  return ceiling === null ? intensity : Math.min(intensity, ceiling);
}

function percent(fraction: number): string {
  return `${Math.round(fraction * 100)} %`;
}

function pad(value: number): string {
  return String(value).padStart(2, "0");
}
