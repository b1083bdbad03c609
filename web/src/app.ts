/**
 * The drawing client, put together: pointer samples -> animation frames ->
 * the chosen simplifier -> strokes -> MQTT, and the sleeve's telemetry back to
 * the status bar, the canvas and the preview. The algorithms live in pure
 * modules; this class only wires them to the page.
 */
import type { ServerConfig } from "./config";
import type { Drawing } from "./drawing";
import { StrokeSender, type BrokerState, type SenderTarget } from "./mqtt/sender";
import { buildRecording, recordingFileName } from "./recording";
import { loadSettings, saveSettings, withServerBroker, type SettingKey, type Settings } from "./settings";
import { parseEvent, parseStatus, type AdjustedEvent, type SleeveEvent, type SleeveStatus } from "./events";
import { parseActuators } from "./telemetry";
import { DrawingView } from "./ui/canvas";
import { DrawingSession } from "./ui/drawing-session";
import { EventLog } from "./ui/event-log";
import type { GridSize } from "./ui/geometry";
import { attachPointer } from "./ui/pointer";
import { SleevePreview } from "./ui/preview";
import { SettingsPanel } from "./ui/settings";
import { byId, StatusBar } from "./ui/status";

/** Settings that change how a drawing is cut or mapped: changing one starts a new drawing. */
const DRAWING_KEYS: readonly SettingKey[] = [
  "algorithm",
  "max_error",
  "max_window",
  "check_frames",
  "max_angle_deg",
  "frame_max",
  "fps",
  "recover",
  "min_duration_ms",
  "min_length",
  "stretch",
  "grid_source",
  "rows",
  "columns",
];
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
const STACKED_LAYOUT = "(max-width: 820px)";
/** In that layout the drawing area takes at most this share of the window's height. */
const STACKED_STAGE_SHARE = 0.55;

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
  readonly #log: EventLog;
  readonly #panel: SettingsPanel;
  readonly #sender: StrokeSender;
  readonly #recordButton: HTMLButtonElement;
  readonly #hint: HTMLElement;
  readonly #stageWrap: HTMLElement;
  readonly #legend: HTMLElement;
  #settings: Settings;
  #sleeve: SleeveStatus | null = null;
  readonly #session: DrawingSession;
  /** The drawing the played/refused counts belong to. */
  #countedDrawing: string | null = null;
  #refitPending = false;
  #played = 0;
  #refused = 0;
  #notices: { broker: string | null; config: string | null } = { broker: null, config: null };

  constructor(doc: Document, options: AppOptions) {
    this.#doc = doc;
    this.#config = options.config;
    this.#storage = options.storage;
    const loaded = loadSettings(options.storage, options.config);
    this.#settings = loaded.settings;
    this.#status = new StatusBar(doc);
    this.#log = new EventLog(byId<HTMLOListElement>(doc, "event-log"), byId(doc, "played-summary"));
    this.#view = new DrawingView(byId(doc, "stage"));
    this.#preview = new SleevePreview(byId<HTMLCanvasElement>(doc, "preview"), byId(doc, "preview-caption"));
    this.#panel = new SettingsPanel(doc, (settings) => this.#applySettings(settings));
    this.#recordButton = byId<HTMLButtonElement>(doc, "record-button");
    this.#hint = byId(doc, "stage-hint");
    this.#stageWrap = byId(doc, "stage-wrap");
    this.#legend = doc.querySelector<HTMLElement>(".legend") ?? this.#hint;
    this.#session = new DrawingSession(this.#view, {
      settings: () => this.#settings,
      grid: () => this.#grid(),
      send: (stroke) => this.#sender.send(stroke),
      changed: (drawing) => this.#drawingChanged(drawing),
      released: () => {
        this.#recordButton.disabled = false;
        if (this.#refitPending) this.#fit();
      },
    });
    this.#sender = new StrokeSender({
      broker: (state, detail) => this.#onBroker(state, detail),
      status: (payload) => this.#onStatus(payload),
      actuators: (payload) => this.#onActuators(payload),
      event: (payload) => this.#onEvent(payload),
      unsent: (count) => this.#status.setUnsent(count),
      acked: (stroke) => this.#session.acked(stroke),
      refused: (_stroke, error) => this.#log.add("error", `A stroke was not sent: ${error.message}`),
    });

    this.#notices.config = options.configNote;
    if (loaded.replaced.length > 0) {
      this.#log.add("info", `Saved settings no longer valid were reset: ${loaded.replaced.join(", ")}.`);
    }
    this.#showNotice();
    this.#status.setSleeve("unknown", this.#settings.sleeve_id);
    this.#status.setUnsent(0);

    attachPointer(this.#view, {
      press: (sample, kind) => this.#session.press(sample, kind),
      move: (samples) => this.#session.move(samples),
      release: (sample) => this.#session.release(sample),
    });
    byId(doc, "clear-button").addEventListener("click", () => this.#session.clear());
    this.#recordButton.addEventListener("click", () => this.#download());
    byId(doc, "settings-button").addEventListener("click", () =>
      this.#panel.open(this.#settings, { config: this.#config, sleeveGrid: this.#sleeve?.layout ?? null }),
    );
    new ResizeObserver(() => this.#fit()).observe(this.#stageWrap);
    window.addEventListener("resize", () => this.#fit());
    this.#fit();
    this.#sender.connect(this.#target());
  }

  /** Keeps the hint, the record button and the counts in step with the drawing. */
  #drawingChanged(drawing: Drawing | null): void {
    if (drawing?.id !== this.#countedDrawing) {
      this.#countedDrawing = drawing?.id ?? null;
      this.#played = 0;
      this.#refused = 0;
    }
    this.#hint.hidden = drawing !== null;
    if (drawing === null) this.#recordButton.disabled = true;
    this.#summarize();
  }

  #summarize(): void {
    this.#log.summarize(this.#session.drawing?.strokeCount ?? 0, this.#played, this.#refused);
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
    if (
      params &&
      (params.rows !== grid.rows ||
        params.columns !== grid.columns ||
        params.stretch !== this.#settings.stretch)
    ) {
      // The strokes drawn were mapped onto another grid: showing them on this one would lie.
      this.#session.clear();
    }
    const legendGapPx = 10;
    const width = this.#stageWrap.clientWidth;
    // Stacked (narrow) layout: the wrap takes its content's height, so the viewport sets the limit.
    const stacked = window.matchMedia(STACKED_LAYOUT).matches;
    const height = stacked
      ? window.innerHeight * STACKED_STAGE_SHARE
      : this.#stageWrap.clientHeight - this.#legend.offsetHeight - legendGapPx;
    this.#view.fit(grid, this.#settings.stretch, width, height);
    this.#preview.setGrid(grid);
  }

  // ---- settings ----------------------------------------------------------------------------

  #applySettings(next: Settings): void {
    const previous = this.#settings;
    this.#settings = withServerBroker(next, this.#config);
    saveSettings(this.#storage, next, this.#config);
    const changed = (keys: readonly SettingKey[]) =>
      keys.some((key) => previous[key] !== this.#settings[key]);
    if (changed(DRAWING_KEYS)) {
      this.#session.clear();
      this.#fit();
    }
    if (changed(TARGET_KEYS)) {
      if (previous.sleeve_id !== this.#settings.sleeve_id) {
        this.#sleeve = null;
        this.#status.setSleeve("unknown", this.#settings.sleeve_id);
        this.#preview.reset("Waiting for the sleeve’s telemetry.");
        this.#fit();
      }
      this.#sender.connect(this.#target());
    }
  }

  #target(): SenderTarget {
    const { ws_url, username, password, sleeve_id, protocol, legacy_topic } = this.#settings;
    return { ws_url, username, password, sleeve_id, protocol, legacy_topic };
  }

  // ---- broker and sleeve -------------------------------------------------------------------

  #onBroker(state: BrokerState, detail: string | null): void {
    this.#status.setBroker(state, detail);
    this.#notices.broker = state === "offline" ? detail : null;
    this.#showNotice();
    if (state !== "connected") {
      // Without the broker nothing is known about the sleeve any more.
      this.#status.setSleeve(
        "unknown",
        this.#settings.sleeve_id,
        "Not known while the broker is not connected.",
      );
    }
  }

  #showNotice(): void {
    const { broker, config } = this.#notices;
    // The missing config explains the broker problem that usually follows it: both, config first.
    if (broker !== null) this.#status.setNotice(config === null ? broker : `${config} ${broker}`, "error");
    else this.#status.setNotice(config, "info");
  }

  #onStatus(payload: string): void {
    const id = this.#settings.sleeve_id;
    if (payload.trim() === "") {
      this.#sleeve = null;
      this.#status.setSleeve("unknown", id, "The sleeve has not published a status.");
      return;
    }
    const status = parseStatus(payload);
    if (status === null) {
      this.#status.setSleeve(
        "unknown",
        id,
        'The sleeve\'s status message is not understood (expected JSON with "online").',
      );
      return;
    }
    this.#sleeve = status;
    this.#status.setSleeve(
      status.online ? "online" : "offline",
      id,
      status.online
        ? `Online${status.layout ? `, ${status.layout.rows} × ${status.layout.columns} actuators` : ""}${status.version ? `, version ${status.version}` : ""}`
        : "Offline: strokes sent now reach the sleeve when it is back (if its session is kept).",
    );
    if (!status.online) this.#preview.reset("The sleeve is offline.");
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
    const drawn =
      drawing !== null && ref !== null && ref.drawing === drawing.id && ref.seq !== null
        ? drawing.bySeq(ref.seq)
        : undefined;
    const label = ref === null || ref.seq === null ? "A stroke" : `Stroke ${ref.seq}`;
    switch (event.type) {
      case "played":
      case "adjusted":
        // An adjusted stroke was played too, only slower (or otherwise changed) than sent.
        if (drawn) {
          this.#played++;
          this.#summarize();
        }
        if (event.type === "adjusted") this.#log.add("adjusted", `${label} ${adjustment(event)}`);
        return;
      case "rejected":
        if (drawn) {
          this.#refused++;
          this.#summarize();
          this.#session.rejected(drawn);
        }
        this.#log.add("rejected", `${label} refused: ${describe(event)}`);
        return;
      case "cancelled":
        this.#log.add("info", `${label} cancelled${event.started ? " while playing" : ""}.`);
        return;
      case "safety":
        this.#log.add(
          "error",
          `Safety: actuator (${event.row}, ${event.column}) switched off: ${describe(event)}`,
        );
        return;
      case "error":
        this.#log.add("error", `The sleeve reports an error: ${describe(event)}`);
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
}

function describe(event: SleeveEvent): string {
  const message = "message" in event ? event.message : null;
  return message ?? ("reason" in event ? event.reason.replaceAll("_", " ") : "no reason given");
}

function adjustment(event: AdjustedEvent): string {
  const { requested_duration_ms: requested, duration_ms: played } = event;
  return `played in ${Math.round(played)} ms instead of ${Math.round(requested)} ms (${event.reason.replaceAll("_", " ")}).`;
}
