/**
 * The felt timeline's caption: whose times it shows, and what became of the strokes, in the
 * counts of the "Sleeve says" card (fates.ts), so that the two never contradict each other.
 */
import { beforeAll, describe, expect, it, vi } from "vitest";
import { Drawing } from "../src/drawing";
import { readEvent, type SleeveEvent } from "../src/events";
import { DrawingFates } from "../src/fates";
import { DEFAULT_ANGLE_PARAMS } from "../src/simplify/params";
import type { DrawingView } from "../src/ui/canvas";
import type { PlacedStroke } from "../src/felt";
import { FeltPanel, timelineCaption, type Tally, type TallySource } from "../src/ui/felt-panel";
import type { TimelineView } from "../src/ui/timeline";

const NONE: Tally = { sent: 4, played: 0, cut: 0, cancelled: 0, refused: 0, dropped: 0 };
const on = (count: number, reported: number, capped = 0) => ({ count, seconds: "1.0", reported, capped });

describe("timelineCaption", () => {
  it("says the times are the page's own until the sleeve answers", () => {
    expect(timelineCaption(on(4, 0), NONE, false)).toBe(
      "4 strokes, 1.0 s: what would be felt, played back to back as the sleeve does.",
    );
  });

  it("says which times are the sleeve's, in the card's count", () => {
    expect(timelineCaption(on(4, 4), { ...NONE, played: 4 }, false)).toBe(
      "4 strokes, 1.0 s, as the sleeve played them.",
    );
    expect(timelineCaption(on(4, 1), { ...NONE, played: 1 }, false)).toBe(
      "4 strokes, 1.0 s; 1 as the sleeve played them, the rest as it would.",
    );
  });

  it("never calls a stroke the duty-cycle cap kept from playing played", () => {
    expect(timelineCaption(on(4, 0, 1), { ...NONE, refused: 1 }, false)).toBe(
      "4 strokes, 1.0 s; 1 not felt (the sleeve's duty-cycle cap kept it from playing), the rest as it would.",
    );
    expect(timelineCaption(on(4, 2, 2), { ...NONE, played: 2, refused: 2 }, false)).toBe(
      "4 strokes, 1.0 s; 2 as the sleeve played them, 2 not felt (the sleeve's duty-cycle cap kept them from playing).",
    );
  });

  it("counts a played stroke whose report never came as played, and says its time is the page's", () => {
    expect(timelineCaption(on(4, 3), { ...NONE, played: 4 }, false)).toBe(
      "4 strokes, 1.0 s; 4 played (the times of 1 are the page's: the sleeve's report of it never came).",
    );
  });

  it("says strokes never sent or refused on arrival apart: they are not on the timeline", () => {
    expect(timelineCaption(on(2, 2), { ...NONE, played: 2, refused: 1, dropped: 1 }, false)).toBe(
      "2 strokes, 1.0 s; 2 as the sleeve played them, 1 refused by the sleeve (not on the timeline), " +
        "1 never sent (not on the timeline).",
    );
  });

  it("says the strokes skipped as late apart from the other refusals, as the card does", () => {
    expect(timelineCaption(on(2, 2), { ...NONE, played: 2, refused: 2, late: 1 }, false)).toBe(
      "2 strokes, 1.0 s; 2 as the sleeve played them, 1 skipped as late (not on the timeline), " +
        "1 refused by the sleeve (not on the timeline).",
    );
    expect(timelineCaption(on(1, 1), { ...NONE, played: 1, refused: 3, late: 3 }, false)).toBe(
      "1 stroke, 1.0 s; 1 as the sleeve played them, 3 skipped as late (not on the timeline).",
    );
  });
});

describe("timelineCaption with strokes held on the page (the wearer paused)", () => {
  it("never says a held stroke is what would be felt: it is held, not sent yet", () => {
    expect(timelineCaption(on(0, 0), { ...NONE, held: 4 }, false)).toBe(
      "4 held on this page, not sent yet (the wearer paused; not on the timeline).",
    );
    expect(
      timelineCaption(on(2, 0), { ...NONE, held: 2, heldWhy: "the wearer asked not to be disturbed" }, false),
    ).toBe(
      "2 strokes, 1.0 s: what would be felt, played back to back as the sleeve does; " +
        "2 held on this page, not sent yet (the wearer asked not to be disturbed; not on the timeline).",
    );
  });

  it("says the held strokes apart from those played", () => {
    expect(timelineCaption(on(2, 2), { ...NONE, played: 2, held: 2 }, false)).toBe(
      "2 strokes, 1.0 s; 2 as the sleeve played them, 2 held on this page, not sent yet (the wearer paused; not on the timeline).",
    );
  });
});

