/** Clock times as both pages say them: 24-hour, in the browser's zone, with the day when not today. */
import { afterEach, describe, expect, it } from "vitest";
import { atClock, clockTime, daysFrom, untilClock } from "../src/clock";

describe("clock times", () => {
  const now = new Date(2026, 10, 26, 22, 11).getTime();

  it("says a time 24-hour, whatever the locale would say", () => {
    expect(clockTime(new Date(2026, 10, 26, 22, 11).getTime())).toBe("22:11");
    expect(clockTime(new Date(2026, 10, 26, 0, 5).getTime())).toBe("00:05");
  });

  it("counts calendar days, not spans of 24 h", () => {
    expect(daysFrom(new Date(2026, 10, 27, 0, 1).getTime(), now)).toBe(1);
    expect(daysFrom(new Date(2026, 10, 26, 0, 1).getTime(), now)).toBe(0);
    expect(daysFrom(new Date(2026, 10, 25, 23, 59).getTime(), now)).toBe(-1);
    expect(daysFrom(new Date(2027, 0, 1, 12, 0).getTime(), now)).toBe(36);
  });

  it("names the day of a time that is not today", () => {
    expect(untilClock(new Date(2026, 10, 26, 23, 0).getTime(), now)).toBe("23:00");
    expect(untilClock(new Date(2026, 10, 27, 7, 0).getTime(), now)).toBe("tomorrow at 07:00");
    expect(atClock(new Date(2026, 10, 26, 23, 0).getTime(), now)).toBe("at 23:00");
    expect(atClock(new Date(2026, 10, 27, 7, 0).getTime(), now)).toBe("tomorrow at 07:00");
    expect(atClock(new Date(2026, 10, 25, 23, 50).getTime(), now)).toBe("yesterday at 23:50");
    expect(atClock(new Date(2026, 10, 28, 7, 0).getTime(), now)).toBe("on 28 Nov at 07:00");
    expect(untilClock(new Date(2026, 10, 28, 7, 0).getTime(), now)).toBe("28 Nov at 07:00");
  });
});

describe("clock times across a change of the clocks", () => {
  const zone = process.env["TZ"];
  afterEach(() => {
    if (zone === undefined) delete process.env["TZ"];
    else process.env["TZ"] = zone;
  });

  it("still calls the next calendar day tomorrow on a 25-hour day", () => {
    process.env["TZ"] = "Europe/Berlin"; // the clocks go back on 25 Oct 2026, 03:00 -> 02:00
    const now = new Date(2026, 9, 24, 23, 30).getTime();
    expect(new Date(now).getTimezoneOffset()).toBe(-120); // the zone took effect
    expect(untilClock(new Date(2026, 9, 25, 23, 0).getTime(), now)).toBe("tomorrow at 23:00");
    expect(daysFrom(new Date(2026, 9, 26, 0, 30).getTime(), new Date(2026, 9, 25, 0, 30).getTime())).toBe(1);
  });
});
