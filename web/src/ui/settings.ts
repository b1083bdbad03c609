/**
 * The settings panel: a slide-over sheet (a full screen on phones) built from
 * the settings' field table, so every field shows its help, unit and allowed
 * range, and an inline error naming that range as soon as a value is wrong.
 * Save is possible only when every field is valid; Reset fills in the defaults.
 */
import type { ServerConfig } from "../config";
import type { SleeveFloor } from "../events";
import { floorNote, type Minimums } from "../sleeve-floor";
import { ceilingNote } from "../wearer-status";
import {
  FIELDS,
  conditionMet,
  conditionNote,
  defaultSettings,
  fieldSpec,
  validateSettings,
  type FieldSpec,
  type SettingKey,
  type Settings,
} from "../settings";
import type { GridSize } from "./geometry";
import { byId } from "./status";
import { ONLY_FOR } from "../simplify/registry";
import { DETAIL_LEVELS, detailLevel, detailValues } from "./detail";

/** The few settings most people change; everything else is under Advanced. */
const BASIC: readonly SettingKey[] = ["intensity", "late_strokes", "clear_on_press", "sleeve_id"];
const DETAIL_NAMES = ["coarse", "broad", "medium", "fine", "finest"] as const;
/** A decimal number as people type it: no hex (0x10), no words (Infinity), no digit separators. */
const DECIMAL = /^[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$/;

const SECTIONS: readonly { id: FieldSpec["section"]; title: string; note?: string }[] = [
  { id: "drawing", title: "Drawing" },
  {
    id: "simplifier",
    title: "Simplifier",
    note:
      "How a drawing is cut into straight strokes: the paper's angle rule (its appendix B.1) " +
      "or the window simplifier, which keeps every drawn point within the max error of its stroke.",
  },
  { id: "sleeve", title: "Sleeve" },
  { id: "connection", title: "Connection" },
];

type Candidate = Record<SettingKey, unknown>;

export interface SettingsPanelContext {
  readonly config: ServerConfig | null;
  /** The grid the sleeve reports, for the "From the sleeve" choice. */
  readonly sleeveGrid: GridSize | null;
  /** The sleeve's actuator spacing: what one grid unit is on the skin. */
  readonly spacingCm?: number | null;
  /** The sleeve's floor (its status): the simplifier's minimums are raised to it. */
  readonly floor?: SleeveFloor | null;
  /** The wearer's intensity ceiling (the status's controls): the sleeve plays no stronger. */
  readonly ceiling?: number | null;
}

export class SettingsPanel {
  readonly #dialog: HTMLDialogElement;
  readonly #body: HTMLElement;
  readonly #summary: HTMLElement;
  readonly #save: HTMLButtonElement;
  readonly #onSave: (settings: Settings) => void;
  readonly #inputs = new Map<SettingKey, HTMLInputElement[]>();
  readonly #errors = new Map<SettingKey, HTMLElement>();
  readonly #rows = new Map<SettingKey, HTMLElement>();
  /** The note a field read by one core only shows while locked. */
  readonly #conditionNotes = new Map<SettingKey, HTMLElement>();
  #context: SettingsPanelContext = { config: null, sleeveGrid: null };
  /** The settings in force when the panel opened. */
  #current: Settings = defaultSettings(null);
  #gridNote: HTMLElement | null = null;
  #brokerNote: HTMLElement | null = null;
  #unitNote: HTMLElement | null = null;
  #floorNote: HTMLElement | null = null;
  #ceilingNote: HTMLElement | null = null;
  #detail: HTMLInputElement | null = null;
  #detailText: HTMLElement | null = null;
  #detailLimit: HTMLElement | null = null;

  constructor(root: Document, onSave: (settings: Settings) => void) {
    this.#dialog = byId<HTMLDialogElement>(root, "settings");
    this.#body = byId(root, "settings-body");
    this.#summary = byId(root, "settings-summary");
    this.#save = byId<HTMLButtonElement>(root, "settings-save");
    this.#onSave = onSave;
    this.#build();
    byId(root, "settings-form").addEventListener("submit", (event) => {
      event.preventDefault();
      this.#submit();
    });
    byId(root, "settings-close").addEventListener("click", () => this.#dialog.close());
    byId(root, "settings-cancel").addEventListener("click", () => this.#dialog.close());
    byId(root, "settings-reset").addEventListener("click", () => {
      this.#fill(defaultSettings(this.#context.config));
      this.#validate();
    });
    // A click on the backdrop (outside the sheet) closes it, as on any slide-over.
    this.#dialog.addEventListener("click", (event) => {
      if (event.target === this.#dialog) this.#dialog.close();
    });
  }

  get isOpen(): boolean {
    return this.#dialog.open;
  }

  open(settings: Settings, context: SettingsPanelContext): void {
    this.#context = context;
    this.#current = settings;
    this.#fill(settings);
    this.#validate();
    this.#dialog.showModal();
  }

  #build(): void {
    const basic = document.createElement("fieldset");
    const basicLegend = document.createElement("legend");
    basicLegend.textContent = "Basic";
    this.#ceilingNote = paragraph("section-note", "");
    this.#ceilingNote.dataset["testid"] = "ceiling-note";
    basic.append(
      basicLegend,
      this.#fieldRow(FIELDS.find((f) => f.key === "intensity")!),
      this.#ceilingNote,
      this.#detailRow(),
    );
    for (const field of FIELDS.filter((f) => BASIC.includes(f.key) && f.key !== "intensity"))
      basic.append(this.#fieldRow(field));
    this.#body.append(basic);
    const advanced = document.createElement("details");
    advanced.className = "settings-level";
    advanced.dataset["testid"] = "settings-advanced";
    const summary = document.createElement("summary");
    summary.textContent = "Advanced: every research parameter";
    advanced.append(summary);
    for (const section of SECTIONS) {
      const fieldset = document.createElement("fieldset");
      const legend = document.createElement("legend");
      legend.textContent = section.title;
      fieldset.append(legend);
      if (section.note !== undefined) fieldset.append(paragraph("section-note", section.note));
      if (section.id === "simplifier") {
        this.#unitNote = paragraph("section-note", "");
        this.#floorNote = paragraph("section-note", "");
        this.#floorNote.dataset["testid"] = "floor-note";
        fieldset.append(this.#unitNote, this.#floorNote);
      }
      if (section.id === "sleeve") {
        this.#gridNote = paragraph("section-note", "");
        fieldset.append(this.#gridNote);
      }
      if (section.id === "connection") {
        this.#brokerNote = paragraph("section-note", "");
        fieldset.append(this.#brokerNote);
      }
      for (const field of FIELDS.filter((f) => f.section === section.id && !BASIC.includes(f.key)))
        fieldset.append(this.#fieldRow(field));
      advanced.append(fieldset);
    }
    this.#body.append(advanced);
  }

  /** One control for how closely strokes follow the hand; it sets max error and max angle. */
  #detailRow(): HTMLElement {
    const row = document.createElement("div");
    row.className = "field";
    row.dataset["kind"] = "range";
    const label = document.createElement("label");
    label.className = "field-label";
    label.htmlFor = "setting-detail";
    label.textContent = "Detail";
    const input = document.createElement("input");
    input.type = "range";
    input.id = "setting-detail";
    input.min = "1";
    input.max = String(DETAIL_LEVELS);
    input.step = "1";
    input.dataset["testid"] = "setting-detail";
    const value = paragraph("unit", "", "span");
    const control = document.createElement("div");
    control.className = "field-control";
    control.append(input, value);
    const help = paragraph(
      "field-help",
      "Coarse: few long strokes; finest: many short ones that follow the hand closely. " +
        "Sets the max error (window) and max angle (angle) under Advanced.",
      "span",
    );
    // What else cuts strokes, so that a detail that changes little is not a puzzle.
    const limit = paragraph("field-help", "", "span");
    limit.dataset["testid"] = "detail-limit";
    help.append(" ", limit);
    this.#detailLimit = limit;
    input.addEventListener("input", () => {
      for (const [key, number] of Object.entries(detailValues(Number(input.value)))) {
        const target = this.#inputs.get(key as SettingKey)?.[0];
        if (target !== undefined) target.value = String(number);
      }
      this.#validate();
    });
    this.#detail = input;
    this.#detailText = value;
    row.append(label, control, help);
    return row;
  }

  #fieldRow(field: FieldSpec): HTMLElement {
    const row = document.createElement("div");
    row.className = "field";
    row.dataset["kind"] = field.kind;
    row.dataset["field"] = field.key;
    const id = `setting-${field.key}`;
    const label = document.createElement("label");
    label.className = "field-label";
    label.htmlFor = field.kind === "choice" ? `${id}-0` : id;
    label.textContent = field.label;
    const control = document.createElement("div");
    control.className = "field-control";
    const inputs: HTMLInputElement[] = [];
    if (field.kind === "boolean") {
      const wrap = document.createElement("span");
      wrap.className = "switch";
      const input = document.createElement("input");
      input.type = "checkbox";
      input.id = id;
      input.setAttribute("role", "switch");
      const track = document.createElement("span");
      track.className = "track";
      wrap.append(input, track);
      control.append(wrap);
      inputs.push(input);
    } else if (field.kind === "choice") {
      const group = document.createElement("span");
      group.className = "segmented";
      group.setAttribute("role", "radiogroup");
      group.setAttribute("aria-label", field.label);
      (field.choices ?? []).forEach((choice, index) => {
        const option = document.createElement("label");
        const input = document.createElement("input");
        input.type = "radio";
        input.name = id;
        input.id = `${id}-${index}`;
        input.value = choice.value;
        option.append(input, choice.label);
        group.append(option);
        inputs.push(input);
      });
      control.append(group);
    } else {
      const input = document.createElement("input");
      input.id = id;
      input.name = field.key;
      input.type = field.kind === "password" ? "password" : "text";
      input.autocomplete = "off";
      input.spellcheck = false;
      if (field.kind === "integer") input.inputMode = "numeric";
      if (field.kind === "number") input.inputMode = "decimal";
      control.append(input);
      // Every number gets a unit column, empty or not, so the inputs line up.
      if (field.kind === "integer" || field.kind === "number")
        control.append(paragraph("unit", field.unit ?? "", "span"));
      inputs.push(input);
    }
    const help = paragraph("field-help", helpText(field), "span");
    help.id = `${id}-help`;
    const error = paragraph("field-error", "", "span");
    error.id = `${id}-error`;
    error.setAttribute("role", "alert");
    for (const input of inputs) {
      input.dataset["testid"] = `setting-${field.key}`;
      input.setAttribute("aria-describedby", `${help.id} ${error.id}`);
      input.addEventListener("input", () => this.#validate());
      input.addEventListener("change", () => this.#validate());
    }
    row.append(label, control, help, error);
    const note = conditionNote(field);
    if (note !== null) {
      const element = paragraph("field-note", note, "span");
      element.dataset["testid"] = `setting-${field.key}-note`;
      element.hidden = true;
      row.insertBefore(element, help);
      this.#conditionNotes.set(field.key, element);
    }
    this.#inputs.set(field.key, inputs);
    this.#errors.set(field.key, error);
    this.#rows.set(field.key, row);
    return row;
  }

  #fill(settings: Settings): void {
    if (this.#detail !== null) this.#detail.value = String(detailLevel(settings.algorithm, settings));
    for (const field of FIELDS) {
      const inputs = this.#inputs.get(field.key) ?? [];
      const value = settings[field.key];
      for (const input of inputs) {
        if (field.kind === "boolean") input.checked = value === true;
        else if (field.kind === "choice") input.checked = input.value === value;
        else input.value = String(value);
      }
    }
  }

  /** The form's values, typed as the settings expect (numbers stay NaN when unreadable). */
  #read(): Candidate {
    const candidate: Partial<Candidate> = {};
    for (const field of FIELDS) {
      const inputs = this.#inputs.get(field.key) ?? [];
      const first = inputs[0];
      let value: unknown;
      if (field.kind === "boolean") value = first?.checked ?? false;
      else if (field.kind === "choice") value = inputs.find((input) => input.checked)?.value ?? null;
      else if (field.kind === "integer" || field.kind === "number") value = parseNumber(first?.value ?? "");
      else value = first?.value ?? "";
      candidate[field.key] = value;
    }
    return candidate as Candidate;
  }

  #validate(): { candidate: Candidate; valid: boolean } {
    const candidate = this.#read();
    const errors = validateSettings(candidate);
    this.#applyDependencies(candidate);
    if (this.#detailText !== null && this.#detail !== null) {
      const level = Number(this.#detail.value);
      this.#detailText.textContent = `${level} · ${DETAIL_NAMES[level - 1] ?? ""}`;
    }
    if (this.#detailLimit !== null) this.#detailLimit.textContent = detailLimit(candidate);
    let count = 0;
    for (const field of FIELDS) {
      const message = this.#isDisabled(field.key, candidate) ? undefined : errors[field.key];
      const error = this.#errors.get(field.key);
      if (error) error.textContent = message ?? "";
      for (const input of this.#inputs.get(field.key) ?? []) {
        input.setAttribute("aria-invalid", message ? "true" : "false");
      }
      if (message) count++;
    }
    this.#summary.textContent = count === 0 ? "" : `Fix ${count} field${count === 1 ? "" : "s"} to save.`;
    this.#save.disabled = count > 0;
    return { candidate, valid: count === 0 };
  }

  /** Fields that do not apply (grid from the sleeve, the server's broker) are shown but locked. */
  #isDisabled(key: SettingKey, candidate: Candidate): boolean {
    if (key === "rows" || key === "columns") return candidate.grid_source === "status";
    if (key === "ws_url" || key === "username" || key === "password") {
      return this.#context.config !== null && candidate.broker_custom !== true;
    }
    if (key === "legacy_topic") return candidate.protocol !== "legacy";
    // Fields only one simplifier has: locked while the other is chosen.
    const owner = ONLY_FOR[key];
    if (owner !== undefined && candidate.algorithm !== owner) return true;
    // Fields only one core of the simplifier reads: locked while its switch chooses the other.
    return !conditionMet(fieldSpec(key), candidate);
  }

  #applyDependencies(candidate: Candidate): void {
    const keys: readonly SettingKey[] = [
      "rows",
      "columns",
      "ws_url",
      "username",
      "password",
      "legacy_topic",
      ...(Object.keys(ONLY_FOR) as SettingKey[]),
    ];
    for (const key of keys) {
      const disabled = this.#isDisabled(key, candidate);
      this.#rows.get(key)!.dataset["disabled"] = String(disabled);
      for (const input of this.#inputs.get(key) ?? []) input.disabled = disabled;
    }
    // Its note only when the switch is why (not when the other simplifier is chosen).
    for (const [key, note] of this.#conditionNotes) {
      const owner = ONLY_FOR[key];
      note.hidden =
        (owner !== undefined && candidate.algorithm !== owner) || conditionMet(fieldSpec(key), candidate);
    }
    const { config, sleeveGrid, spacingCm, floor, ceiling } = this.#context;
    if (this.#ceilingNote) {
      const intensity = candidate.intensity;
      const note = typeof intensity === "number" ? ceilingNote(ceiling ?? null, intensity) : null;
      this.#ceilingNote.textContent = note ?? "";
      this.#ceilingNote.hidden = note === null;
    }
    if (this.#floorNote) {
      const note = floorNote(candidateMinimums(candidate), floor);
      this.#floorNote.textContent = note ?? "";
      this.#floorNote.hidden = note === null;
    }
    if (this.#unitNote) {
      this.#unitNote.textContent =
        "Lengths are in grid units: 1 grid unit is the spacing between two neighbouring actuators" +
        (spacingCm != null ? ` (${spacingCm} cm on this sleeve).` : " (the sleeve's layout gives it in cm).");
    }
    const customRow = this.#rows.get("broker_custom");
    if (customRow) customRow.hidden = config === null;
    if (this.#brokerNote) {
      this.#brokerNote.textContent =
        config === null
          ? "This page was not given a broker by its server (no /config.json, e.g. under 'vite dev'): enter one here."
          : candidate.broker_custom === true
            ? "Using the broker below instead of the server's."
            : `Using the server's broker, ${config.ws_url}, as ${config.username}.`;
    }
    if (this.#gridNote) {
      this.#gridNote.textContent =
        sleeveGrid === null
          ? "The sleeve has not reported its grid yet; until it does, rows and columns below are used."
          : `The sleeve reports ${sleeveGrid.rows} rows × ${sleeveGrid.columns} columns.`;
    }
  }

  #submit(): void {
    const { candidate, valid } = this.#validate();
    if (!valid) return;
    // A locked field may hold a value left half typed; it keeps its last valid value instead.
    const errors = validateSettings(candidate);
    const saved: Record<string, unknown> = { ...this.#current };
    for (const field of FIELDS) {
      if (errors[field.key] === undefined) saved[field.key] = candidate[field.key];
    }
    this.#onSave(saved as unknown as Settings);
    this.#dialog.close();
  }
}

/** The minimums being edited, as numbers (a half-typed value counts as 0: the floor applies). */
function candidateMinimums(candidate: Candidate): Minimums {
  const number = (value: unknown): number =>
    typeof value === "number" && Number.isFinite(value) ? value : 0;
  return { min_duration_ms: number(candidate.min_duration_ms), min_length: number(candidate.min_length) };
}

function helpText(field: FieldSpec): string {
  if (field.minimum !== undefined && field.maximum !== undefined) {
    const unit = field.unit !== undefined && field.unit !== "°" ? ` ${field.unit}` : (field.unit ?? "");
    return `${capitalize(field.help)} · ${field.minimum} to ${field.maximum}${unit}`;
  }
  return capitalize(field.help);
}

/** What limits the Detail setting besides itself: the window simplifier's longest-stroke cap. */
export function detailLimit(candidate: { algorithm?: unknown; max_stroke_ms?: unknown }): string {
  const capMs = candidate.max_stroke_ms;
  if (candidate.algorithm !== "window" || typeof capMs !== "number" || !(capMs > 0)) return "";
  return (
    `The longest stroke (${capMs} ms of drawing, under Advanced) cuts too: at any detail a stroke ` +
    "lasts longer only between two samples drawn further apart, so for a drawing slower " +
    "than that, coarse sends about as many strokes as fine. " +
    "Set it to 0 for the fewest, longest strokes."
  );
}

function capitalize(text: string): string {
  return text.charAt(0).toUpperCase() + text.slice(1);
}

/** A decimal number as typed (a decimal comma too); "", 0x10 and anything else give NaN, which the field reports. */
function parseNumber(text: string): number {
  const trimmed = text.trim().replace(",", ".");
  return DECIMAL.test(trimmed) ? Number(trimmed) : Number.NaN;
}

function paragraph(className: string, text: string, tag: "p" | "span" = "p"): HTMLElement {
  const element = document.createElement(tag);
  element.className = className;
  element.textContent = text;
  return element;
}
