/**
 * The drawing client, put together: pointer samples -> animation frames ->
 * the chosen simplifier -> strokes -> MQTT, and the sleeve's telemetry back to
 * the status bar, the canvas, the preview and the felt timeline. The
 * algorithms live in pure modules; this class only wires them to the page.
 */
import { CANCEL_ALL } from "./control";
import type { ServerConfig } from "./config";
import { Drawing } from "./drawing";
import { newDrawingId } from "./drawing-id";
import { parseEvent, parseStatus, type SleeveEvent, type SleeveStatus } from "./events";
import { StrokeSender, type BrokerState, type SenderTarget } from "./mqtt/sender";
import { buildRecording, recordingFileName } from "./recording";
import { drawingFromRecording, parseRecording } from "./recording-load";
import {
  LATE_LIMIT_MS,
  loadSettings,
  saveSettings,
  SIMPLIFIER_PARAM_KEYS,
  simplifierParams,
  withServerBroker,
  type SettingKey,
  type Settings,
} from "./settings";
import { simplifyPaths } from "./simplify/registry";
import { parseActuators } from "./telemetry";
import { DrawingView } from "./ui/canvas";
import { detailParams } from "./ui/detail";
import { DrawingSession } from "./ui/drawing-session";
import { FeltPanel, type Arrival } from "./ui/felt-panel";
import type { GridSize } from "./ui/geometry";
import { attachPointer } from "./ui/pointer";
import { SleevePreview } from "./ui/preview";
import { SettingsPanel } from "./ui/settings";
import { SleevePicker } from "./ui/sleeve-picker";
import { LATE_MS, NOTABLE_ADJUSTMENT, SleeveSays, seconds } from "./ui/sleeve-says";
import { byId, StatusBar, type SleeveState } from "./ui/status";
import { TimelineView } from "./ui/timeline";

/** Settings that change how a drawing is cut or mapped: changing one re-simplifies it. */
const DRAWING_KEYS: readonly SettingKey[] = ["algorithm", ...SIMPLIFIER_PARAM_KEYS];
/** Settings that change the grid: a drawing mapped onto another grid cannot be shown on this one. */
const GRID_KEYS: readonly SettingKey[] = ["grid_source", "rows", "columns"];
/** Settings that change where and how strokes are published: changing one reconnects. */
const TARGET_KEYS: readonly SettingKey[] = [
  "ws_url",
  "username",
  "password",
  "sleeve_id",
  "protocol",
  "legacy_topic",
];
/** The media query of styles.css under which the sleeve's cards go below the drawing area. */
const STACKED_LAYOUT = "(max-width: 820px), (max-height: 560px)";
/** The one of styles.css for a phone on its side: the toolbar beside the area, the legend below it all. */
const SHORT_LANDSCAPE = "(max-height: 560px) and (orientation: landscape)";
/** Stacked, below the area: the gap to the legend and the workspace's padding (styles.css). */
const STACKED_BELOW_PX = 10 + 12;
/** Stacked, the area is never squeezed below this height: the page scrolls instead. */
const STACKED_MIN_HEIGHT_PX = 240;
/** A sleeve that listens has its retained status at the broker: none after this, none listens. */
const STATUS_WAIT_MS = 2500;

export interface AppOptions {
  readonly config: ServerConfig | null;
  readonly configNote: string | null;
  readonly storage: Storage;
}

