/**
 * The "Sleeve says" card tells the sender how the sleeve kept the drawing in time: of the strokes
 * played, how many it played faster to catch up (and how much shorter in all) and how many it
 * slowed to its floor; of the refused, how many it skipped as late, apart from other refusals. Its
 * parts still add up to the strokes drawn, and its data attributes carry each figure.
 */
import { describe, expect, it } from "vitest";
import { parseEvent, type SleeveEvent } from "../src/events";
import { SleeveSays } from "../src/ui/sleeve-says";

const DRAWING = "3f2a9c1e-0000-4000-8000-000000000000";
const AT_MS = 1795326267664.25;
const stroke = { topic: "feelmysign/sleeve1/strokes", drawing: DRAWING, received_at_ms: AT_MS };
const timing = {
  start_at_ms: AT_MS,
  first_command_at_ms: AT_MS + 0.25,
  latency_ms: 0.25,
  start_error_ms: 0.031,
  queued_ms: 0,
  duration_ms: 417.5,
  commands: 5,
};

const event = (fields: Record<string, unknown>): SleeveEvent => {
  const parsed = parseEvent(JSON.stringify(fields));
  if (parsed === null) throw new Error(`not an event: ${JSON.stringify(fields)}`);
  return parsed;
};
const played = (seq: number, extra: Record<string, unknown> = {}): SleeveEvent =>
  event({ type: "played", ...stroke, seq, ...timing, ...extra });
const compressed = (seq: number, ms: number): SleeveEvent =>
  played(seq, { queued_ms: 300, duration_ms: 417.5 - ms, compressed_ms: ms });
const slowed = (seq: number): SleeveEvent =>
  event({
    type: "adjusted",
    ...stroke,
    seq,
    ...timing,
    duration_ms: 73.7,
    reason: "too_fast",
    requested_duration_ms: 40,
  });
const refused = (seq: number, reason: string): SleeveEvent =>
  event({ type: "rejected", ...stroke, seq, reason, message: `refused as ${reason}` });

/** A card on stand-ins for its elements: what it renders is their text and data attributes. */
function card(): { says: SleeveSays; summary: { textContent: string; dataset: Record<string, string> } } {
  const summary = { textContent: "", dataset: {} as Record<string, string> };
  const title = { textContent: "", title: "" };
  const list = { replaceChildren: () => {} };
  const says = new SleeveSays(
    title as unknown as HTMLElement,
    list as unknown as HTMLOListElement,
    summary as never,
  );
  says.reset(DRAWING);
  return { says, summary };
}

describe("the card says how the sleeve caught up", () => {
  it("names the strokes played faster, slowed and skipped as late, and still adds up", () => {
    const { says, summary } = card();
    says.setSent(14);
    // 8 as they came, 3 faster to catch up (70 + 80 + 60 ms shorter), 1 slowed, 2 skipped.
    for (const seq of [0, 1, 2, 3, 4, 5, 6, 7]) says.fate(played(seq));
    says.fate(compressed(8, 70));
    says.fate(compressed(9, 80));
    says.fate(compressed(10, 60));
    says.fate(slowed(11));
    says.fate(refused(12, "late"));
    says.fate(refused(13, "late"));
    expect(summary.textContent).toBe(
      "12 of 14 strokes played (3 faster to catch up, 210 ms shorter in all; 1 slowed to the sleeve's floor), " +
        "2 skipped as late.",
    );
    expect(summary.dataset).toMatchObject({
      sent: "14",
      played: "12",
      compressed: "3",
      compressedMs: "210",
      slowed: "1",
      refused: "2",
      late: "2",
    });
    // Each stroke once: the late ones are among the refused, the caught-up among the played.
    const counts = says.counts;
    expect(counts.played + counts.cut + counts.cancelled + counts.refused + counts.dropped).toBe(counts.sent);
  });

  it("says how many strokes drawn faster than the sleeve plays were sent at its floor", () => {
    const { says, summary } = card();
    says.setSent(6, 2);
    for (const seq of [0, 1, 2, 3]) says.fate(played(seq));
    says.fate(compressed(4, 50));
    says.fate(played(5));
    expect(summary.textContent).toBe(
      "6 of 6 strokes played (1 faster to catch up, 50 ms shorter in all; " +
        "2 drawn faster than the sleeve can play, sent at its floor).",
    );
    expect(summary.dataset).toMatchObject({ sent: "6", lengthened: "2", slowed: "0" });
    // None lengthened: nothing said of it.
    says.setSent(6, 0);
    expect(summary.textContent).toBe("6 of 6 strokes played (1 faster to catch up, 50 ms shorter in all).");
  });

  it("keeps the late apart from the other refusals, and the wearer's words on those", () => {
    const { says, summary } = card();
    says.setSent(5);
    says.fate(played(0));
    says.fate(compressed(1, 1234.5));
    says.fate(refused(2, "late"));
    says.fate(refused(3, "paused"));
    says.fate(refused(4, "paused"));
    expect(summary.textContent).toBe(
      "2 of 5 strokes played (1 faster to catch up, 1.2 s shorter in all), 1 skipped as late, " +
        "2 refused (the wearer paused).",
    );
    expect(summary.dataset).toMatchObject({ refused: "3", late: "1", wearerRefused: "2", slowed: "0" });
  });

  it("counts a stroke caught up and then cut short by Stop under cut short, not as caught up", () => {
    const { says, summary } = card();
    says.setSent(2);
    says.fate(played(0));
    says.fate(compressed(1, 95));
    says.fate(
      event({
        type: "cancelled",
        reason: "cancelled",
        message: "cut short",
        ...stroke,
        seq: 1,
        cancelled_at_ms: AT_MS + 100,
        started: true,
      }),
    );
    expect(summary.textContent).toBe("1 of 2 strokes played, 1 cut short by Stop.");
    expect(summary.dataset).toMatchObject({ compressed: "0", compressedMs: "0", cut: "1" });
  });

  it("says nothing more of a drawing played as it came", () => {
    const { says, summary } = card();
    says.setSent(3);
    says.fate(played(0));
    says.fate(played(1));
    says.fate(refused(2, "outside_grid"));
    expect(summary.textContent).toBe("2 of 3 strokes played, 1 refused.");
    expect(summary.dataset).toMatchObject({ compressed: "0", slowed: "0", late: "0" });
  });
});

