/** The incremental placement gives what placing every stroke again from scratch gives. */
import fc from "fast-check";
import { describe, expect, it } from "vitest";
import { SLEEVE_FLOOR_MS } from "../src/sleeve-queue";
import { placeStrokes, playingAt, totalMs, type FeltStroke, type PlacedStroke } from "../src/felt";
import { FeltPlacement } from "../src/felt-placement";

/** The full computation the felt panel made on every change before it was incremental. */
function placeFromScratch(
  strokes: readonly FeltStroke[],
  startedAt: ReadonlyMap<number, number>,
  cut: ReadonlyMap<number, number>,
  capped: ReadonlySet<number> = new Set(),
  refused: ReadonlySet<number> = new Set(),
): PlacedStroke[] {
  const kept = strokes.filter((s) => !refused.has(s.seq));
  if (kept.length === 0) return [];
  const start = Math.min(...kept.map((s) => s.arrives_ms));
  const shifted = kept.map((s) => ({ ...s, arrives_ms: s.arrives_ms - start }));
  const estimate = placeStrokes(shifted, new Map(), cut, capped);
  const first = estimate.find((s) => startedAt.has(s.seq));
  if (first === undefined) return estimate;
  const offset = startedAt.get(first.seq)! - first.start_ms;
  const reported = new Map([...startedAt].map(([seq, at]) => [seq, at - offset]));
  return placeStrokes(shifted, reported, cut, capped);
}

type Step =
  | { kind: "append"; gap_ms: number; duration_ms: number }
  | { kind: "report"; pick: number; at_ms: number }
  | { kind: "cut"; pick: number; cut_ms: number }
  | { kind: "cap"; pick: number }
  | { kind: "refuse"; pick: number };

const step: fc.Arbitrary<Step> = fc.oneof(
  fc.record({
    kind: fc.constant("append" as const),
    gap_ms: fc.integer({ min: 0, max: 400 }),
    duration_ms: fc.integer({ min: 1, max: 300 }),
  }),
  fc.record({
    kind: fc.constant("report" as const),
    pick: fc.nat(),
    at_ms: fc.integer({ min: 0, max: 20_000 }),
  }),
  fc.record({ kind: fc.constant("cut" as const), pick: fc.nat(), cut_ms: fc.integer({ min: 0, max: 300 }) }),
  fc.record({ kind: fc.constant("cap" as const), pick: fc.nat() }),
  fc.record({ kind: fc.constant("refuse" as const), pick: fc.nat() }),
);

describe("FeltPlacement", () => {
  it("after every new stroke, report, cut, cap and refusal, places as the full computation does", () => {
    fc.assert(
      fc.property(fc.integer({ min: 0, max: 5000 }), fc.array(step, { maxLength: 60 }), (origin, steps) => {
        const placement = new FeltPlacement();
        const strokes: FeltStroke[] = [];
        const startedAt = new Map<number, number>();
        const cut = new Map<number, number>();
        const capped = new Set<number>();
        const refused = new Set<number>();
        let arrives = origin;
        for (const s of steps) {
          if (s.kind === "append") {
            arrives += s.gap_ms;
            const stroke: FeltStroke = {
              seq: strokes.length * 2, // gaps in seq, as undone paths leave
              start: [0, 0],
              end: [1, 1],
              duration_ms: s.duration_ms,
              intensity: 0.8,
              arrives_ms: arrives,
            };
            strokes.push(stroke);
            placement.append(stroke);
          } else if (strokes.length > 0) {
            const seq = strokes[s.pick % strokes.length]!.seq;
            if (s.kind === "report") {
              startedAt.set(seq, s.at_ms);
              placement.report(seq, s.at_ms);
            } else if (s.kind === "cut") {
              cut.set(seq, s.cut_ms);
              placement.cut(seq, s.cut_ms);
            } else if (s.kind === "cap") {
              capped.add(seq);
              placement.cap(seq);
            } else {
              refused.add(seq);
              placement.refuse(seq);
            }
          }
          if (strokes.length === 0) continue;
          const expected = placeFromScratch(strokes, startedAt, cut, capped, refused);
          expect(placement.placed).toEqual(expected);
          expect(placement.totalMs).toBe(totalMs(expected));
          expect(placement.reportedCount).toBe(expected.filter((p) => p.reported).length);
          expect(placement.cappedCount).toBe(expected.filter((p) => p.capped).length);
          for (const seq of refused) expect(placement.bySeq(seq)).toBeUndefined();
          for (const t of [0, 17, 150, 333, 1000, 4000, 12_000, totalMs(expected)]) {
            expect(placement.playingAt(t)).toEqual(playingAt(expected, t));
          }
        }
      }),
      { numRuns: 300 },
    );
  });

  it("reset gives the same placement as appending the strokes one by one", () => {
    const strokes: FeltStroke[] = [0, 1, 2, 3].map((seq) => ({
      seq,
      start: [0, 0],
      end: [1, 0],
      duration_ms: 100,
      intensity: 1,
      arrives_ms: 1000 + 30 * seq,
    }));
    const one = new FeltPlacement();
    for (const stroke of strokes) one.append(stroke);
    const all = new FeltPlacement();
    all.reset([...strokes].reverse());
    expect(all.placed).toEqual(one.placed);
    // Each waits behind the one before, so plays at the sleeve's floor.
    const F = SLEEVE_FLOOR_MS;
    expect(all.placed.map((s) => s.start_ms)).toEqual([0, 100, 100 + F, 100 + F + F]);
    expect(all.bySeq(2)?.start_ms).toBe(100 + F);
  });

  it("leaves a refused stroke out: the strokes after it move up into its place", () => {
    const placement = new FeltPlacement();
    for (const seq of [0, 1, 2, 3]) {
      placement.append({ seq, start: [0, 0], end: [1, 0], duration_ms: 100, intensity: 1, arrives_ms: 10 });
    }
    placement.refuse(1);
    // Each waits behind the one before, so plays at the sleeve's floor.
    const F = SLEEVE_FLOOR_MS;
    expect(placement.placed.map((s) => [s.seq, s.start_ms])).toEqual([
      [0, 0],
      [2, 100],
      [3, 100 + F],
    ]);
    expect(placement.totalMs).toBe(100 + F + F);
    // Refused before it is drawn (the event came first): never placed.
    placement.refuse(4);
    placement.append({ seq: 4, start: [0, 0], end: [1, 0], duration_ms: 100, intensity: 1, arrives_ms: 20 });
    expect(placement.placed.map((s) => s.seq)).toEqual([0, 2, 3]);
  });

  it("says from when the picture changed, and everything after a reset", () => {
    const placement = new FeltPlacement();
    expect(placement.takeDirty()).toBe("all");
    const stroke = (seq: number, arrives_ms: number): FeltStroke => ({
      seq,
      start: [0, 0],
      end: [1, 0],
      duration_ms: 100,
      intensity: 1,
      arrives_ms,
    });
    placement.append(stroke(0, 0));
    placement.append(stroke(1, 500));
    expect(placement.takeDirty()).toBe(0);
    placement.append(stroke(2, 900));
    expect(placement.takeDirty()).toBe(900);
    expect(placement.takeDirty()).toBeNull();
    placement.cut(1, 50);
    expect(placement.takeDirty()).toBe(500);
    expect(placement.firstEndingAfter(560)).toBe(2);
    placement.reset([stroke(0, 0)]);
    expect(placement.takeDirty()).toBe("all");
  });
});
