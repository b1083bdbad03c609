/** Settings: validated with exactly the ranges of testdata/angle/params.json, persisted, reset. */
import { describe, expect, it } from "vitest";
import type { ServerConfig } from "../src/config";
import { memoryStorage } from "../src/memory-storage";
import { PARAMETERS } from "../src/simplify/params.generated";
import {
  DEFAULT_SETTINGS,
  FIELDS,
  STORAGE_KEY,
  defaultSettings,
  loadSettings,
  saveSettings,
  validateSettings,
  withServerBroker,
  type SettingKey,
  type Settings,
} from "../src/settings";
import { vectors } from "./testdata";

interface ParamRow {
  name: string;
  type: "integer" | "number" | "boolean";
  default: number | boolean;
  minimum: number | null;
  maximum: number | null;
}

const table = (
  vectors("angle").find(([name]) => name.endsWith("params.json"))![1] as { parameters: ParamRow[] }
).parameters;
const settingKeys = new Set<string>(FIELDS.map((field) => field.key));
/** The parameters the settings panel offers (the canvas size comes from the page). */
const offered = table.filter((row) => settingKeys.has(row.name));

function errorsFor(key: SettingKey, value: unknown): string | undefined {
  return validateSettings({ ...DEFAULT_SETTINGS, [key]: value })[key];
}

const CONFIG: ServerConfig = {
  ws_url: "ws://127.0.0.1:19001",
  sleeve_id: "armband",
  sleeves: ["armband"],
  username: "sender",
  password: "from-the-server",
};

