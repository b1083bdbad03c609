/**
 * What the wearer's page says and offers, apart from the page (no DOM, the time passed in), so
 * the unit tests read it as the wearer does. Intensities are drive levels (drive-level.ts), the
 * scale the sender's page, `feelmysign send` and the sleeve's status use: a ceiling of 0.6 is
 * "60 %" here and there. Times are clock.ts's, as on the sender's page.
 */
import { untilClock } from "../clock";
import { drivePercent } from "../drive-level";
import type { Controls, WearerState } from "./api";

/** The sleeve's lowest ceiling (feelmysign.sleeve.controls MIN_CEILING). */
export const MIN_CEILING = 0.05;
/** "do not disturb" lasts at most this (feelmysign.sleeve.controls MAX_DO_NOT_DISTURB_MS). */
export const MAX_DO_NOT_DISTURB_MS = 24 * 3_600_000;
/** The choices below the sleeve's strongest, a step apart (two presses of the turn-down button). */
const CEILING_STEP = 0.2;
const CEILING_CHOICES = 4;

/**
 * The ceilings offered, strongest first: the round drive levels (80 %, 60 %, ...) below the
 * layout's `max_intensity`, a step apart, none below MIN_CEILING. Above them the page offers no
 * ceiling: the strongest this sleeve allows. A sleeve allowing 0.5 or less gets steps of 0.1.
 */
export function ceilingChoices(maxIntensity: number): number[] {
  const step = maxIntensity > 0.5 ? CEILING_STEP : CEILING_STEP / 2;
  // In hundredths: 0.6 is 60, never 0.6000000000000001.
  const top = Math.round(maxIntensity * 100);
  const stepHundredths = Math.round(step * 100);
  const choices: number[] = [];
  for (let level = Math.ceil(top / stepHundredths) - 1; level >= 1; level--) {
    const hundredths = level * stepHundredths;
    if (hundredths >= top || hundredths < MIN_CEILING * 100) continue;
    choices.push(hundredths / 100);
    if (choices.length === CEILING_CHOICES) break;
  }
  return choices;
}

/** A choice's words: "60 % at most", or the strongest this sleeve allows for none. */
export function ceilingChoiceLabel(ceiling: number | null, maxIntensity: number): string {
  return ceiling === null
    ? `The strongest this sleeve allows (${drivePercent(maxIntensity)})`
    : `${drivePercent(ceiling)} at most`;
}

/** The line under "Strongest vibration". */
export function ceilingLine(ceiling: number | null, maxIntensity: number): string {
  return ceiling === null
    ? `No ceiling: up to the strongest this sleeve allows, ${drivePercent(maxIntensity)}.`
    : `At most ${drivePercent(ceiling)}, whatever the sender asks (this sleeve allows up to ${drivePercent(maxIntensity)}).`;
}

/** The line under "Do not disturb". */
export function doNotDisturbLine(untilMs: number | null, nowMs: number): string {
  return untilMs === null
    ? "Off: senders may draw on you."
    : `On until ${untilClock(untilMs, nowMs)}: nothing reaches you.`;
}

/**
 * The line above the senders. A block also stops what plays and what waits (every sender's: the
 * sleeve cannot tell whose stroke is whose), so what the blocked sender already sent ends too.
 */
export function sendersLine(blocking: boolean): string {
  return blocking
    ? "Block a sender to stop them drawing on you until you unblock them. Blocking also stops " +
        "what is playing and waiting now, from every sender: the sleeve cannot tell whose " +
        "strokes are whose."
    : "Blocking is not offered here: this page does not find the broker's files on this " +
        "computer (its usual state directory). Block senders on the wearer's page of " +
        "'feelmysign up', where the broker runs.";
}

/** The sleeve's paused_by when it started paused by itself: the wearer's last choices unreadable. */
export const PAUSED_BY_SLEEVE = "sleeve";

/** A "do not disturb" still running at `nowMs`, or null. */
function dndRunning(c: Controls, nowMs: number): number | null {
  const until = c.do_not_disturb_until_ms;
  return until !== null && until > nowMs ? until : null;
}

/**
 * The line under "Vibration": paused (by whom), do not disturb, or playing. A sleeve that started
 * paused by itself says why: it could not read the wearer's last choices, so it took the safe side
 * of both (paused, and the lowest ceiling).
 */
