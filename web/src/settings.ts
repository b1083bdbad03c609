/**
 * The sender's settings: every parameter of the paper's appendix B.1, the
 * sleeve, the intensity, the wire format and the broker. One table of fields
 * drives validation and the settings panel; the simplifiers' fields are the
 * rows of their parameter table (`simplify/params.generated.ts`, generated from
 * the Python reference's declarations) with its labels, units, defaults and
 * ranges, so both sides accept exactly the same values. Pure: storage is passed in.
 */
import type { ServerConfig } from "./config";
import { LEGACY_TOPIC } from "./mqtt/topics";
import {
  ANGLE_PARAM_NAMES,
  PARAMETERS,
  WINDOW_PARAM_NAMES,
  paramProblem,
  type AngleParams,
  type PanelParamName,
  type PanelParams,
  type PanelSection,
  type ParamSpec,
  type WindowParams,
} from "./simplify/params";
import type { Algorithm, SimplifierParams } from "./simplify/registry";

export type WireProtocol = "json" | "legacy";
/** Strokes that could not be sent at once (no broker): sent when it is back, or dropped. */
export type LateStrokes = "send" | "drop";
/** With "drop": a stroke not sent within this time is no longer the drawing's touch. */
export const LATE_LIMIT_MS = 2000;
/**
 * The faintest intensity sent (Python's `cli.send.MIN_INTENSITY`): at 0 the sleeve plays and reports
 * a stroke as played that no one feels, so 0 is refused here rather than reported as played.
 */
export const MIN_INTENSITY = 0.01;
export type GridSource = "status" | "manual";

/** Both simplifiers' parameters that a person sets (`PanelParams`), and the page's own settings. */
export interface Settings extends PanelParams {
  /** The simplifier: the paper's angle rule, or the error-bounded window. */
  readonly algorithm: Algorithm;
  readonly late_strokes: LateStrokes;
  /** Where the grid comes from: the sleeve's retained status, or rows/columns below. */
  readonly grid_source: GridSource;
  readonly intensity: number;
  readonly pressure_sets_intensity: boolean;
  readonly protocol: WireProtocol;
  readonly legacy_topic: string;
  readonly sleeve_id: string;
  /** Use the broker below instead of the one the server's /config.json names. */
  readonly broker_custom: boolean;
  readonly ws_url: string;
  readonly username: string;
  readonly password: string;
}

export type SettingKey = keyof Settings;
export type FieldKind = "integer" | "number" | "boolean" | "text" | "password" | "choice";

export interface FieldSpec {
  readonly key: SettingKey;
  readonly section: PanelSection | "connection";
  readonly label: string;
  readonly help: string;
  readonly kind: FieldKind;
  readonly minimum?: number;
  readonly maximum?: number;
  readonly unit?: string;
  readonly choices?: readonly { readonly value: string; readonly label: string }[];
  /** Read only while the switch `key` is `value` (the other core ignores it): locked otherwise. */
  readonly onlyWhen?: { readonly key: SettingKey; readonly value: boolean };
  /** Why the value is not allowed (a sentence fragment after the label), or null. */
  problem(value: unknown): string | null;
}

export const STORAGE_KEY = "feelmysign.settings.v1";
const SLEEVE_ID = /^[A-Za-z0-9_-]{1,64}$/;
/** MQTT allows 65535 bytes; a topic a person types is far shorter, and a log line stays readable. */
const MAX_TOPIC_CHARS = 256;

/** The parameters the settings panel shows, in the table's order. */
const PANEL_PARAMS = PARAMETERS.filter(
  (spec): spec is ParamSpec<PanelParamName> & { panel: PanelSection } => spec.panel !== null,
);

/** The simplifier parameters whose change re-cuts a drawing (the panel's simplifier section). */
export const SIMPLIFIER_PARAM_KEYS: readonly SettingKey[] = PANEL_PARAMS.filter(
  (spec) => spec.panel === "simplifier",
).map((spec) => spec.name);

/** The panel's rows for the parameters of one section, from their table. */
function paramFields(section: PanelSection): FieldSpec[] {
  return PANEL_PARAMS.filter((spec) => spec.panel === section).map(specField);
}

