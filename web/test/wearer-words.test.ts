/** What the wearer's page says and offers: the same scale and clock as the sender's page. */
import { afterEach, describe, expect, it } from "vitest";
import type { WearerState } from "../src/wearer/api";
import {
  ceilingChoiceLabel,
  ceilingChoices,
  ceilingLine,
  doNotDisturbLine,
  playLine,
  sendersLine,
  summary,
  untilHint,
  untilTime,
} from "../src/wearer/words";
import { ceilingNote } from "../src/wearer-status";

describe("the wearer's ceiling", () => {
  it("offers round drive levels below the layout's max_intensity, strongest first", () => {
    expect(ceilingChoices(1)).toEqual([0.8, 0.6, 0.4, 0.2]);
    expect(ceilingChoices(0.9)).toEqual([0.8, 0.6, 0.4, 0.2]);
    expect(ceilingChoices(0.8)).toEqual([0.6, 0.4, 0.2]);
    expect(ceilingChoices(0.5)).toEqual([0.4, 0.3, 0.2, 0.1]);
    expect(ceilingChoices(0.3)).toEqual([0.2, 0.1]);
    // Nothing below the sleeve's lowest ceiling (0.05), nothing at or above its maximum.
    expect(ceilingChoices(0.1)).toEqual([]);
  });

  it("says a ceiling as the sender's page says it: the drive level, not a share of the maximum", () => {
    const max = 0.9;
    const ceiling = 0.6; // three presses of the turn-down button from 0.9
    expect(ceilingChoiceLabel(ceiling, max)).toBe("60 % at most");
    expect(ceilingLine(ceiling, max)).toBe(
      "At most 60 %, whatever the sender asks (this sleeve allows up to 90 %).",
    );
    expect(summary(state({ ceiling }, max), 0)).toContain("Strongest vibration 60 %.");
    // The sender's page, for the same ceiling:
    expect(ceilingNote(ceiling, 0.8)).toBe("The wearer set a ceiling of 60 %: your 80 % plays at 60 %.");
    for (const choice of ceilingChoices(max)) {
      expect(ceilingChoiceLabel(choice, max)).toBe(`${Math.round(choice * 100)} % at most`);
    }
  });

  it("calls no ceiling the strongest this sleeve allows, with its level", () => {
    expect(ceilingChoiceLabel(null, 0.9)).toBe("The strongest this sleeve allows (90 %)");
    expect(ceilingLine(null, 0.9)).toBe("No ceiling: up to the strongest this sleeve allows, 90 %.");
  });
});

function state(controls: Partial<NonNullable<WearerState["controls"]>>, max = 1): WearerState {
  return {
    sleeve_id: "s1",
    online: true,
    controls: { paused: false, paused_by: null, ceiling: null, do_not_disturb_until_ms: null, ...controls },
    max_intensity: max,
    senders: [],
    blocking: false,
  };
}

