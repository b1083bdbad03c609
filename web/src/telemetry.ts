/**
 * The sleeve's telemetry, read defensively: `status` (retained), `actuators`
 * and `events` under `feelmysign/<sleeve-id>/`. A payload that does not have
 * the expected shape gives null (and the page says so), never an exception:
 * the sender's page must survive any message a broker delivers.
 */

export interface SleeveLayout {
  readonly rows: number;
  readonly columns: number;
  readonly spacing_cm: number | null;
}

export interface SleeveStatus {
  readonly online: boolean;
  readonly layout: SleeveLayout | null;
  readonly version: string | null;
}

export interface ActuatorFrame {
  readonly t_ms: number;
  readonly rows: number;
  readonly columns: number;
  /** intensities[row][column], clamped into 0..1. */
  readonly intensities: readonly (readonly number[])[];
}

/** played/adjusted (played, slowed or changed) and rejected per stroke; safety and error per sleeve. */
export type SleeveEventType = "played" | "rejected" | "adjusted" | "safety" | "error";

export interface SleeveEvent {
  readonly type: SleeveEventType;
  readonly reason: string | null;
  readonly message: string | null;
  readonly drawing: string | null;
  readonly seq: number | null;
  /** The duration played; for "adjusted", instead of `requested_duration_ms`. */
  readonly duration_ms: number | null;
  readonly requested_duration_ms: number | null;
  /** For "safety" and "error": the actuator concerned, when there is one. */
  readonly row: number | null;
  readonly column: number | null;
}

/** A grid side the page will draw: the layout file's own limit. */
const MAX_GRID_SIDE = 64;

function parseObject(text: string): Record<string, unknown> | null {
  try {
    const value: unknown = JSON.parse(text);
    return typeof value === "object" && value !== null && !Array.isArray(value)
      ? (value as Record<string, unknown>)
      : null;
  } catch {
    return null;
  }
}

function gridSide(value: unknown): number | null {
  return typeof value === "number" && Number.isInteger(value) && value >= 1 && value <= MAX_GRID_SIDE
    ? value
    : null;
}

function finiteOrNull(value: unknown): number | null {
  return typeof value === "number" && Number.isFinite(value) ? value : null;
}

function stringOrNull(value: unknown): string | null {
  return typeof value === "string" ? value : null;
}

export function parseStatus(text: string): SleeveStatus | null {
  const data = parseObject(text);
  if (data === null || typeof data["online"] !== "boolean") return null;
  let layout: SleeveLayout | null = null;
  const raw = data["layout"];
  if (typeof raw === "object" && raw !== null) {
    const fields = raw as Record<string, unknown>;
    const rows = gridSide(fields["rows"]);
    const columns = gridSide(fields["columns"]);
    if (rows !== null && columns !== null) {
      layout = { rows, columns, spacing_cm: finiteOrNull(fields["spacing_cm"]) };
    }
  }
  const version = data["version"];
  return {
    online: data["online"],
    layout,
    version: typeof version === "string" || typeof version === "number" ? String(version) : null,
  };
}

export function parseActuators(text: string): ActuatorFrame | null {
  const data = parseObject(text);
  if (data === null) return null;
  const rows = gridSide(data["rows"]);
  const columns = gridSide(data["columns"]);
  const grid = data["intensities"];
  if (rows === null || columns === null || !Array.isArray(grid) || grid.length !== rows) return null;
  const intensities: number[][] = [];
  for (const row of grid) {
    if (!Array.isArray(row) || row.length !== columns) return null;
    const values: number[] = [];
    for (const value of row) {
      if (typeof value !== "number" || !Number.isFinite(value)) return null;
      values.push(Math.min(Math.max(value, 0), 1));
    }
    intensities.push(values);
  }
  return { t_ms: finiteOrNull(data["t_ms"]) ?? 0, rows, columns, intensities };
}

const EVENT_TYPES: readonly string[] = ["played", "rejected", "adjusted", "safety", "error"];

function indexOrNull(value: unknown): number | null {
  return typeof value === "number" && Number.isInteger(value) && value >= 0 ? value : null;
}

export function parseEvent(text: string): SleeveEvent | null {
  const data = parseObject(text);
  const type = data?.["type"];
  if (data === null || typeof type !== "string" || !EVENT_TYPES.includes(type)) return null;
  return {
    type: type as SleeveEventType,
    reason: stringOrNull(data["reason"]),
    message: stringOrNull(data["message"]),
    drawing: stringOrNull(data["drawing"]),
    seq: indexOrNull(data["seq"]),
    duration_ms: finiteOrNull(data["duration_ms"]),
    requested_duration_ms: finiteOrNull(data["requested_duration_ms"]),
    row: indexOrNull(data["row"]),
    column: indexOrNull(data["column"]),
  };
}