function specField(spec: ParamSpec<PanelParamName> & { panel: PanelSection }): FieldSpec {
  const kind: FieldKind = spec.type === "boolean" ? "boolean" : spec.type;
  return {
    key: spec.name,
    section: spec.panel,
    label: spec.label,
    help: spec.help,
    kind,
    ...(spec.minimum !== null ? { minimum: spec.minimum } : {}),
    ...(spec.maximum !== null ? { maximum: spec.maximum } : {}),
    ...(spec.unit !== null ? { unit: spec.unit } : {}),
    ...(spec.only_when !== null
      ? { onlyWhen: { key: spec.only_when.name as SettingKey, value: spec.only_when.value } }
      : {}),
    problem: (value) => paramProblem(spec, value),
  };
}

function boolField(key: SettingKey, section: FieldSpec["section"], label: string, help: string): FieldSpec {
  return {
    key,
    section,
    label,
    help,
    kind: "boolean",
    problem: (value) => (typeof value === "boolean" ? null : "must be on or off"),
  };
}

function textProblem(value: unknown, check: (text: string) => string | null): string | null {
  return typeof value === "string" ? check(value) : "must be text";
}

export const FIELDS: readonly FieldSpec[] = [
  // The page's own help: what a press does here, where New drawing starts over.
  ...paramFields("drawing").map((field) =>
    field.key === "clear_on_press"
      ? {
          ...field,
          help:
            "on: every press starts a new drawing, as in the paper; off: a press adds a path to the drawing " +
            "(letters of several strokes), and New drawing starts over",
        }
      : field,
  ),
  {
    key: "late_strokes",
    section: "drawing",
    label: "Timing",
    help:
      `strokes drawn while the broker is out of reach: sent when it is back, with the time they were drawn ` +
      `(the sleeve plays those it is not too late for, counted delayed, and refuses the rest as late), ` +
      `or dropped after ${LATE_LIMIT_MS / 1000} s`,
    kind: "choice",
    choices: [
      { value: "send", label: "Send late" },
      { value: "drop", label: "Drop late" },
    ],
    problem: (value) => (value === "send" || value === "drop" ? null : "must be a listed choice"),
  },
  {
    key: "intensity",
    section: "drawing",
    label: "Intensity",
    help: "how strongly the sleeve vibrates (1 = strongest; 0 is not sent: nothing would be felt)",
    kind: "number",
    minimum: MIN_INTENSITY,
    maximum: 1,
    problem: (value) =>
      typeof value === "number" && value >= MIN_INTENSITY && value <= 1
        ? null
        : `must be a number from ${MIN_INTENSITY} to 1 (at 0 the sleeve would play strokes no one feels)`,
  },
  boolField(
    "pressure_sets_intensity",
    "drawing",
    "Pen pressure sets intensity",
    "with a pen, pressing fully gives the intensity above and lighter presses less (mouse and touch report no real pressure)",
  ),
  {
    key: "algorithm",
    section: "simplifier",
    label: "Simplifier",
    help: "angle: the paper's turn rule; window: every drawn point within the max error of its stroke",
    kind: "choice",
    choices: [
      { value: "angle", label: "Angle (paper)" },
      { value: "window", label: "Window (error-bounded)" },
    ],
    problem: (value) => (value === "angle" || value === "window" ? null : "must be a listed choice"),
  },
  ...paramFields("simplifier"),
  {
    key: "sleeve_id",
    section: "sleeve",
    label: "Sleeve id",
    help: "the sleeve to draw on: strokes go to feelmysign/<id>/strokes",
    kind: "text",
    problem: (value) =>
      textProblem(value, (text) =>
        SLEEVE_ID.test(text) ? null : "must be 1 to 64 letters, digits, '_' or '-' (e.g. sleeve1)",
      ),
  },
  {
    key: "grid_source",
    section: "sleeve",
    label: "Grid",
    help: "the actuator grid the drawing area is shaped after",
    kind: "choice",
    choices: [
      { value: "status", label: "From the sleeve" },
      { value: "manual", label: "Set here" },
    ],
    problem: (value) => (value === "status" || value === "manual" ? null : "must be a listed choice"),
  },
  ...paramFields("sleeve"),
  {
    key: "protocol",
    section: "connection",
    label: "Message format",
    help: "JSON v1 carries intensity and order; legacy text drives the paper's original sleeve",
    kind: "choice",
    choices: [
      { value: "json", label: "JSON v1" },
      { value: "legacy", label: "Legacy text" },
    ],
    problem: (value) => (value === "json" || value === "legacy" ? null : "must be a listed choice"),
  },
  {
    key: "legacy_topic",
    section: "connection",
    label: "Legacy topic",
    help: "where legacy text strokes are published",
    kind: "text",
    problem: (value) =>
      textProblem(value, (text) => {
        if (text.length === 0 || text.length > MAX_TOPIC_CHARS) {
          return `must be 1 to ${MAX_TOPIC_CHARS} characters (e.g. deviceOne/line)`;
        }
        return /[+#\u0000]/.test(text) ? "cannot contain '+', '#' (MQTT wildcards) or NUL" : null;
      }),
  },
  boolField(
    "broker_custom",
    "connection",
    "Use my own broker",
    "instead of the broker the server hands the page",
  ),
  {
    key: "ws_url",
    section: "connection",
    label: "Broker URL",
    help: "MQTT over WebSockets",
    kind: "text",
    problem: (value) => textProblem(value, wsUrlProblem),
  },
  {
    key: "username",
    section: "connection",
    label: "Username",
    help: "the broker's sender account",
    kind: "text",
    problem: (value) =>
      textProblem(value, (text) => (text.length <= 256 ? null : "must be at most 256 characters")),
  },
  {
    key: "password",
    section: "connection",
    label: "Password",
    help: "kept in this browser only when you use your own broker",
    kind: "password",
    problem: (value) =>
      textProblem(value, (text) => (text.length <= 256 ? null : "must be at most 256 characters")),
  },
];

function wsUrlProblem(text: string): string | null {
  let url: URL;
  try {
    url = new URL(text);
  } catch {
    return "must be a WebSocket URL such as ws://127.0.0.1:9001";
  }
  return url.protocol === "ws:" || url.protocol === "wss:"
    ? null
    : `must start with ws:// or wss:// (got ${url.protocol}//)`;
}

const FIELDS_BY_KEY = new Map(FIELDS.map((field) => [field.key, field]));

export function fieldSpec(key: SettingKey): FieldSpec {
  const field = FIELDS_BY_KEY.get(key);
  if (field === undefined) throw new Error(`no settings field '${key}'`);
  return field;
}

/** Whether a field is read with these values: not while its switch (`onlyWhen`) is the other way. */
export function conditionMet(field: FieldSpec, values: Partial<Record<SettingKey, unknown>>): boolean {
  return field.onlyWhen === undefined || values[field.onlyWhen.key] === field.onlyWhen.value;
}

/** What a field read by one core only says while locked: "Lookahead: least squares only". */
export function conditionNote(field: FieldSpec): string | null {
  if (field.onlyWhen === undefined) return null;
  const switchLabel = fieldSpec(field.onlyWhen.key).label.toLowerCase();
  return field.onlyWhen.value
    ? `${field.label}: ${switchLabel} only`
    : `${field.label}: only with ${switchLabel} off`;
}

/** The reference's defaults of the parameters a person sets. */
const PANEL_DEFAULTS = Object.fromEntries(
  PANEL_PARAMS.map((spec) => [spec.name, spec.default]),
) as unknown as PanelParams;

export const DEFAULT_SETTINGS: Settings = Object.freeze({
  ...PANEL_DEFAULTS,
  // The project's default (docs/research.md, "Default settings"); "angle" is the paper's.
  algorithm: "window",
  // The paper cleared the drawing at every press; people expect a letter of several paths.
  clear_on_press: false,
  late_strokes: "send",
  grid_source: "status",
  intensity: 0.8,
  pressure_sets_intensity: true,
  protocol: "json",
  legacy_topic: LEGACY_TOPIC,
  sleeve_id: "sleeve1",
  broker_custom: false,
  ws_url: "ws://127.0.0.1:9001",
  username: "sender",
  password: "",
});

export type SettingsErrors = Partial<Record<SettingKey, string>>;

/** Every field's problem, keyed by field; empty when all are valid. */
export function validateSettings(candidate: Record<SettingKey, unknown>): SettingsErrors {
  const errors: SettingsErrors = {};
  for (const field of FIELDS) {
    const problem = field.problem(candidate[field.key]);
    if (problem !== null) errors[field.key] = `${field.label} ${problem}.`;
  }
  return errors;
}

/** The defaults, with the server's broker and sleeve when it gave them. */
export function defaultSettings(config: ServerConfig | null): Settings {
  if (config === null) return DEFAULT_SETTINGS;
  return {
    ...DEFAULT_SETTINGS,
    sleeve_id: config.sleeve_id,
    ws_url: config.ws_url,
    username: config.username,
    password: config.password,
  };
}

/** The broker settings in force: the server's unless the person chose their own. */
export function withServerBroker(settings: Settings, config: ServerConfig | null): Settings {
  if (config === null || settings.broker_custom) return settings;
  return { ...settings, ws_url: config.ws_url, username: config.username, password: config.password };
}

export interface LoadedSettings {
  readonly settings: Settings;
  /** Stored values that were not valid any more and were replaced by defaults. */
  readonly replaced: readonly string[];
}

/** Stored settings over the defaults; a stored value that fails validation falls back. */
export function loadSettings(storage: Pick<Storage, "getItem">, config: ServerConfig | null): LoadedSettings {
  const defaults = defaultSettings(config);
  let stored: unknown = null;
  try {
    stored = JSON.parse(storage.getItem(STORAGE_KEY) ?? "null");
  } catch {
    stored = null;
  }
  const merged: Record<string, unknown> = { ...defaults };
  const replaced: string[] = [];
  if (typeof stored === "object" && stored !== null) {
    for (const field of FIELDS) {
      const value = (stored as Record<string, unknown>)[field.key];
      if (value === undefined) continue;
      if (field.problem(value) === null) merged[field.key] = value;
      else replaced.push(field.label);
    }
  }
  return { settings: withServerBroker(merged as unknown as Settings, config), replaced };
}

/**
 * Persists the settings. The broker and password are kept only when they are
 * the person's own: the server's login changes with its state directory, and
 * a stale copy here would lock the page out.
 */
export function saveSettings(
  storage: Pick<Storage, "setItem">,
  settings: Settings,
  config: ServerConfig | null,
): void {
  if (config !== null && !settings.broker_custom) {
    const { ws_url: _url, username: _user, password: _password, ...rest } = settings;
    storage.setItem(STORAGE_KEY, JSON.stringify(rest));
  } else {
    storage.setItem(STORAGE_KEY, JSON.stringify(settings));
  }
}

type Grid = { readonly rows: number; readonly columns: number };
type Canvas = { readonly width_px: number; readonly height_px: number };

/** A simplifier's parameters from the settings, in its table's order, on this grid and canvas. */
function paramsFrom<P extends SimplifierParams>(
  algorithm: P["algorithm"],
  names: readonly string[],
  settings: Settings,
  grid: Grid,
  canvas: Canvas,
): P {
  const values: Record<string, unknown> = {
    ...settings,
    rows: grid.rows,
    columns: grid.columns,
    canvas_width_px: canvas.width_px,
    canvas_height_px: canvas.height_px,
  };
  return Object.fromEntries([["algorithm", algorithm], ...names.map((name) => [name, values[name]])]) as P;
}

/** The simplifier's parameters for a drawing area of this size on this grid. */
export function angleParams(settings: Settings, grid: Grid, canvas: Canvas): AngleParams {
  return paramsFrom<AngleParams>("angle", ANGLE_PARAM_NAMES, settings, grid, canvas);
}

/** The window simplifier's parameters for a drawing area of this size on this grid. */
export function windowParams(settings: Settings, grid: Grid, canvas: Canvas): WindowParams {
  return paramsFrom<WindowParams>("window", WINDOW_PARAM_NAMES, settings, grid, canvas);
}

/** The chosen simplifier's parameters (their `algorithm` says which one). */
export function simplifierParams(settings: Settings, grid: Grid, canvas: Canvas): SimplifierParams {
  return settings.algorithm === "window"
    ? windowParams(settings, grid, canvas)
    : angleParams(settings, grid, canvas);
}