describe("do not disturb until a time", () => {
  const now = new Date(2026, 10, 26, 22, 11, 30).getTime();

  it("takes a time still to come today as today", () => {
    const until = untilTime("23:00", now);
    expect(until).toEqual({
      ok: true,
      untilMs: new Date(2026, 10, 26, 23, 0).getTime(),
      words: "until 23:00",
    });
    expect(untilHint("23:00", now)).toBe("Set makes it until 23:00.");
  });

  it("says tomorrow before and after setting a time that has passed today", () => {
    const until = untilTime("22:00", now);
    expect(until).toEqual({
      ok: true,
      untilMs: new Date(2026, 10, 27, 22, 0).getTime(),
      words: "until tomorrow at 22:00",
    });
    expect(untilHint("22:00", now)).toBe("Set makes it until tomorrow at 22:00: that time has passed today.");
    // Once set, the page's line says the same day.
    expect(doNotDisturbLine(new Date(2026, 10, 27, 22, 0).getTime(), now)).toBe(
      "On until tomorrow at 22:00: nothing reaches you.",
    );
    expect(
      summary(state({ do_not_disturb_until_ms: new Date(2026, 10, 27, 22, 0).getTime() }), now),
    ).toContain("Do not disturb until tomorrow at 22:00: nothing plays.");
  });

  it("takes the current minute as tomorrow's, within the 24 h the sleeve allows", () => {
    const until = untilTime("22:11", now);
    expect(until.ok).toBe(true);
    if (until.ok) expect(until.untilMs - now).toBeLessThanOrEqual(24 * 3_600_000);
  });

  it("says what to enter when the time is empty or not a time", () => {
    expect(untilTime("", now)).toEqual({
      ok: false,
      problem: "Enter the time do not disturb ends, such as 22:30, then press Set.",
    });
    expect(untilTime("late", now)).toEqual({
      ok: false,
      problem: "late is not a time of day: enter one such as 22:30 (24-hour), then press Set.",
    });
    expect(untilHint("", now)).toBe("");
    for (const wrong of ["24:00", "22:60", "10:30 PM", "12345"]) expect(untilTime(wrong, now).ok).toBe(false);
  });

  it("takes 24-hour times as the wearer types them", () => {
    const at = (h: number, m: number, day = 26) => new Date(2026, 10, day, h, m).getTime();
    expect(untilTime("23:05", now)).toMatchObject({ ok: true, untilMs: at(23, 5) });
    expect(untilTime("2305", now)).toMatchObject({ ok: true, untilMs: at(23, 5) });
    expect(untilTime("7:05", now)).toMatchObject({
      ok: true,
      untilMs: at(7, 5, 27),
      words: "until tomorrow at 07:05",
    });
  });

  describe("on the night the clocks go back", () => {
    const zone = process.env["TZ"];
    afterEach(() => {
      if (zone === undefined) delete process.env["TZ"];
      else process.env["TZ"] = zone;
    });

    it("refuses in words a time more than 24 h away", () => {
      process.env["TZ"] = "Europe/Berlin"; // 25 Oct 2026 has 25 hours
      const evening = new Date(2026, 9, 24, 22, 30).getTime();
      expect(new Date(evening).getTimezoneOffset()).toBe(-120);
      const until = untilTime("22:00", evening);
      expect(until).toEqual({
        ok: false,
        problem:
          "Do not disturb until tomorrow at 22:00 is more than 24 hours away (the clocks change tonight), and it lasts at most 24 hours: choose an earlier time.",
      });
      expect(untilHint("22:00", evening)).toContain("more than 24 hours away");
      // An hour earlier is within the 24 hours.
      expect(untilTime("21:00", evening).ok).toBe(true);
    });
  });
});

describe("the wearer's senders", () => {
  it("says that a block also stops what is playing and waiting, from every sender", () => {
    expect(sendersLine(true)).toContain("Blocking also stops what is playing and waiting now");
    expect(sendersLine(true)).toContain("cannot tell whose strokes are whose");
  });

  it("without the broker's files, says where to block rather than that the broker is another", () => {
    expect(sendersLine(false)).not.toContain("uses another one");
    expect(sendersLine(false)).toContain("wearer's page of 'feelmysign up'");
  });
});

describe("what the wearer's page says plays", () => {
  const now = new Date(2026, 10, 26, 23, 24).getTime();
  const until = new Date(2026, 10, 26, 23, 39).getTime();

  it("says nothing plays under do not disturb, not that it plays what senders draw", () => {
    const dnd = state({ do_not_disturb_until_ms: until }).controls!;
    expect(playLine(dnd, now)).toBe("Do not disturb until 23:39: nothing plays.");
    expect(summary(state({ do_not_disturb_until_ms: until }), now)).toBe(
      "Do not disturb until 23:39: nothing plays.",
    );
    // Once its time has passed, it plays again.
    expect(playLine(dnd, until + 1)).toBe("Playing: what senders draw, you feel.");
  });

  it("says why the sleeve started paused at the lowest strength by itself", () => {
    const safe = state({ paused: true, paused_by: "sleeve", ceiling: 0.05 }).controls!;
    expect(playLine(safe, now)).toContain("could not read your last choices");
    expect(playLine(safe, now)).toContain("at the lowest strength, 5 %");
    expect(summary(state({ paused: true, paused_by: "sleeve", ceiling: 0.05 }), now)).toBe(
      "Paused by the sleeve itself: it could not read your last choices. Strongest vibration 5 %.",
    );
    expect(playLine(state({ paused: true, paused_by: "page" }).controls!, now)).toBe(
      "Paused: nothing plays until you resume.",
    );
  });
});
