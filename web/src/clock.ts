/**
 * Clock times as every page says them: 24-hour "22:11", in the browser's time zone, the same as
 * `feelmysign send` and the sleeve's logs, whatever the browser's locale would make of them
 * ("10:11 PM"). The sender's page and the wearer's page both import this module, so one time is
 * never shown two ways. A time on another day than `nowMs` names the day ("tomorrow at 07:00"):
 * "do not disturb" may end after midnight.
 */

const MONTHS = ["Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec"];

/** "22:11": the wall-clock time of `ms`, without the day. */
export function clockTime(ms: number): string {
  const at = new Date(ms);
  return `${pad(at.getHours())}:${pad(at.getMinutes())}`;
}

/** Calendar days from `nowMs` to `ms` in the browser's time zone: 0 today, 1 tomorrow, -1 yesterday. */
export function daysFrom(ms: number, nowMs: number): number {
  const day = (at: number) => {
    const date = new Date(at);
    // Noon UTC of the local calendar date: a difference of whole days, whatever the clocks did.
    return Date.UTC(date.getFullYear(), date.getMonth(), date.getDate(), 12);
  };
  return Math.round((day(ms) - day(nowMs)) / 86_400_000);
}

/**
 * `ms` after "until": "22:11" today, "tomorrow at 07:00", "yesterday at 23:50", or
 * "28 Nov at 07:00" further away.
 */
export function untilClock(ms: number, nowMs: number): string {
  const days = daysFrom(ms, nowMs);
  if (days === 0) return clockTime(ms);
  return `${dayName(ms, days)} at ${clockTime(ms)}`;
}

/** `ms` as a moment: "at 22:11" today, "tomorrow at 07:00", "yesterday at 23:50", "on 28 Nov at 07:00". */
export function atClock(ms: number, nowMs: number): string {
  const days = daysFrom(ms, nowMs);
  if (days === 0) return `at ${clockTime(ms)}`;
  const name = dayName(ms, days);
  return `${Math.abs(days) === 1 ? name : `on ${name}`} at ${clockTime(ms)}`;
}

function dayName(ms: number, days: number): string {
  if (days === 1) return "tomorrow";
  if (days === -1) return "yesterday";
  const date = new Date(ms);
  return `${date.getDate()} ${MONTHS[date.getMonth()]}`;
}

function pad(value: number): string {
  return String(value).padStart(2, "0");
}
