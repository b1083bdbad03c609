/** The study page's sentences: counts with their nouns, and what became of the strokes sent. */
import { describe, expect, it } from "vitest";
import { plural } from "../src/study/dom";
import { sentText, trialDetail } from "../src/study/session-view";

describe("the study page's counts", () => {
  it("says 1 stroke and 1 participant, 2 strokes and 0 participants", () => {
    expect(plural(1, "stroke")).toBe("1 stroke");
    expect(plural(2, "stroke")).toBe("2 strokes");
    expect(plural(1, "participant")).toBe("1 participant");
    expect(plural(0, "participant")).toBe("0 participants");
  });

  it("says what became of a send's strokes, cut short and cancelled included", () => {
    const sent = {
      strokes: 1,
      played: 1,
      adjusted: 0,
      rejected: [],
      latency_ms_max: null,
      felt_duration_ms: 1,
    };
    expect(sentText(sent)).toBe("played 1 of 1 stroke");
    expect(sentText({ ...sent, strokes: 4, played: 1, cut_short: 1, cancelled: 2 })).toBe(
      "played 1 of 4 strokes · 1 cut short · 2 cancelled",
    );
  });

  it("says how many strokes the sleeve played faster to catch up, and skipped as late", () => {
    const sent = {
      strokes: 5,
      played: 4,
      adjusted: 0,
      rejected: ["late"],
      compressed: 2,
      compressed_ms: 210.4,
      latency_ms_max: null,
      felt_duration_ms: 1,
    };
    expect(sentText(sent)).toBe(
      "played 4 of 5 strokes · 2 faster to catch up (210 ms shorter in all) · rejected: late",
    );
    expect(sentText({ ...sent, compressed: 0, compressed_ms: 0 })).toBe(
      "played 4 of 5 strokes · rejected: late",
    );
  });
});

describe("the trial's line on the study page", () => {
  const trial = {
    id: 1,
    number: 3,
    total: 10,
    block: "main" as const,
    repetition: 1,
    shape: "circle",
    resolution: "coarse",
    segments: 4,
    speed_cm_s: 6,
    sends: 0,
    last_send: null,
  };

  it("shows the speed only when the design compares speeds", () => {
    expect(trialDetail(trial, true)).toBe(" · coarse, 4 strokes · 6 cm/s");
    expect(trialDetail(trial, false)).toBe(" · coarse, 4 strokes");
  });

  it("says a practice shape's strokes, and no speed for a drawing at its own timing", () => {
    expect(trialDetail({ ...trial, resolution: null, segments: 1, speed_cm_s: 3 }, true)).toBe(
      " · 1 stroke · 3 cm/s",
    );
    expect(trialDetail({ ...trial, speed_cm_s: null }, true)).toBe(" · coarse, 4 strokes");
  });
});

describe("a threshold run's estimate on the study page", () => {
  it("gives a measured threshold with its interval, and a bound where the interval reaches an end", async () => {
    const { estimateWords } = await import("../src/study/threshold-view");
    const estimate = { threshold: 0.6234, low: 0.45, high: 0.8 };
    expect(estimateWords(estimate, "grid units")).toBe("0.623 grid units, 95% interval 0.45 to 0.8");
    expect(estimateWords(estimate, "grid units", true)).toBe("0.623 grid units (95% interval 0.45 to 0.8)");
    expect(estimateWords({ ...estimate, censored: "above" }, "grid units")).toMatch(
      /^not measured: the 95% interval 0.45 to 0.8 reaches the top of the tested range/,
    );
    expect(estimateWords({ ...estimate, censored: "below" }, "grid units")).toMatch(
      /^at most 0.623 grid units: the 95% interval 0.45 to 0.8 reaches the bottom/,
    );
  });
});