export function playLine(c: Controls, nowMs: number): string {
  if (c.paused) {
    if (c.paused_by === PAUSED_BY_SLEEVE) {
      return (
        "Paused by the sleeve itself: it could not read your last choices (its settings file), so " +
        `it started paused and at the lowest strength${c.ceiling === null ? "" : `, ${drivePercent(c.ceiling)}`}. ` +
        "Resume when you want, and choose the strongest vibration again."
      );
    }
    return `Paused${c.paused_by === "button" ? " with the sleeve's button" : ""}: nothing plays until you resume.`;
  }
  const until = dndRunning(c, nowMs);
  if (until !== null) return `Do not disturb until ${untilClock(until, nowMs)}: nothing plays.`;
  return "Playing: what senders draw, you feel.";
}

/** The words a screen reader says when they change (pause, ceiling, do not disturb, online). */
export function summary(state: WearerState, nowMs: number): string {
  const c = state.controls;
  if (c === null) return "The sleeve is starting.";
  const until = dndRunning(c, nowMs);
  const parts = [
    state.online ? "" : "The sleeve cannot reach the broker.",
    c.paused
      ? c.paused_by === PAUSED_BY_SLEEVE
        ? "Paused by the sleeve itself: it could not read your last choices."
        : "Paused: nothing plays."
      : until === null
        ? "Playing what senders draw."
        : `Do not disturb until ${untilClock(until, nowMs)}: nothing plays.`,
    c.ceiling === null ? "" : `Strongest vibration ${drivePercent(c.ceiling)}.`,
    // Under a pause, a do not disturb still running is said too: it outlasts a resume.
    c.paused && until !== null ? `Do not disturb until ${untilClock(until, nowMs)}.` : "",
  ];
  return parts.filter(Boolean).join(" ");
}

/** The line at the top when the page's own server does not answer: the sleeve itself may be gone. */
export const UNREACHABLE_LINE =
  "The sleeve does not answer: it may not be running, or this phone is not on its network. " +
  "Nothing here reaches it. If a motor keeps buzzing, switch the sleeve off or unplug it.";

/** What the live region says of it (the line above says the rest). */
export const UNREACHABLE_SAID = "The sleeve does not answer: your controls are off until it does.";

/** What the page says after a block: the stop that came with it too. */
export function blockedSaid(sender: string): string {
  return `Blocked ${sender}. What was playing or waiting was stopped too.`;
}

/** What the page says after Stop: the API does not tell whether anything was playing. */
export const STOPPED_SAID = "Stopped: anything playing or waiting was dropped.";

/** A time of day the wearer typed, as "do not disturb" would take it. */
export type UntilTime =
  | { readonly ok: true; readonly untilMs: number; readonly words: string }
  | { readonly ok: false; readonly problem: string };

/**
 * The next time `hhmm` comes: today, or tomorrow when it has passed (said so: "until tomorrow at
 * 07:00"). 24-hour, as the wearer types it: "22:30", "7:05", "2230" (and "22:30:00"). Refused in
 * words when empty, not a time of day, or more than 24 h away (the sleeve's limit; only on the
 * day the clocks go back).
 */
export function untilTime(hhmm: string, nowMs: number): UntilTime {
  const match = /^(\d{1,2})[:.h]?(\d{2})(?::\d{2}(?:\.\d+)?)?$/.exec(hhmm.trim());
  if (match === null || Number(match[1]) > 23 || Number(match[2]) > 59) {
    return {
      ok: false,
      problem:
        hhmm.trim() === ""
          ? "Enter the time do not disturb ends, such as 22:30, then press Set."
          : `${hhmm.trim()} is not a time of day: enter one such as 22:30 (24-hour), then press Set.`,
    };
  }
  const at = new Date(nowMs);
  at.setHours(Number(match[1]), Number(match[2]), 0, 0);
  // Tomorrow on the calendar (not 24 h on): the clock time asked for, even when the clocks change.
  if (at.getTime() <= nowMs) at.setDate(at.getDate() + 1);
  const untilMs = at.getTime();
  const words = `until ${untilClock(untilMs, nowMs)}`;
  if (untilMs - nowMs > MAX_DO_NOT_DISTURB_MS) {
    return {
      ok: false,
      problem:
        `Do not disturb ${words} is more than 24 hours away (the clocks change tonight), and ` +
        "it lasts at most 24 hours: choose an earlier time.",
    };
  }
  return { ok: true, untilMs, words };
}

/** What the time field's hint says while the wearer types, before Set. */
export function untilHint(hhmm: string, nowMs: number): string {
  if (hhmm.trim() === "") return "";
  const until = untilTime(hhmm, nowMs);
  if (!until.ok) return until.problem;
  const tomorrow = until.words.startsWith("until tomorrow");
  return `Set makes it ${until.words}${tomorrow ? ": that time has passed today" : ""}.`;
}
