/**
 * Stroke messages on the wire, as the sender writes them: JSON v1 and the
 * original sleeve's legacy text ("Can You Feel My Sign?", appendix A.2).
 * Port of `format_json` / `format_legacy` in `feelmysign/protocol.py`; both
 * produce the bytes of `testdata/protocol/format/*.json`. docs/protocol.md
 * describes the formats and every field's range.
 */
import type { Point } from "./simplify/segment";

/** A straight stroke in grid units and ms; optional fields left out when null or undefined. */
export interface Stroke {
  readonly start: Point;
  readonly end: Point;
  readonly duration_ms: number;
  readonly intensity?: number | null;
  readonly drawing?: string | null;
  readonly seq?: number | null;
  readonly sent_at_ms?: number | null;
}

export const JSON_VERSION = 1;
/** 1e-4 grid units is ~3 micrometres on a 3 cm grid: far below touch acuity. */
export const LEGACY_DECIMALS = 4;
/** The largest integer a JavaScript sender holds exactly. */
export const MAX_SEQ = Number.MAX_SAFE_INTEGER;
/** The latest sent_at_ms a sender's clock can give (1e13 ms: 20 November 2286), as the sleeve checks. */
export const MAX_SENT_AT_MS = 1e13;
/** Printable ASCII without spaces, 1 to 64 characters (a UUID is 36). */
export const DRAWING_ID = /^[!-~]{1,64}$/;
/** Number.prototype.toFixed switches to exponent notation from here on. */
const TO_FIXED_LIMIT = 1e21;

/** A stroke no sleeve would accept; `reason` is the protocol's stable reason code. */
export class StrokeError extends Error {
  readonly reason: string;
  constructor(reason: string, message: string) {
    super(message);
    this.name = "StrokeError";
    this.reason = reason;
  }
}

/** The compact JSON v1 text, keys in wire order, optional fields left out. */
export function formatJson(stroke: Stroke): string {
  throwIfInvalid(stroke);
  const fields: [string, unknown][] = [
    ["v", JSON_VERSION],
    ["drawing", stroke.drawing],
    ["seq", stroke.seq],
    ["start", [stroke.start[0], stroke.start[1]]],
    ["end", [stroke.end[0], stroke.end[1]]],
    ["duration_ms", stroke.duration_ms],
    ["intensity", stroke.intensity],
    ["sent_at_ms", stroke.sent_at_ms],
  ];
  const parts = fields
    .filter(([, value]) => value !== null && value !== undefined)
    .map(([key, value]) => `${JSON.stringify(key)}:${JSON.stringify(value)}`);
  return `{${parts.join(",")}}`;
}

/**
 * The legacy text `startX,startY,endX,endY,duration`: at most 4 decimals, no
 * trailing zeros, half away from zero on the exact binary value. Intensity,
 * drawing, seq and sent_at_ms cannot be carried and are dropped.
 */
export function formatLegacy(stroke: Stroke): string {
  throwIfInvalid(stroke);
  const numbers = [stroke.start[0], stroke.start[1], stroke.end[0], stroke.end[1], stroke.duration_ms];
  return numbers.map(legacyDecimal).join(",");
}

function legacyDecimal(value: number): string {
  // Doubles this large are whole numbers; BigInt writes every digit as the reference does.
  if (Math.abs(value) >= TO_FIXED_LIMIT) return BigInt(value).toString();
  const text = value.toFixed(LEGACY_DECIMALS).replace(/0+$/, "").replace(/\.$/, "");
  return text === "" || text === "-0" ? "0" : text;
}

/** The first problem in wire order (the same order as the reference), or null. */
export function strokeProblem(stroke: Stroke): StrokeError | null {
  const { drawing, seq, start, end, duration_ms, intensity, sent_at_ms } = stroke;
  if (drawing !== null && drawing !== undefined && !DRAWING_ID.test(drawing)) {
    return new StrokeError(
      "bad_drawing_id",
      `"drawing" is ${JSON.stringify(drawing)}; it must be 1 to 64 printable ASCII characters without spaces (a UUID works).`,
    );
  }
  if (seq !== null && seq !== undefined && !(Number.isInteger(seq) && seq >= 0 && seq <= MAX_SEQ)) {
    return new StrokeError(
      "seq_out_of_range",
      `"seq" is ${seq}; it must be a whole number from 0 to ${MAX_SEQ}.`,
    );
  }
  for (const [key, point] of [
    ["start", start],
    ["end", end],
  ] as const) {
    if (!Number.isFinite(point[0]) || !Number.isFinite(point[1])) {
      return new StrokeError("not_finite", `${key} (${point[0]}, ${point[1]}) is not a finite point.`);
    }
  }
  if (!Number.isFinite(duration_ms)) {
    return new StrokeError(
      "not_finite",
      `duration_ms is ${duration_ms}; it must be a finite number of milliseconds.`,
    );
  }
  if (duration_ms <= 0) {
    return new StrokeError(
      "duration_not_positive",
      `duration_ms is ${duration_ms}; a stroke must last more than 0 ms.`,
    );
  }
  if (intensity !== null && intensity !== undefined) {
    if (!Number.isFinite(intensity)) {
      return new StrokeError(
        "not_finite",
        `intensity is ${intensity}; it must be a finite number from 0 to 1.`,
      );
    }
    if (intensity < 0 || intensity > 1) {
      return new StrokeError(
        "intensity_out_of_range",
        `intensity is ${intensity}; it must be from 0 (off) to 1 (strongest).`,
      );
    }
  }
  if (sent_at_ms !== null && sent_at_ms !== undefined) {
    if (!Number.isFinite(sent_at_ms)) {
      return new StrokeError(
        "not_finite",
        `sent_at_ms is ${sent_at_ms}; it must be a finite time in milliseconds.`,
      );
    }
    if (sent_at_ms < 0) {
      return new StrokeError("sent_at_out_of_range", `sent_at_ms is ${sent_at_ms}; it must be 0 or more.`);
    }
    if (sent_at_ms > MAX_SENT_AT_MS) {
      return new StrokeError(
        "sent_at_out_of_range",
        `sent_at_ms is ${sent_at_ms}; it must be at most ${MAX_SENT_AT_MS} (the year 2286): check this machine's clock.`,
      );
    }
  }
  return null;
}

function throwIfInvalid(stroke: Stroke): void {
  const problem = strokeProblem(stroke);
  if (problem !== null) throw problem;
}
