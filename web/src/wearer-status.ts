/**
 * The wearer's choice, as the sleeve's retained status carries it (`controls`, docs/protocol.md):
 * paused, an intensity ceiling, "do not disturb" until a time. The wearer's choice always wins
 * over the sender's, so a sender holds its drawing instead of sending it into refusals, and says
 * what the sleeve will play. A status without `controls` (an older sleeve, a last will) means
 * none of them. Like events.ts, a value of the wrong type gives null, never an exception.
 */

export interface WearerControls {
  readonly paused: boolean;
  /** Who paused ("button", "page", "cli"); null when not paused or not said. */
  readonly paused_by: string | null;
  /** The wearer's intensity ceiling (0..1); null: none. */
  readonly ceiling: number | null;
  /** Wall clock, ms since 1970; null: off. */
  readonly do_not_disturb_until_ms: number | null;
}

/** What a status without `controls` means. */
export const NO_CONTROLS: WearerControls = {
  paused: false,
  paused_by: null,
  ceiling: null,
  do_not_disturb_until_ms: null,
};

/** Refusal reasons of a stroke the wearer's choice kept from playing (docs/protocol.md). */
export const PAUSED_REASON = "paused";
export const DO_NOT_DISTURB_REASON = "do_not_disturb";

/**
 * The `controls` of a status (its JSON value, already parsed); NO_CONTROLS when it has none;
 * null when the status is not an object or `controls` has a field of the wrong type.
 */
export function readWearerControls(status: unknown): WearerControls | null {
  if (!isObject(status)) return null;
  const controls = status["controls"];
  if (controls === undefined || controls === null) return NO_CONTROLS;
  if (!isObject(controls)) return null;
  const paused = controls["paused"];
  const pausedBy = controls["paused_by"] ?? null;
  const ceiling = controls["ceiling"] ?? null;
  const untilMs = controls["do_not_disturb_until_ms"] ?? null;
  if (typeof paused !== "boolean") return null;
  if (pausedBy !== null && typeof pausedBy !== "string") return null;
  if (ceiling !== null && !(isFinite(ceiling) && ceiling >= 0 && ceiling <= 1)) return null;
  if (untilMs !== null && !(isFinite(untilMs) && Number.isInteger(untilMs) && untilMs >= 0)) return null;
  return {
    paused,
    paused_by: paused ? pausedBy : null,
    ceiling,
    do_not_disturb_until_ms: untilMs,
  };
}

/** `readWearerControls` of a status message's text; null when it is not JSON. */
export function parseWearerControls(text: string): WearerControls | null {
  try {
    return readWearerControls(JSON.parse(text));
  } catch {
    return null;
  }
}

/** Why the sleeve plays nothing now by the wearer's choice; `sinceMs`: when it paused, if known. */
export type WearerHold =
  | { readonly reason: "paused"; readonly sinceMs: number | null }
  | { readonly reason: "do_not_disturb"; readonly untilMs: number };

/**
 * What holds the drawing at `nowMs`, or null. Pausing wins over "do not disturb" (it has no end),
 * and a "do not disturb" whose time has passed holds nothing, whether or not the sleeve has said so.
 */
export function wearerHold(
  controls: WearerControls,
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

function isObject(value: unknown): value is Record<string, unknown> {
  return typeof value === "object" && value !== null && !Array.isArray(value);
}

function isFinite(value: unknown): value is number {
  return typeof value === "number" && Number.isFinite(value);
}