export class App {
  readonly #doc: Document;
  readonly #config: ServerConfig | null;
  readonly #storage: Storage;
  readonly #view: DrawingView;
  readonly #preview: SleevePreview;
  readonly #status: StatusBar;
  readonly #says: SleeveSays;
  readonly #panel: SettingsPanel;
  readonly #picker: SleevePicker;
  readonly #sender: StrokeSender;
  readonly #felt: FeltPanel;
  readonly #session: DrawingSession;
  readonly #buttons: Record<"undo" | "replay" | "record", HTMLButtonElement>;
  readonly #hint: HTMLElement;
  readonly #stageArea: HTMLElement;
  readonly #legend: HTMLElement;
  readonly #legendTurned: HTMLElement;
  readonly #compareToggle: HTMLInputElement;
  readonly #compareDetail: HTMLInputElement;
  #settings: Settings;
  #sleeve: SleeveStatus | null = null;
  #sleeveState: SleeveState = "unknown";
  #brokerState: BrokerState = "connecting";
  #statusTimer: ReturnType<typeof setTimeout> | null = null;
  #refitPending = false;
  #arrival: Arrival = "as-drawn";
  #notices: { broker: string | null; config: string | null; sleeve: string | null; page: string | null } = {
    broker: null,
    config: null,
    sleeve: null,
    page: null,
  };

  constructor(doc: Document, options: AppOptions) {
    this.#doc = doc;
    this.#config = options.config;
    this.#storage = options.storage;
    const loaded = loadSettings(options.storage, options.config);
    this.#settings = loaded.settings;
    this.#status = new StatusBar(doc);
    this.#says = new SleeveSays(
      byId(doc, "log-title"),
      byId<HTMLOListElement>(doc, "event-log"),
      byId(doc, "played-summary"),
    );
    this.#view = new DrawingView(byId(doc, "stage"));
    this.#preview = new SleevePreview(byId<HTMLCanvasElement>(doc, "preview"), byId(doc, "preview-caption"));
    const timeline = new TimelineView(
      byId<HTMLCanvasElement>(doc, "timeline"),
      byId<HTMLCanvasElement>(doc, "timeline-cursor"),
      byId(doc, "timeline-caption"),
    );
    this.#felt = new FeltPanel(timeline, this.#view);
    this.#panel = new SettingsPanel(doc, (settings) => this.#applySettings(settings));
    this.#picker = new SleevePicker(
      byId<HTMLSelectElement>(doc, "sleeve-select"),
      this.#settings.sleeve_id,
      (sleeve_id) => this.#applySettings({ ...this.#settings, sleeve_id }),
    );
    this.#picker.setKnown(options.config?.sleeves ?? []);
    this.#buttons = {
      undo: byId<HTMLButtonElement>(doc, "undo-button"),
      replay: byId<HTMLButtonElement>(doc, "replay-button"),
      record: byId<HTMLButtonElement>(doc, "record-button"),
    };
    this.#hint = byId(doc, "stage-hint");
    this.#stageArea = byId(doc, "stage-area");
    this.#legend = byId(doc, "legend");
    this.#legendTurned = byId(doc, "legend-turned");
    this.#compareToggle = byId<HTMLInputElement>(doc, "compare-toggle");
    this.#compareDetail = byId<HTMLInputElement>(doc, "compare-detail");
    this.#session = new DrawingSession(this.#view, {
      settings: () => this.#settings,
      grid: () => this.#grid(),
      send: (stroke) => this.#sender.send(stroke),
      changed: (drawing) => this.#drawingChanged(drawing),
      released: () => {
        if (this.#refitPending) this.#fit();
      },
    });
    this.#sender = new StrokeSender({
      broker: (state, detail) => this.#onBroker(state, detail),
      status: (payload) => this.#onStatus(payload),
      sleeveStatus: (sleeveId, payload) => this.#picker.setStatus(sleeveId, payload),
      actuators: (payload) => this.#onActuators(payload),
      event: (payload) => this.#onEvent(payload),
      unsent: (count) => this.#status.setUnsent(count),
      acked: (stroke) => this.#session.acked(stroke),
      refused: (_stroke, error) => this.#says.add("error", `A stroke was not sent: ${error.message}`),
      late: (strokes) => {
        this.#says.addDropped(strokes.length);
        this.#says.add(
          "info",
          `${strokes.length} stroke(s) dropped: not sent within ${LATE_LIMIT_MS / 1000} s.`,
        );
      },
    });
    this.#sender.setLateLimit(this.#settings.late_strokes === "drop" ? LATE_LIMIT_MS : null);

    this.#notices.config = options.configNote;
    if (loaded.replaced.length > 0) {
      this.#says.add("info", `Saved settings no longer valid were reset: ${loaded.replaced.join(", ")}.`);
    }
    this.#showNotice();
    this.#setSleeve("unknown");
    this.#status.setUnsent(0);

    attachPointer(this.#view, {
      press: (sample, kind) => this.#session.press(sample, kind),
      move: (samples) => this.#session.move(samples),
      release: (sample) => this.#session.release(sample),
    });
    this.#wireButtons();
    const resized = new ResizeObserver(() => this.#fit());
    resized.observe(this.#stageArea);
    resized.observe(byId(this.#doc, "stage-wrap")); // the area's height follows its content
    window.addEventListener("resize", () => this.#fit());
    this.#fit();
    this.#drawingChanged(null);
    this.#sender.connect(this.#target());
  }

  #wireButtons(): void {
    const doc = this.#doc;
    byId(doc, "new-button").addEventListener("click", () => this.#session.clear());
    this.#buttons.undo.addEventListener("click", () => this.#session.undo());
    byId(doc, "stop-button").addEventListener("click", () => this.stop());
    this.#buttons.replay.addEventListener("click", () => this.playAgain());
    this.#buttons.record.addEventListener("click", () => this.#download());
    const file = byId<HTMLInputElement>(doc, "load-file");
    byId(doc, "load-button").addEventListener("click", () => file.click());
    file.addEventListener("change", () => {
      const chosen = file.files?.[0];
      if (chosen !== undefined) void chosen.text().then((text) => this.load(text, chosen.name));
      file.value = "";
    });
    byId(doc, "settings-button").addEventListener("click", () =>
      this.#panel.open(this.#settings, {
        config: this.#config,
        sleeveGrid: this.#sleeve?.layout ?? null,
        spacingCm: this.#sleeve?.layout?.spacing_cm ?? null,
      }),
    );
    doc.addEventListener("keydown", (event) => {
      // Esc closes the settings sheet when it is open; otherwise it stops the sleeve.
      if (event.key === "Escape" && !this.#panel.isOpen) this.stop();
    });
    this.#compareToggle.addEventListener("change", () => this.#compare());
    this.#compareDetail.addEventListener("input", () => this.#compare());
  }

  // ---- the drawing ---------------------------------------------------------------------------

  /** Keeps the buttons, the hint, the card and the timeline in step with the drawing. */
  #drawingChanged(drawing: Drawing | null): void {
    this.#says.reset(drawing?.id ?? null);
    this.#says.setSent(drawing?.strokeCount ?? 0);
    this.#hint.hidden = drawing !== null;
    const hasPaths = drawing !== null && drawing.paths.length > 0;
    this.#buttons.undo.disabled = !hasPaths;
    this.#buttons.record.disabled = !hasPaths;
    this.#buttons.replay.disabled = drawing === null || drawing.keptStrokeCount === 0;
    if (drawing === null || drawing.id !== this.#feltDrawing) {
      this.#feltDrawing = drawing?.id ?? null;
      this.#felt.setDrawing(drawing, this.#grid(), this.#arrival);
      this.#arrival = "as-drawn";
      this.#compare();
    } else {
      this.#felt.refresh();
      if (this.#compareToggle.checked && !this.#session.pressed) this.#compare();
    }
  }

  #feltDrawing: string | null = null;

  /** Stop: every motor off on the sleeve, the rest of this drawing dropped (also Esc). */
  stop(): void {
    const drawing = this.#session.drawing;
    let dropped = 0;
    if (drawing !== null) dropped += this.#sender.cancel(drawing.id);
    dropped += this.#sender.cancel(CANCEL_ALL);
    this.#felt.stopCursor();
    this.#session.close();
    if (dropped > 0) this.#says.addDropped(dropped);
    this.#says.add("info", `Stop sent${dropped > 0 ? `; ${dropped} unsent stroke(s) dropped` : ""}.`);
  }

  /** Sends the current drawing's strokes again, as a new drawing (the sleeve plays them back to back). */
  playAgain(): void {
    const drawing = this.#session.drawing;
    if (drawing === null || drawing.strokes.length === 0) return;
    const copy = drawing.copyAs(newDrawingId());
    this.#arrival = "at-once";
    this.#session.adopt(copy);
    for (const stroke of copy.strokes) this.#sender.send(stroke);
    this.#says.setSent(copy.strokeCount);
  }

  /** A saved recording back on the canvas: what would be felt, ready for Play again. */
  load(text: string, name: string): boolean {
    const recording = parseRecording(text);
    if (typeof recording === "string") {
      this.#says.add("error", `${name}: ${recording}`);
      return false;
    }
    const grid = this.#grid();
    if (recording.sleeve.rows !== grid.rows || recording.sleeve.columns !== grid.columns) {
      this.#says.add(
        "error",
        `${name} was drawn for a ${recording.sleeve.rows} × ${recording.sleeve.columns} sleeve; this one is ` +
          `${grid.rows} × ${grid.columns}. Set the grid in Settings → Sleeve to load it.`,
      );
      return false;
    }
    const drawing = drawingFromRecording(recording, newDrawingId(), this.#settings.intensity);
    this.#session.adopt(drawing);
    this.#says.add(
      "info",
      `Loaded ${name}: ${drawing.strokes.length} strokes, not sent. Play again sends them.`,
    );
    return true;
  }

  #download(): void {
    const drawing = this.#session.drawing;
    if (drawing === null) return;
    const now = new Date();
    const blob = new Blob([JSON.stringify(buildRecording(drawing, now), null, 1)], {
      type: "application/json",
    });
    const link = this.#doc.createElement("a");
    link.href = URL.createObjectURL(blob);
    link.download = recordingFileName(now);
    link.click();
    // The download has started once click() returns; the URL can go after this task.
    setTimeout(() => URL.revokeObjectURL(link.href), 0);
  }

  /** A/B: the same paths under the B detail (same simplifier), overlaid on canvas and timeline. */
  #compare(): void {
    const drawing = this.#session.drawing;
    const on = this.#compareToggle.checked;
    byId(this.#doc, "compare-controls").hidden = !on;
    byId(this.#doc, "legend-b").hidden = !on;
    const level = Number(this.#compareDetail.value);
    byId(this.#doc, "compare-detail-value").textContent = String(level);
    if (!on || drawing === null) {
      this.#felt.compare(null);
      return;
    }
    const params = detailParams(drawing.params, level);
    const count = this.#felt.compare(params);
    byId(this.#doc, "compare-note").textContent =
      `A (solid): ${drawing.strokes.length} strokes as drawn. B (dashed): ${count} strokes at detail ${level} of 5.`;
  }

  // ---- layout ------------------------------------------------------------------------------

  #grid(): GridSize {
    const layout = this.#sleeve?.layout;
    if (this.#settings.grid_source === "status" && layout)
      return { rows: layout.rows, columns: layout.columns };
    return { rows: this.#settings.rows, columns: this.#settings.columns };
  }

  #fit(): void {
    if (this.#session.pressed) {
      // Never reshape the canvas under a finger: after the release.
      this.#refitPending = true;
      return;
    }
    this.#refitPending = false;
    const grid = this.#grid();
    const params = this.#session.drawing?.params;
    if (params && (params.rows !== grid.rows || params.columns !== grid.columns)) {
      // The strokes drawn were mapped onto another grid: showing them on this one would lie.
      this.#session.clear();
    }
    const width = this.#stageArea.clientWidth;
    // The area takes its content's height, the legend right under it: the viewport (stacked,
    // phone) or the column (desktop) sets the limit.
    const stacked = window.matchMedia(STACKED_LAYOUT).matches;
    const height = stacked ? this.#firstScreenHeight() : this.#columnHeight();
    this.#view.fit(grid, this.#settings.stretch, width, height);
    this.#legendTurned.hidden = !this.#view.turned;
    this.#preview.setGrid(grid, this.#view.turned);
  }

  /** Stacked, the area fills the first screen: from its top to the window's bottom, the legend under it. */
  #firstScreenHeight(): number {
    const workspace = this.#stageArea.closest(".workspace");
    const top = this.#stageArea.getBoundingClientRect().top + (workspace?.scrollTop ?? 0) + window.scrollY;
    // A phone on its side keeps every pixel of height for drawing: the legend follows below the fold.
    const legend = window.matchMedia(SHORT_LANDSCAPE).matches ? 0 : this.#legendHeightTurned();
    return Math.max(STACKED_MIN_HEIGHT_PX, window.innerHeight - top - legend - STACKED_BELOW_PX);
  }

  /** Desktop, the area fills its column but for the legend, which follows it with no gap to fill. */
  #columnHeight(): number {
    const column = this.#stageArea.parentElement;
    if (!column) return this.#stageArea.clientHeight;
    const gap = parseFloat(getComputedStyle(column).rowGap) || 0;
    const bottom = column.getBoundingClientRect().bottom;
    const top = this.#stageArea.getBoundingClientRect().top;
    return Math.max(0, bottom - top - gap - this.#legendHeightTurned());
  }

  /**
   * The legend's height with its "turned" line shown, whether it is or not: the height left for
   * the area must not depend on the turn it decides, or a small phone would flip between the two.
   */
  #legendHeightTurned(): number {
    const line = this.#legendTurned;
    if (!line.hidden) return this.#legend.offsetHeight;
    line.hidden = false;
    const height = this.#legend.offsetHeight;
    line.hidden = true;
    return height;
  }

  // ---- settings ----------------------------------------------------------------------------

  #applySettings(next: Settings): void {
    const previous = this.#settings;
    this.#settings = withServerBroker(next, this.#config);
    saveSettings(this.#storage, next, this.#config);
    this.#sender.setLateLimit(this.#settings.late_strokes === "drop" ? LATE_LIMIT_MS : null);
    const changed = (keys: readonly SettingKey[]) =>
      keys.some((key) => previous[key] !== this.#settings[key]);
    if (changed(GRID_KEYS)) {
      this.#session.clear();
      this.#fit();
    } else if (changed(DRAWING_KEYS)) {
      this.#resimplify();
      this.#fit();
    }
    if (changed(TARGET_KEYS)) {
      const sleeveChanged = previous.sleeve_id !== this.#settings.sleeve_id;
      if (sleeveChanged) {
        // Its strokes went to the other sleeve: the next path starts a new drawing for this one.
        this.#session.close();
        this.#picker.setCurrent(this.#settings.sleeve_id);
        this.#says.add(
          "info",
          `Now drawing on sleeve ${this.#settings.sleeve_id}; the next path starts a new drawing.`,
        );
        this.#sleeve = null;
        this.#setSleeve("unknown");
        this.#fit();
      }
      // Another sleeve on the same broker keeps the connection; its status, if known, comes at once.
      this.#sender.connect(this.#target());
      if (sleeveChanged && this.#brokerState === "connected") this.#waitForStatus();
    }
  }

  /** The drawing on the canvas cut again under the new settings, at once (not sent: Play again). */
  #resimplify(): void {
    const drawing = this.#session.drawing;
    if (drawing === null || drawing.paths.length === 0) return;
    const params = simplifierParams(this.#settings, this.#grid(), {
      width_px: drawing.params.canvas_width_px,
      height_px: drawing.params.canvas_height_px,
    });
    const again = new Drawing(newDrawingId(), params);
    const pieces = simplifyPaths(params, drawing.paths);
    drawing.paths.forEach((samples, path) => {
      again.beginPath(drawing.pointerKinds[path] ?? "mouse");
      again.paths[path]!.push(...samples);
      for (const piece of pieces) {
        if (piece.path === path) again.addSegment(piece.segment, this.#settings.intensity);
      }
    });
    this.#session.adopt(again);
    this.#says.add(
      "info",
      `Re-simplified with the new settings: ${again.strokes.length} strokes, not sent. Play again sends them.`,
    );
  }

  #target(): SenderTarget {
    const { ws_url, username, password, sleeve_id, protocol, legacy_topic } = this.#settings;
    return { ws_url, username, password, sleeve_id, protocol, legacy_topic };
  }

  // ---- broker and sleeve -------------------------------------------------------------------

  #onBroker(state: BrokerState, detail: string | null): void {
    const wasOffline = this.#brokerState === "offline" || this.#notices.broker !== null;
    this.#brokerState = state;
    this.#status.setBroker(state, detail);
    if (state === "connected") {
      this.#notices.broker = null;
      this.#waitForStatus();
    } else if (state === "offline") {
      this.#notices.broker = this.#offlineAdvice(detail);
    } else if (!wasOffline) {
      this.#notices.broker = null;
    }
    // A reconnection attempt ("connecting") keeps the offline notice: it is not back yet.
    this.#showNotice();
    if (state !== "connected") {
      if (this.#statusTimer !== null) clearTimeout(this.#statusTimer);
      // Without the broker nothing is known about the sleeve any more.
      this.#setSleeve("unknown", "Not known while the broker is not connected.");
      this.#picker.forget();
    }
  }

  /** What to do about a lost broker, for the way this page was started. */
  #offlineAdvice(detail: string | null): string {
    if (detail !== null && detail.includes("refused the login")) return detail;
    const where = this.#settings.ws_url;
    if (this.#config !== null && !this.#settings.broker_custom) {
      return (
        `No connection to ${where}; retrying every 2 s. The broker runs inside 'feelmysign up' ` +
        "(make up): its terminal says whether it is restarting; if that stopped, start it again."
      );
    }
    return `No connection to ${where}; retrying every 2 s. Start a broker with 'make up', or set yours in Settings → Connection.`;
  }

  #waitForStatus(): void {
    if (this.#statusTimer !== null) clearTimeout(this.#statusTimer);
    this.#statusTimer = setTimeout(() => {
      this.#statusTimer = null;
      if (this.#sleeveState === "unknown" && this.#brokerState === "connected") this.#setSleeve("absent");
    }, STATUS_WAIT_MS);
  }

  /** The chip, the preview's caption and the notice say the same thing about the sleeve. */
  #setSleeve(state: SleeveState, detail: string | null = null): void {
    this.#sleeveState = state;
    const id = this.#settings.sleeve_id;
    this.#status.setSleeve(state, id, detail, this.#brokerState === "connected");
    const layout = this.#sleeve?.layout;
    const caption = {
      online: `Sleeve ${id} online${layout ? `: ${layout.rows} × ${layout.columns} actuators` : ""}, waiting for strokes.`,
      offline: `Sleeve ${id} is offline: nothing is felt now.`,
      absent: `No sleeve answers on id ${id}: nothing is felt.`,
      unknown:
        this.#brokerState === "connected"
          ? `Waiting for sleeve ${id} to report…`
          : `Not connected to the broker: the sleeve cannot be seen.`,
    }[state];
    this.#preview.reset(caption, state === "online");
    this.#notices.sleeve =
      state === "absent"
        ? `No sleeve listens on id '${id}': nothing has ever reported there, so strokes sent now are not felt. ` +
          "Check the sleeve id in Settings → Sleeve (a sleeve prints its id when it starts)."
        : state === "offline"
          ? `Sleeve '${id}' is offline: strokes wait at the broker and play when it is back.`
          : null;
    this.#showNotice();
  }

  #showNotice(): void {
    const { broker, config, sleeve, page } = this.#notices;
    // The missing config explains the broker problem that usually follows it: both, config first.
    if (broker !== null) this.#status.setNotice(config === null ? broker : `${config} ${broker}`, "error");
    else if (sleeve !== null) this.#status.setNotice(sleeve, "warn");
    else this.#status.setNotice(config ?? page, "info");
  }

  #onStatus(payload: string): void {
    if (payload.trim() === "") {
      this.#sleeve = null;
      this.#setSleeve("absent");
      return;
    }
    const status = parseStatus(payload);
    if (status === null) {
      this.#setSleeve(
        "unknown",
        'The sleeve\'s status message is not understood (expected JSON with "online").',
      );
      return;
    }
    const wasOnline = this.#sleeveState === "online";
    this.#sleeve = status;
    this.#setSleeve(
      status.online ? "online" : "offline",
      status.online
        ? `Online${status.layout ? `, ${status.layout.rows} × ${status.layout.columns} actuators` : ""}${status.version ? `, version ${status.version}` : ""}`
        : "Offline: strokes sent now reach the sleeve when it is back (if its session is kept).",
    );
    if (status.online && !wasOnline && this.#says.counts.played + this.#says.counts.refused > 0) {
      this.#says.add("info", `Sleeve ${this.#settings.sleeve_id} is back.`);
    }
    this.#fit();
  }

  #onActuators(payload: string): void {
    const frame = parseActuators(payload);
    if (frame !== null) this.#preview.show(frame);
  }

  #onEvent(payload: string): void {
    const event = parseEvent(payload);
    if (event === null) return;
    const drawing = this.#session.drawing;
    const ref = "seq" in event ? event : null;
    const ours = drawing !== null && ref !== null && ref.drawing === drawing.id && ref.seq !== null;
    const drawn = ours ? drawing.bySeq(ref.seq!) : undefined;
    const label = ref === null || ref.seq === null ? "A stroke" : `Stroke ${ref.seq}`;
    switch (event.type) {
      case "played":
      case "adjusted": {
        if (!ours) return;
        this.#says.count("played");
        this.#felt.played(event);
        // Late: sent -> felt, less the wait behind the strokes before it (playing back to back is
        // the design, not lateness). What remains is the network, the broker holding it, the sleeve.
        const late =
          event.sent_at_ms === null ? 0 : event.first_command_at_ms - event.sent_at_ms - event.queued_ms;
        if (late > LATE_MS) {
          this.#says.count("late", late);
          this.#says.add(
            "adjusted",
            `${label} played ${seconds(late)} late (it waited at the broker or on the way).`,
          );
        }
        if (event.type === "adjusted") {
          const change =
            Math.abs(event.duration_ms - event.requested_duration_ms) / event.requested_duration_ms;
          // "Played in 418 ms instead of 417 ms" is noise: only changes a person could feel.
          if (change >= NOTABLE_ADJUSTMENT) {
            this.#says.add(
              "adjusted",
              `${label} played in ${Math.round(event.duration_ms)} ms instead of ${Math.round(event.requested_duration_ms)} ms (${event.reason.replaceAll("_", " ")}).`,
            );
          }
        }
        return;
      }
      case "rejected":
        if (ours) {
          this.#says.count("refused");
          if (drawn) this.#session.rejected(drawn);
        }
        if (ours || ref?.drawing == null) this.#says.add("rejected", `${label} refused: ${describe(event)}`);
        return;
      case "cancelled":
        if (!ours) return;
        this.#says.count("cancelled");
        if (event.started) this.#says.count("cut");
        this.#felt.cancelled(event);
        this.#says.add(
          "info",
          `${label} cancelled${event.started ? " while playing" : " before it played"}.`,
        );
        return;
      case "safety":
        this.#says.add(
          "error",
          `Safety: actuator (${event.row}, ${event.column}) switched off: ${describe(event)}`,
        );
        return;
      case "error":
        this.#says.add("error", `The sleeve reports an error: ${describe(event)}`);
        return;
    }
  }

  // ---- for the benchmark and the browser tests ---------------------------------------------

  /** Work done in each recent animation frame, in ms. */
  frameWorkMs(): number[] {
    return this.#session.frameWorkMs();
  }

  resetFrameStats(): void {
    this.#session.resetFrameStats();
  }

  /** Draws `strokes` synthetic strokes into the current drawing; returns its stroke count. */
  drawSynthetic(strokes: number): number {
    return this.#session.drawSynthetic(strokes);
  }

  /** The current drawing's id, or null. */
  get drawingId(): string | null {
    return this.#session.drawing?.id ?? null;
  }
}

function describe(event: SleeveEvent): string {
  const message = "message" in event ? event.message : null;
  return message ?? ("reason" in event ? event.reason.replaceAll("_", " ") : "no reason given");
}