describe("settings validation", () => {
  it("offers every parameter of the paper's B.1 a person sets, the sleeve grid too", () => {
    // The paper's names, from the generated table; the canvas size is set by the drawing area.
    const papers = PARAMETERS.filter((spec) => spec.paper !== null && spec.panel !== null);
    expect(papers.map((spec) => spec.name)).toEqual(
      expect.arrayContaining(["rows", "columns", "max_angle_deg"]),
    );
    for (const spec of papers) {
      expect(settingKeys.has(spec.name), spec.name).toBe(true);
    }
  });

  it("the defaults are valid and are the table's", () => {
    expect(validateSettings({ ...DEFAULT_SETTINGS })).toEqual({});
    for (const row of offered) {
      // One departure, on purpose: a press adds a path (letters of several strokes); the
      // paper's clear-on-press is one setting away.
      const expected = row.name === "clear_on_press" ? false : row.default;
      expect(DEFAULT_SETTINGS[row.name as SettingKey], row.name).toBe(expected);
    }
  });

  it.each(offered.filter((row) => row.type !== "boolean"))(
    "$name accepts exactly [$minimum, $maximum]",
    (row) => {
      const key = row.name as SettingKey;
      expect(errorsFor(key, row.minimum)).toBeUndefined();
      expect(errorsFor(key, row.maximum)).toBeUndefined();
      const step = row.type === "integer" ? 1 : 1e-9 * Math.max(1, Math.abs(row.maximum!));
      const below = errorsFor(key, row.minimum! - step);
      const above = errorsFor(key, row.maximum! + step);
      expect(below).toContain(`from ${row.minimum} to ${row.maximum}`);
      expect(above).toContain(`from ${row.minimum} to ${row.maximum}`);
      expect(errorsFor(key, Number.NaN)).toMatch(/must be/);
      expect(errorsFor(key, Number.POSITIVE_INFINITY)).toMatch(/must be/);
      if (row.type === "integer") {
        expect(errorsFor(key, row.minimum! + 0.5)).toMatch(/whole number/);
      }
    },
  );

  it.each(offered.filter((row) => row.type === "boolean"))("$name must be on or off", (row) => {
    expect(errorsFor(row.name as SettingKey, "yes")).toMatch(/on or off/);
    expect(errorsFor(row.name as SettingKey, false)).toBeUndefined();
  });

  it.each<[SettingKey, unknown, RegExp]>([
    ["intensity", 1.01, /from 0.01 to 1/],
    ["intensity", -0.1, /from 0.01 to 1/],
    ["intensity", 0, /from 0.01 to 1 \(at 0 the sleeve would play strokes no one feels\)/],
    ["sleeve_id", "sleeve/1", /letters, digits/],
    ["sleeve_id", "", /letters, digits/],
    ["legacy_topic", "deviceOne/#", /wildcards/],
    ["legacy_topic", "", /1 to 256/],
    ["ws_url", "http://127.0.0.1:9001", /ws:\/\/ or wss:\/\//],
    ["ws_url", "not a url", /WebSocket URL/],
    ["protocol", "xml", /listed choice/],
  ])("%s = %j is refused with a message naming what is allowed", (key, value, message) => {
    const error = errorsFor(key, value);
    expect(error).toMatch(message);
    // The message starts with the field's label, so it reads on its own.
    expect(error).toMatch(/^[A-Z]/);
  });

  it("accepts the other good values", () => {
    expect(errorsFor("ws_url", "wss://broker.example:8884/mqtt")).toBeUndefined();
    expect(errorsFor("sleeve_id", "Sleeve_2-b")).toBeUndefined();
    expect(errorsFor("intensity", 0.01)).toBeUndefined();
  });
});

describe("settings persistence", () => {
  it("round-trips through storage", () => {
    const storage = memoryStorage();
    const changed: Settings = { ...DEFAULT_SETTINGS, check_frames: 9, protocol: "legacy", intensity: 0.3 };
    saveSettings(storage, changed, null);
    expect(loadSettings(storage, null).settings).toEqual(changed);
  });

  it("falls back to the default for a stored value that is no longer valid, and says which", () => {
    const storage = memoryStorage({ [STORAGE_KEY]: JSON.stringify({ check_frames: 1, fps: 30 }) });
    const { settings, replaced } = loadSettings(storage, null);
    expect(settings.check_frames).toBe(DEFAULT_SETTINGS.check_frames);
    expect(settings.fps).toBe(30);
    expect(replaced).toEqual(["Check frames"]);
  });

  it("survives garbage in storage", () => {
    const storage = memoryStorage({ [STORAGE_KEY]: "{not json" });
    expect(loadSettings(storage, null).settings).toEqual(DEFAULT_SETTINGS);
  });

  it("uses the server's broker and sleeve, and does not store the server's password", () => {
    const storage = memoryStorage();
    const { settings } = loadSettings(storage, CONFIG);
    expect(settings).toMatchObject({
      ws_url: CONFIG.ws_url,
      password: CONFIG.password,
      sleeve_id: "armband",
    });
    saveSettings(storage, settings, CONFIG);
    expect(storage.getItem(STORAGE_KEY)).not.toContain(CONFIG.password);
    // A later server with a new password is followed, not shadowed by an old copy.
    const next = { ...CONFIG, password: "rotated" };
    expect(loadSettings(storage, next).settings.password).toBe("rotated");
  });

  it("keeps the person's own broker when they chose one", () => {
    const storage = memoryStorage();
    const own: Settings = {
      ...defaultSettings(CONFIG),
      broker_custom: true,
      ws_url: "wss://mine:8884",
      password: "p",
    };
    saveSettings(storage, own, CONFIG);
    expect(loadSettings(storage, CONFIG).settings).toMatchObject({
      ws_url: "wss://mine:8884",
      password: "p",
    });
    expect(withServerBroker(own, CONFIG).ws_url).toBe("wss://mine:8884");
  });

  it("resetting gives the table's defaults with the server's broker", () => {
    expect(defaultSettings(CONFIG)).toEqual({
      ...DEFAULT_SETTINGS,
      sleeve_id: CONFIG.sleeve_id,
      ws_url: CONFIG.ws_url,
      username: CONFIG.username,
      password: CONFIG.password,
    });
  });
});