describe("timelineCaption after Stop", () => {
  it("never says the rest plays as it would once Stop was pressed", () => {
    const six = { ...NONE, sent: 6 };
    expect(timelineCaption(on(6, 2), { ...six, played: 2, cancelled: 3 }, true)).toBe(
      "6 strokes, 1.0 s; 2 as the sleeve played them, 3 cancelled by Stop before they played, the rest stopped: not felt.",
    );
    expect(timelineCaption(on(4, 0), NONE, true)).toBe("4 strokes, 1.0 s; the rest stopped: not felt.");
    expect(timelineCaption(on(4, 3), { ...NONE, played: 3, cancelled: 1 }, true)).toBe(
      "4 strokes, 1.0 s; 3 as the sleeve played them, 1 cancelled by Stop before it played.",
    );
    expect(timelineCaption(on(6, 4), { ...six, played: 3, cut: 1, cancelled: 2 }, true)).toBe(
      "6 strokes, 1.0 s; 3 as the sleeve played them, 1 cut short by Stop, 2 cancelled by Stop before they played.",
    );
  });
});

// ---- the panel itself, fed as the page feeds it ------------------------------------------------

const DRAWING = "d-1";

function wire(type: string, seq: number, fields: Record<string, unknown>): SleeveEvent {
  const event = readEvent({ type, topic: "feelmysign/sleeve1/strokes", drawing: DRAWING, seq, ...fields });
  if (event === null) throw new Error(`not an event: ${type} ${JSON.stringify(fields)}`);
  return event;
}

function played(seq: number, startMs: number): SleeveEvent {
  const at = { received_at_ms: startMs, start_at_ms: startMs, first_command_at_ms: startMs };
  return wire("played", seq, {
    ...at,
    latency_ms: 0,
    start_error_ms: 0,
    queued_ms: 0,
    duration_ms: 200,
    commands: 2,
  });
}

function duplicate(seq: number, originalPlayed: boolean): SleeveEvent {
  return wire("rejected", seq, {
    reason: "duplicate",
    message: "a copy",
    received_at_ms: 0,
    original_played: originalPlayed,
  });
}

/** A drawing of `strokes` strokes of 200 ms, drawn back to back. */
function drawingOf(strokes: number): Drawing {
  const drawing = new Drawing(DRAWING, {
    ...DEFAULT_ANGLE_PARAMS,
    canvas_width_px: 400,
    canvas_height_px: 300,
  });
  drawing.beginPath("mouse");
  for (let i = 0; i < strokes; i++) {
    const [start_ms, end_ms] = [i * 200, (i + 1) * 200];
    const segment = { start: [i % 2, 0], end: [(i + 1) % 2, 1], start_ms, end_ms, duration_ms: 200 } as const;
    drawing.addSegment({ ...segment, emitted_at_ms: end_ms, dropped: null }, 0.8);
  }
  return drawing;
}

/**
 * The panel with the card's tally (the same fates the card counts), and what it shows. `heldSeqs`:
 * strokes held on the page as they were drawn (the wearer paused), as the page marks them before
 * the panel sees them.
 */
