/**
 * What a change of settings asks of the page: every setting is in exactly one
 * group, so a new one cannot be forgotten (test/settings-diff.test.ts checks
 * it). Pure: the page does what the change says.
 */
import type { SenderTarget } from "./mqtt/sender";
import { LATE_LIMIT_MS, SIMPLIFIER_PARAM_KEYS, type SettingKey, type Settings } from "./settings";

/** Settings that change how a drawing is cut or mapped: changing one re-simplifies it. */
export const DRAWING_KEYS: readonly SettingKey[] = ["algorithm", ...SIMPLIFIER_PARAM_KEYS];
/** Settings that change the grid: a drawing mapped onto another grid cannot be shown on this one. */
export const GRID_KEYS: readonly SettingKey[] = ["grid_source", "rows", "columns"];
/** Settings that change where and how strokes are published: changing one reconnects. */
export const TARGET_KEYS = [
  "ws_url",
  "username",
  "password",
  "sleeve_id",
  "protocol",
  "legacy_topic",
] as const satisfies readonly (keyof SenderTarget & SettingKey)[];
/**
 * Settings read each time they are used (the next press, the next stroke, the sender's next
 * flush), or that only choose which value another key takes (`broker_custom`): nothing to redo.
 */
export const LIVE_KEYS: readonly SettingKey[] = [
  "clear_on_press",
  "late_strokes",
  "intensity",
  "pressure_sets_intensity",
  "broker_custom",
];

export interface SettingsChange {
  /** The grid changed: the drawing on the canvas was mapped onto another one. */
  readonly grid: boolean;
  /** How a drawing is cut or mapped changed. */
  readonly drawing: boolean;
  /** Where or how strokes are published changed: connect again. */
  readonly target: boolean;
  /** Another sleeve is drawn on. */
  readonly sleeve: boolean;
}

export function settingsChange(previous: Settings, next: Settings): SettingsChange {
  const changed = (keys: readonly SettingKey[]) => keys.some((key) => previous[key] !== next[key]);
  return {
    grid: changed(GRID_KEYS),
    drawing: changed(DRAWING_KEYS),
    target: changed(TARGET_KEYS),
    sleeve: previous.sleeve_id !== next.sleeve_id,
  };
}

/** Where and how the sender publishes, under `settings`. */
export function senderTarget(settings: Settings): SenderTarget {
  const { ws_url, username, password, sleeve_id, protocol, legacy_topic } = settings;
  return { ws_url, username, password, sleeve_id, protocol, legacy_topic };
}

/** The sender's limit for strokes it could not send at once: null, they go out whenever possible. */
export function lateLimitMs(settings: Settings): number | null {
  return settings.late_strokes === "drop" ? LATE_LIMIT_MS : null;
}