describe("the card for a drawing not sent, or sent all at once by Play again", () => {
  /** Stroke `seq` played by the sleeve at `startMs` after the first, for `durationMs`, `shorterMs` faster. */
  const playedAt = (seq: number, startMs: number, durationMs: number, shorterMs = 0): SleeveEvent =>
    played(seq, {
      start_at_ms: AT_MS + startMs,
      first_command_at_ms: AT_MS + startMs + 0.25,
      duration_ms: durationMs,
      ...(shorterMs > 0 ? { queued_ms: startMs, compressed_ms: shorterMs } : {}),
    });

  it("says a loaded drawing is not sent yet and Play again sends it, not that none was played", () => {
    const { says, summary } = card();
    says.setSent(52);
    says.notSent(52, "loaded");
    expect(summary.textContent).toBe("52 strokes loaded, not sent yet: Play again sends them.");
    expect(summary.textContent).not.toContain("0 of");
    expect(summary.dataset).toMatchObject({ sent: "52", notSent: "52", played: "0" });
    says.notSent(1, "re-simplified");
    says.setSent(1);
    expect(summary.textContent).toBe("1 stroke re-simplified, not sent yet: Play again sends them.");
  });

  it("counts strokes drawn on after a load as sent, and the loaded ones apart", () => {
    const { says, summary } = card();
    says.setSent(5);
    says.notSent(3, "loaded");
    says.fate(playedAt(3, 0, 400));
    expect(summary.textContent).toBe(
      "1 of 2 strokes played, 3 strokes loaded, not sent yet: Play again sends them.",
    );
  });

  it("says a drawing played again was played back to back, and how much shorter than drawn", () => {
    const { says, summary } = card();
    says.setSent(4);
    says.replayed(13_600);
    // Back to back from the first start: 1000 + 1000 + 1000 + 1000 ms, three of them played faster.
    says.fate(playedAt(0, 0, 1000));
    says.fate(playedAt(1, 1000, 1000, 500));
    expect(summary.textContent).toBe("2 of 4 strokes played (back to back).");
    says.fate(playedAt(2, 2000, 1000, 400));
    says.fate(playedAt(3, 3000, 1000, 600));
    expect(summary.textContent).toBe(
      "4 of 4 strokes played (back to back in 4.0 s, 9.6 s shorter than drawn: the pauses left out " +
        "and 3 strokes played faster).",
    );
    expect(summary.textContent).not.toContain("catch up");
    // The figures as before: the caught-up among the played, and how much shorter they were.
    expect(summary.dataset).toMatchObject({
      sent: "4",
      played: "4",
      compressed: "3",
      compressedMs: "1500",
      replay: "yes",
      drawnMs: "13600",
      spanMs: "4000",
    });
  });

  it("keeps the catch-up words for a drawing sent as it was drawn", () => {
    const { says, summary } = card();
    says.setSent(2);
    says.fate(playedAt(0, 0, 1000));
    says.fate(playedAt(1, 1000, 1000, 500));
    expect(summary.textContent).toBe("2 of 2 strokes played (1 faster to catch up, 500 ms shorter in all).");
    expect(summary.dataset).toMatchObject({ replay: "no" });
  });
});