function panelOf(strokes: number, heldSeqs: readonly number[] = []) {
  const fates = new DrawingFates();
  let dropped = 0;
  const drawing = drawingOf(strokes);
  for (const seq of heldSeqs) drawing.markHeld(seq);
  let held = heldSeqs.length;
  const told: TallySource = {
    get counts() {
      return { sent: strokes, ...fates.counts(), dropped, held };
    },
    fateOf: (seq) => fates.fate(seq),
  };
  const shown: { caption: string; onTimeline: number; placed: readonly PlacedStroke[] } = {
    caption: "",
    onTimeline: 0,
    placed: [],
  };
  const timeline = {
    show: (_grid: unknown, a: { placed: readonly PlacedStroke[] }) => {
      shown.placed = a.placed;
      shown.onTimeline = a.placed.length;
    },
    setCaption: (text: string) => (shown.caption = text),
    setCursor: () => undefined,
  } as unknown as TimelineView;
  const view = { setCompare: () => undefined, drawMarker: () => undefined } as unknown as DrawingView;
  const panel = new FeltPanel(timeline, view, told);
  panel.setDrawing(drawing, { rows: 3, columns: 4 });
  /** An event, as the page takes it: the card's fate first, then the timeline. */
  const hear = (event: SleeveEvent) => {
    fates.add(event);
    if (event.type === "played" || event.type === "adjusted") panel.played(event);
    else panel.told("seq" in event ? event.seq : null);
  };
  const neverSent = (seqs: number[]) => {
    dropped += seqs.length;
    panel.unsent(seqs);
  };
  /** The wearer resumed and the held strokes went out at `atMs`, as the page's sendHeld does. */
  const sendHeld = (atMs: number) => {
    for (const seq of heldSeqs) drawing.unhold(seq);
    held = 0;
    panel.heldSent(heldSeqs, atMs);
  };
  return { fates, shown, hear, neverSent, sendHeld };
}

describe("the felt panel's caption and the card count from the same fates", () => {
  // The cursor's animation: no frames here, the caption is what is read.
  beforeAll(() => vi.stubGlobal("requestAnimationFrame", () => 0));

  it("a stroke whose played event was lost, told played by its copy's refusal: played in both", () => {
    const { fates, shown, hear } = panelOf(3);
    hear(played(0, 1000));
    hear(played(1, 1200));
    hear(duplicate(2, true)); // its own played event was lost with the broker
    expect(fates.counts().played).toBe(3);
    expect(shown.caption).toContain("3 played");
    expect(shown.caption).not.toContain("the rest as it would");
  });

  it("strokes never sent leave the timeline and are never said to be felt as it would", () => {
    const { fates, shown, hear, neverSent } = panelOf(4);
    hear(played(0, 1000));
    hear(played(1, 1200));
    neverSent([2, 3]);
    expect(fates.counts().played).toBe(2);
    expect(shown.onTimeline).toBe(2);
    expect(shown.caption).toMatch(
      /^2 strokes, [\d.]+ s; 2 as the sleeve played them, 2 never sent \(not on the timeline\)\.$/,
    );
  });

  it("a copy's refusal that says its stroke was never felt takes it off the timeline", () => {
    const { shown, hear } = panelOf(2);
    hear(played(0, 1000));
    hear(duplicate(1, false)); // its own refusal was lost: nothing says it was felt
    expect(shown.onTimeline).toBe(1);
    expect(shown.caption).toContain(
      "1 as the sleeve played them, 1 refused by the sleeve (not on the timeline)",
    );
  });
});

describe("the felt panel with strokes held while the wearer paused", () => {
  beforeAll(() => vi.stubGlobal("requestAnimationFrame", () => 0));

  function refused(seq: number): SleeveEvent {
    return wire("rejected", seq, { reason: "paused", message: "the wearer paused", received_at_ms: 0 });
  }

  it("keeps held strokes off the timeline and says them held, not what would be felt", () => {
    const { shown, hear } = panelOf(4, [2, 3]);
    expect(shown.onTimeline).toBe(2);
    expect(shown.placed.map((stroke) => stroke.seq)).toEqual([0, 1]);
    expect(shown.caption).toMatch(
      /^2 strokes, [\d.]+ s: what would be felt, played back to back as the sleeve does; 2 held on this page, not sent yet \(the wearer paused; not on the timeline\)\.$/,
    );
    hear(played(0, 1000));
    hear(played(1, 1200));
    expect(shown.caption).toContain("2 as the sleeve played them, 2 held on this page, not sent yet");
  });

  it("puts held strokes on the timeline when they are sent, arriving then, and moves them by their fate", () => {
    const { shown, hear, sendHeld } = panelOf(4, [2, 3]);
    hear(played(0, 1000));
    hear(played(1, 1200));
    sendHeld(5000); // drawn at 400..800 ms: they reach the sleeve at 5 s, when they were sent
    expect(shown.placed.map((stroke) => stroke.seq)).toEqual([0, 1, 2, 3]);
    const sentLate = shown.placed.filter((stroke) => stroke.seq >= 2);
    // The timeline's zero is the first stroke's arrival (200 ms): drawn-time arrival would place them by 1 s.
    expect(Math.min(...sentLate.map((stroke) => stroke.start_ms))).toBeGreaterThanOrEqual(5000 - 200);
    expect(shown.caption).not.toContain("held");
    expect(shown.caption).toContain("the rest as it would");
    hear(played(2, 6000));
    hear(refused(3)); // the wearer paused again before it played
    expect(shown.placed.map((stroke) => stroke.seq)).toEqual([0, 1, 2]);
    expect(shown.caption).toMatch(
      /^3 strokes, [\d.]+ s; 3 as the sleeve played them, 1 refused by the sleeve \(not on the timeline\)\.$/,
    );
  });
});

