/** What a change of settings asks of the page: each key in one group, each group noticed. */
import { describe, expect, it } from "vitest";
import { DEFAULT_SETTINGS, LATE_LIMIT_MS, type SettingKey, type Settings } from "../src/settings";
import {
  DRAWING_KEYS,
  GRID_KEYS,
  LIVE_KEYS,
  TARGET_KEYS,
  lateLimitMs,
  senderTarget,
  settingsChange,
} from "../src/settings-diff";

const GROUPS: Record<string, readonly SettingKey[]> = {
  drawing: DRAWING_KEYS,
  grid: GRID_KEYS,
  target: TARGET_KEYS,
  live: LIVE_KEYS,
};

/** A value of `key` other than the default's, of the same type. */
function other(key: SettingKey): Settings {
  const value = DEFAULT_SETTINGS[key];
  const changed =
    typeof value === "boolean"
      ? !value
      : typeof value === "number"
        ? value + 1
        : key === "algorithm"
          ? value === "window"
            ? "angle"
            : "window"
          : `${value}-other`;
  return { ...DEFAULT_SETTINGS, [key]: changed } as Settings;
}

describe("settings groups", () => {
  it("put every setting in exactly one group", () => {
    const counts = new Map<string, string[]>();
    for (const [group, keys] of Object.entries(GROUPS))
      for (const key of keys) counts.set(key, [...(counts.get(key) ?? []), group]);
    for (const key of Object.keys(DEFAULT_SETTINGS)) {
      expect(counts.get(key), `setting ${key}: in which group`).toHaveLength(1);
    }
    expect([...counts.keys()].sort()).toEqual(Object.keys(DEFAULT_SETTINGS).sort());
  });

  it.each(Object.keys(DEFAULT_SETTINGS) as SettingKey[])("notices a change of %s", (key) => {
    const change = settingsChange(DEFAULT_SETTINGS, other(key));
    expect(change.grid).toBe(GRID_KEYS.includes(key));
    expect(change.drawing).toBe(DRAWING_KEYS.includes(key));
    expect(change.target).toBe((TARGET_KEYS as readonly SettingKey[]).includes(key));
    expect(change.sleeve).toBe(key === "sleeve_id");
  });

  it("sees no change between equal settings", () => {
    expect(settingsChange(DEFAULT_SETTINGS, { ...DEFAULT_SETTINGS })).toEqual({
      grid: false,
      drawing: false,
      target: false,
      sleeve: false,
    });
  });
});

describe("the sender", () => {
  it("publishes where the target keys say, and nothing else", () => {
    const settings: Settings = { ...DEFAULT_SETTINGS, ws_url: "wss://example.org:8443", sleeve_id: "left" };
    const target = senderTarget(settings);
    expect(Object.keys(target).sort()).toEqual([...TARGET_KEYS].sort());
    expect(target.ws_url).toBe("wss://example.org:8443");
    expect(target.sleeve_id).toBe("left");
  });

  it("drops late strokes only when asked", () => {
    expect(lateLimitMs({ ...DEFAULT_SETTINGS, late_strokes: "drop" })).toBe(LATE_LIMIT_MS);
    expect(lateLimitMs({ ...DEFAULT_SETTINGS, late_strokes: "send" })).toBeNull();
  });
});
