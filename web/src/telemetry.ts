/**
 * The sleeve's `actuators` telemetry, read defensively (its `status` and
 * `events` are typed in events.ts). A payload that does not have the expected
 * shape gives null, never an exception: the sender's page must survive any
 * message a broker delivers.
 */

export interface ActuatorFrame {
  readonly t_ms: number;
  readonly rows: number;
  readonly columns: number;
  /** intensities[row][column], clamped into 0..1. */
  readonly intensities: readonly (readonly number[])[];
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