describe("the felt panel's caption after Undo", () => {
  beforeAll(() => vi.stubGlobal("requestAnimationFrame", () => 0));

  /** Two paths, `first` and `second` strokes of 200 ms, the panel told by the card's fates. */
  function twoPaths(first: number, second: number) {
    const drawing = new Drawing(DRAWING, {
      ...DEFAULT_ANGLE_PARAMS,
      canvas_width_px: 400,
      canvas_height_px: 300,
    });
    let t = 0;
    for (const strokes of [first, second]) {
      drawing.beginPath("mouse");
      for (let i = 0; i < strokes; i++, t += 200) {
        const segment = { start: [i % 2, 0], end: [(i + 1) % 2, 1], start_ms: t, end_ms: t + 200 } as const;
        drawing.addSegment({ ...segment, duration_ms: 200, emitted_at_ms: t + 200, dropped: null }, 0.8);
      }
    }
    const fates = new DrawingFates();
    const shown = { caption: "", onTimeline: 0 };
    const timeline = {
      show: (_grid: unknown, a: { placed: readonly PlacedStroke[] }) => (shown.onTimeline = a.placed.length),
      setCaption: (text: string) => (shown.caption = text),
      setCursor: () => undefined,
    } as unknown as TimelineView;
    const view = { setCompare: () => undefined, drawMarker: () => undefined } as unknown as DrawingView;
    // As the card counts: every stroke the drawing numbered, undone ones too (Drawing.strokeCount).
    const told: TallySource = {
      get counts() {
        return { sent: drawing.strokeCount, ...fates.counts(), dropped: 0 };
      },
      fateOf: (seq) => fates.fate(seq),
      reasonOf: (seq) => fates.reason(seq),
    };
    const panel = new FeltPanel(timeline, view, told);
    panel.setDrawing(drawing, { rows: 3, columns: 4 });
    const hear = (event: SleeveEvent) => {
      fates.add(event);
      if (event.type === "played" || event.type === "adjusted") panel.played(event);
      else panel.told("seq" in event ? event.seq : null);
    };
    const undo = () => {
      drawing.removeLastPath();
      panel.refresh();
    };
    return { shown, hear, undo };
  }

  it("counts only the drawing as it stands, and never says the reports of undone strokes are missing", () => {
    const { shown, hear, undo } = twoPaths(9, 8);
    for (let seq = 0; seq < 17; seq++) hear(played(seq, 1000 + seq * 200));
    expect(shown.caption).toMatch(/^17 strokes, [\d.]+ s, as the sleeve played them\.$/);
    undo();
    expect(shown.onTimeline).toBe(9);
    expect(shown.caption).not.toContain("never came");
    expect(shown.caption).toMatch(
      /^9 strokes, [\d.]+ s, as the sleeve played them\. Not counted: 8 strokes taken back with Undo \(8 played\)\.$/,
    );
  });

  it("says what became of undone strokes the sleeve has not answered yet, or refused", () => {
    const { shown, hear, undo } = twoPaths(2, 3);
    hear(played(0, 1000));
    hear(played(1, 1200));
    hear(played(2, 1400));
    hear(wire("rejected", 3, { reason: "late", message: "too late", received_at_ms: 0 }));
    undo();
    expect(shown.caption).toMatch(
      /^2 strokes, [\d.]+ s, as the sleeve played them\. Not counted: 3 strokes taken back with Undo \(1 played, 1 skipped as late, 1 not answered yet\)\.$/,
    );
  });
});
