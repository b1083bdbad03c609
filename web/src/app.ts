/**
 * The drawing client, put together: pointer samples -> animation frames ->
 * the chosen simplifier -> strokes -> MQTT, and the sleeve's telemetry back to
 * the status bar, the canvas, the preview and the felt timeline. The
 * algorithms live in pure modules; this class only wires them to the page.
 */
import { CANCEL_ALL } from "./control";
import type { ServerConfig } from "./config";
import type { Drawing } from "./drawing";
import { newDrawingId } from "./drawing-id";
import { BY_WEARER, EventCopies, interpretEvent, parseEvent, parseStatus, strokeLabel } from "./events";
import { StrokeSender, type BrokerState } from "./mqtt/sender";
import type { Stroke } from "./protocol";
import { buildRecording, recordingFileName } from "./recording";
import { drawingFromRecording, parseRecording } from "./recording-load";
import { LATE_LIMIT_MS, loadSettings, saveSettings, withServerBroker, type Settings } from "./settings";
import { lateLimitMs, senderTarget, settingsChange } from "./settings-diff";
import { withFloor } from "./sleeve-floor";
import { offlineAdvice, SleeveWatch } from "./sleeve-state";
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
import { SleeveSays } from "./ui/sleeve-says";
import { StageSpace } from "./ui/stage-space";
import { byId, StatusBar } from "./ui/status";
import { TimelineView } from "./ui/timeline";
import { WearerNotice } from "./ui/wearer-notice";
import { WearerHoldKeeper, type HoldChange } from "./wearer-hold";
import {
  ceilingNote,
  holdChangeNote,
  holdReason,
  isWearerRefusal,
  NO_CONTROLS,
  wearerRefusalNote,
  wearerStoppedDetail,
  wearerStoppedHeadline,
} from "./wearer-status";

/** A cut by the wearer is said as their stop once this passed without a pause in their status. */
const WEARER_STOP_SETTLE_MS = 1000;

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
  /** Copies of events a broker restart delivers again: each stroke counted once. */
  readonly #copies = new EventCopies();
  readonly #panel: SettingsPanel;
  readonly #picker: SleevePicker;
  readonly #sender: StrokeSender;
  readonly #felt: FeltPanel;
  readonly #session: DrawingSession;
  readonly #buttons: Record<"undo" | "replay" | "record", HTMLButtonElement>;
  readonly #hint: HTMLElement;
  readonly #space: StageSpace;
  readonly #compareToggle: HTMLInputElement;
  readonly #compareDetail: HTMLInputElement;
  readonly #sleeve: SleeveWatch;
  /** The wearer's choice (the status's controls): strokes held on the page while paused. */
  readonly #wearer = new WearerHoldKeeper();
  readonly #wearerNotice: WearerNotice;
  /** Wakes the page when a "do not disturb" runs out. */
  #wearerTimer: ReturnType<typeof setTimeout> | null = null;
  /** The drawing the wearer stopped (their stop or block): the sleeve refuses the rest of it. */
  #wearerStopped: string | null = null;
  #settings: Settings;
  #refitPending = false;
  #arrival: Arrival = "as-drawn";
  /** The drawing the felt panel shows. */
  #feltDrawing: string | null = null;
  /** The grid the felt panel's lanes show. */
  #feltGrid: GridSize = { rows: 0, columns: 0 };

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
    // The caption counts from the card: one tally of what became of each stroke (fates.ts).
    this.#felt = new FeltPanel(timeline, this.#view, this.#says);
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
    this.#space = new StageSpace(doc);
    this.#compareToggle = byId<HTMLInputElement>(doc, "compare-toggle");
    this.#compareDetail = byId<HTMLInputElement>(doc, "compare-detail");
    this.#session = new DrawingSession(this.#view, {
      // The simplifier keeps every stroke at or above the sleeve's floor (its status), the last
      // one known while the sleeve or the broker is away.
      settings: () => withFloor(this.#settings, this.#sleeve.floor),
      grid: () => this.#grid(),
      send: (stroke) => this.#send(stroke),
      changed: (drawing) => this.#drawingChanged(drawing),
      released: () => {
        if (this.#refitPending) this.#fit();
      },
    });
    this.#sleeve = new SleeveWatch(
      {
        sleeveId: () => this.#settings.sleeve_id,
        offlineAdvice: (detail) =>
          offlineAdvice(
            detail,
            this.#settings.ws_url,
            this.#config !== null && !this.#settings.broker_custom,
          ),
        showBroker: (state, detail) => this.#status.setBroker(state, detail),
        showSleeve: ({ state, id, detail, brokerConnected, caption }) => {
          this.#status.setSleeve(state, id, detail, brokerConnected);
          this.#preview.reset(caption, state === "online");
        },
        showNotice: (text, level) => this.#status.setNotice(text, level),
      },
      options.configNote,
    );
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
        const unsent = this.#markUnsent(strokes);
        this.#says.addDropped(strokes.length);
        this.#felt.unsent(unsent);
        this.#says.add(
          "info",
          `${strokes.length} stroke(s) dropped: not sent within ${LATE_LIMIT_MS / 1000} s.`,
        );
      },
    });
    this.#sender.setLateLimit(lateLimitMs(this.#settings));
    this.#wearerNotice = new WearerNotice(doc, {
      sendHeld: () => this.sendHeld(),
      dropHeld: () => this.#dropHeld(),
    });

    if (loaded.replaced.length > 0) {
      this.#says.add("info", `Saved settings no longer valid were reset: ${loaded.replaced.join(", ")}.`);
    }
    this.#status.setUnsent(0);

    attachPointer(this.#view, {
      press: (sample, kind) => this.#session.press(sample, kind),
      move: (samples) => this.#session.move(samples),
      release: (sample) => this.#session.release(sample),
    });
    this.#wireButtons();
    const resized = new ResizeObserver(() => this.#fit());
    resized.observe(this.#space.area);
    resized.observe(byId(this.#doc, "stage-wrap")); // the area's height follows its content
    window.addEventListener("resize", () => this.#fit());
    this.#fit();
    this.#drawingChanged(null);
    this.#sender.connect(senderTarget(this.#settings));
  }

  #wireButtons(): void {
    const doc = this.#doc;
    byId(doc, "new-button").addEventListener("click", () => this.#session.clear());
    this.#buttons.undo.addEventListener("click", () => {
      if (!this.#session.undo()) return;
      // A held stroke of the path taken back is not sent on resume: it is no longer drawn.
      const drawing = this.#session.drawing;
      const gone = this.#wearer.release(
        (stroke) => drawing !== null && stroke.seq != null && drawing.bySeq(stroke.seq) !== undefined,
      );
      if (gone.length > 0) this.#says.setHeld(this.#wearer.heldCount);
      this.#showWearer();
    });
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
        sleeveGrid: this.#sleeve.status?.layout ?? null,
        spacingCm: this.#sleeve.status?.layout?.spacing_cm ?? null,
        floor: this.#sleeve.floor,
        ceiling: this.#wearer.ceiling,
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
    const another = (drawing?.id ?? null) !== this.#says.drawingId;
    this.#says.reset(drawing?.id ?? null);
    this.#says.setSent(drawing?.strokeCount ?? 0, drawing?.lengthenedCount ?? 0);
    if (another) {
      this.#wearerStopped = null;
      this.#newDrawingHeld();
    }
    this.#hint.hidden = drawing !== null;
    const hasPaths = drawing !== null && drawing.paths.length > 0;
    this.#buttons.undo.disabled = !hasPaths;
    this.#buttons.record.disabled = !hasPaths;
    this.#buttons.replay.disabled = drawing === null || drawing.keptStrokeCount === 0;
    if (drawing === null || drawing.id !== this.#feltDrawing) {
      this.#feltDrawing = drawing?.id ?? null;
      this.#setFelt(drawing, this.#grid());
      this.#arrival = "as-drawn";
      this.#compare();
    } else {
      this.#felt.refresh();
      if (this.#compareToggle.checked && !this.#session.pressed) this.#compare();
    }
  }

  /** Stop: every motor off on the sleeve, the rest of this drawing dropped (also Esc). */
  stop(): void {
    // A pen still down draws nothing more: its path ends here, before the cancels go out.
    this.#session.endPath();
    const drawing = this.#session.drawing;
    const dropped = [
      ...(drawing === null ? [] : this.#sender.cancel(drawing.id)),
      ...this.#sender.cancel(CANCEL_ALL),
    ];
    this.#felt.stopCursor();
    // Strokes held while the wearer paused are dropped too: Stop means nothing more of this drawing.
    this.#markNeverSent(this.#wearer.take());
    this.#says.setHeld(0);
    this.#showWearer();
    this.#session.close();
    // Never sent: marked as such, and counted apart from what the sleeve cancelled.
    const unsent = this.#markUnsent(dropped);
    if (dropped.length > 0) this.#says.addDropped(dropped.length);
    this.#felt.unsent(unsent);
    this.#says.add(
      "info",
      `Stop sent${dropped.length > 0 ? `; ${dropped.length} unsent stroke(s) dropped` : ""}. ` +
        "Strokes the sleeve had not played yet are cancelled.",
    );
  }

  /** Marks the current drawing's `strokes` never sent on the canvas; returns their seqs. */
  #markUnsent(strokes: readonly Stroke[]): number[] {
    const drawing = this.#session.drawing;
    const seqs: number[] = [];
    for (const stroke of strokes) {
      if (drawing !== null && stroke.drawing === drawing.id && stroke.seq != null) seqs.push(stroke.seq);
    }
    for (const seq of seqs) this.#session.refused(seq, "unsent");
    return seqs;
  }

  /** Sends the current drawing's strokes again, as a new drawing (the sleeve plays them back to back). */
  playAgain(): void {
    const drawing = this.#session.drawing;
    if (drawing === null || drawing.strokes.length === 0) return;
    const copy = drawing.copyAs(newDrawingId());
    this.#arrival = "at-once";
    this.#session.adopt(copy);
    for (const stroke of copy.strokes) this.#send(stroke);
    this.#says.setSent(copy.strokeCount, copy.lengthenedCount);
    // No pen to catch up with: the sleeve plays what it has in hand back to back, the pauses
    // between strokes left out, and the card says so (sleeve-says.ts).
    const drawn = drawnMs(copy);
    this.#says.replayed(drawn);
    this.#says.add("info", playAgainNote(copy.strokes.length, this.#felt.totalMs, drawn));
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
    // Not sent: Play again will send it, all at once. The timeline shows that, not the drawing's
    // own pace, so the time it predicts is the time Play again keeps.
    this.#arrival = "at-once";
    this.#session.adopt(drawing);
    this.#says.notSent(drawing.strokeCount, "loaded");
    this.#says.add(
      "info",
      `Loaded ${name}: ${drawing.strokes.length} strokes, not sent. Play again sends them all at once; ` +
        `the timeline shows them as the sleeve will then play them, back to back and caught up ` +
        `(${(this.#felt.totalMs / 1000).toFixed(1)} s, where the drawing took ${(drawnMs(drawing) / 1000).toFixed(1)} s).`,
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
    let note = `A (solid): ${drawing.strokes.length} strokes as drawn. B (dashed): ${count} strokes at detail ${level} of 5.`;
    // The longest-stroke cap cuts at every detail: say how much of B's count is its doing.
    if (params.algorithm === "window" && params.max_stroke_ms > 0) {
      const uncapped = simplifyPaths({ ...params, max_stroke_ms: 0 }, drawing.paths).filter(
        (piece) => piece.segment.dropped === null,
      ).length;
      if (uncapped < count) {
        note +=
          ` The longest-stroke cap (${params.max_stroke_ms} ms, Settings → Advanced) cuts ${count - uncapped} of them:` +
          ` without it, detail ${level} would send ${uncapped}.`;
      }
    }
    byId(this.#doc, "compare-note").textContent = note;
  }

  // ---- layout ------------------------------------------------------------------------------

  /** The felt panel's drawing (or none) on `grid`: its lanes are the grid's actuators. */
  #setFelt(drawing: Drawing | null, grid: GridSize): void {
    this.#feltGrid = grid;
    this.#felt.setDrawing(drawing, grid, this.#arrival);
  }

  #grid(): GridSize {
    const layout = this.#sleeve.status?.layout;
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
    const { widthPx, heightPx } = this.#space.available();
    this.#view.fit(grid, this.#settings.stretch, widthPx, heightPx);
    this.#space.setTurned(this.#view.turned);
    this.#preview.setGrid(grid, this.#view.turned);
    // Before the first drawing the timeline's lanes are the sleeve's too, as soon as its status
    // says its grid (a drawing's grid is given with the drawing, in #drawingChanged).
    const shown = this.#feltGrid;
    if (this.#feltDrawing === null && (shown.rows !== grid.rows || shown.columns !== grid.columns))
      this.#setFelt(null, grid);
  }

  // ---- settings ----------------------------------------------------------------------------

  #applySettings(next: Settings): void {
    const previous = this.#settings;
    this.#settings = withServerBroker(next, this.#config);
    saveSettings(this.#storage, next, this.#config);
    this.#showWearer(); // the ceiling's line names the intensity
    this.#sender.setLateLimit(lateLimitMs(this.#settings));
    const change = settingsChange(previous, this.#settings);
    if (change.grid) {
      this.#session.clear();
      this.#fit();
    } else if (change.drawing) {
      this.#arrival = "at-once"; // not sent: Play again sends it, all at once
      const again = this.#session.recut();
      if (again === null) this.#arrival = "as-drawn";
      else {
        this.#says.notSent(again.strokeCount, "re-simplified");
        this.#says.add(
          "info",
          `Re-simplified with the new settings: ${again.strokes.length} strokes, not sent. Play again sends them.`,
        );
      }
      this.#fit();
    }
    if (change.target) {
      if (change.sleeve) {
        // The other sleeve's wearer has not said anything yet: its status will.
        this.#wearer.forgetSleeve();
        this.#showWearer();
        // Its strokes went to the other sleeve: the next path starts a new drawing for this one.
        this.#session.close();
        this.#picker.setCurrent(this.#settings.sleeve_id);
        this.#says.add(
          "info",
          `Now drawing on sleeve ${this.#settings.sleeve_id}; the next path starts a new drawing.`,
        );
        this.#sleeve.sleeveChanged();
        this.#fit();
      }
      // Another sleeve on the same broker keeps the connection; its status, if known, comes at once.
      this.#sender.connect(senderTarget(this.#settings));
      if (change.sleeve) this.#sleeve.awaitStatus();
    }
  }

  // ---- broker and sleeve -------------------------------------------------------------------

  #onBroker(state: BrokerState, detail: string | null): void {
    this.#sleeve.onBroker(state, detail);
    if (state !== "connected") this.#picker.forget();
  }

  #onStatus(payload: string): void {
    const read = this.#sleeve.onStatus(payload);
    this.#onControls(payload);
    if (read === null) return;
    if (read.back && this.#says.counts.played + this.#says.counts.refused > 0) {
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
    if (event === null || this.#copies.isCopy(payload, event)) return;
    const drawingId = this.#session.drawing?.id ?? null;
    const reading = interpretEvent(event, drawingId);
    if (reading.counts.includes("delayed")) this.#says.delayed(reading.delayMs);
    // What became of the stroke: fates.ts, the rule `up` and the study report from too.
    const seq = "seq" in event ? event.seq : null;
    const ours = seq !== null && drawingId !== null && "drawing" in event && event.drawing === drawingId;
    const fate = ours ? this.#says.fate(event) : null;
    if (ours && event.type === "cancelled" && event.by === BY_WEARER) this.#cancelledByWearer(event.started);
    // A copy's refusal (after a broker restart, or after Stop) of a stroke that was felt.
    const feltCopy = event.type === "rejected" && (fate === "played" || fate === "cut");
    if (reading.played !== null) this.#felt.played(reading.played);
    if (reading.cancelled !== null) this.#felt.cancelled(reading.cancelled);
    if (ours && (fate === "refused" || fate === "cancelled")) this.#session.refused(seq, fate);
    if (reading.unplayed !== null && !feltCopy) this.#felt.unplayed(reading.unplayed);
    else if (ours && reading.played === null && reading.cancelled === null) this.#felt.told(seq);
    if (feltCopy) {
      this.#says.add(
        "info",
        `${strokeLabel(seq)} came again (a reconnect) and was not played twice: it was felt once.`,
      );
      return;
    }
    if (event.type === "rejected" && isWearerRefusal(event.reason)) {
      // The status came after the stroke left: said as the wearer's pause, not a generic refusal.
      // Shown as the generic refusal would be: for this drawing, or for no drawing in particular.
      if (ours || event.drawing == null) {
        this.#says.add("rejected", wearerRefusalNote(strokeLabel(seq), event.reason, event.message));
      }
      return;
    }
    for (const note of reading.notes) this.#says.add(note.kind, note.text);
  }

  // ---- the wearer's choice -----------------------------------------------------------------

  /**
   * The wearer cancelled a stroke of this drawing. One dropped before it played means their stop
   * (or block): the sleeve refuses the rest of the drawing, so the page says so. One cut while it
   * played may also be their pause: said as a stop only if, a moment later (the sleeve tells the
   * cut before its new status), the wearer holds nothing.
   */
  #cancelledByWearer(started: boolean): void {
    const drawing = this.#session.drawing?.id ?? null;
    if (drawing === null || this.#wearerStopped === drawing) return;
    const stopped = () => {
      if (this.#session.drawing?.id !== drawing || this.#wearerStopped === drawing) return;
      if (this.#wearer.hold(Date.now()) !== null) return;
      this.#wearerStopped = drawing;
      // As after the sender's Stop: what has no answer yet will not be felt.
      this.#felt.stopCursor();
      this.#says.add("info", `${wearerStoppedHeadline} ${wearerStoppedDetail}`);
      this.#showWearer();
    };
    if (started) setTimeout(stopped, WEARER_STOP_SETTLE_MS);
    else stopped();
  }

  /** A stroke drawn (or played again): sent, or held on the page while the wearer paused. */
  #send(stroke: Stroke): void {
    const drawing = this.#session.drawing;
    if (this.#wearer.keep(stroke, Date.now())) {
      if (drawing !== null && stroke.drawing === drawing.id && stroke.seq != null)
        this.#session.held(stroke.seq);
      const hold = this.#wearer.hold(Date.now());
      this.#says.setHeld(this.#wearer.heldCount, hold === null ? null : holdReason(hold));
      this.#showWearer();
      return;
    }
    this.#wearer.dismissResumed();
    this.#showWearer();
    this.#sender.send(stroke);
  }

  /** The held strokes go out now, back to back (wearer-hold.ts says why that suits the sleeve's pace). */
  sendHeld(): void {
    if (this.#wearer.hold(Date.now()) !== null) return;
    const strokes = this.#wearer.take();
    for (const stroke of strokes) {
      if (stroke.seq != null) this.#session.unhold(stroke.seq);
      this.#sender.send(stroke);
    }
    this.#says.setHeld(0);
    // On the timeline now, arriving as they go; their fate (played, refused) moves them from there.
    const drawing = this.#session.drawing;
    this.#felt.heldSent(
      strokes.flatMap((stroke) =>
        drawing !== null && stroke.drawing === drawing.id && stroke.seq != null ? [stroke.seq] : [],
      ),
      performance.now(),
    );
    if (strokes.length > 0) this.#says.add("info", `${strokes.length} held stroke(s) sent.`);
    this.#showWearer();
  }

  #dropHeld(): void {
    const strokes = this.#wearer.take();
    this.#markNeverSent(strokes);
    this.#says.setHeld(0);
    this.#felt.refresh();
    this.#showWearer();
  }

  /** A new drawing (or none): the strokes held for the old one are never sent. */
  #newDrawingHeld(): void {
    this.#markNeverSent(this.#wearer.newDrawing());
    this.#showWearer();
  }

  #markNeverSent(strokes: readonly Stroke[]): void {
    if (strokes.length === 0) return;
    const drawing = this.#session.drawing;
    for (const stroke of strokes) {
      if (stroke.seq == null) continue;
      this.#session.unhold(stroke.seq);
      if (drawing !== null && stroke.drawing === drawing.id) this.#session.refused(stroke.seq, "unsent");
    }
    if (drawing !== null && strokes.some((stroke) => stroke.drawing === drawing.id))
      this.#says.addDropped(strokes.length);
    this.#says.add("info", `${strokes.length} held stroke(s) dropped, never sent.`);
  }

  #onControls(payload: string): void {
    const online = this.#sleeve.status?.online === true && payload.trim() !== "";
    const status = online ? parseStatus(payload) : null;
    const controls = status === null ? null : (status.controls ?? NO_CONTROLS);
    if (online && controls === null) {
      this.#says.add(
        "error",
        "The sleeve's wearer controls (its status, controls) are not understood: the page cannot tell whether the wearer paused the sleeve or asked not to be disturbed.",
      );
    }
    const nowMs = Date.now();
    if (controls !== null)
      this.#holdChanged(
        this.#wearer.onStatus(controls, online, this.#sleeve.status?.at_ms ?? null, nowMs),
        nowMs,
      );
    this.#showWearer();
  }

  /** What holds the drawing changed: said in the log, and the card's held strokes say why now. */
  #holdChanged(change: HoldChange | null, nowMs: number): void {
    if (change === null) return;
    const note = holdChangeNote(change.before, change.after, change.ranOut, nowMs);
    if (note !== null) this.#says.add("info", note);
    if (change.after !== null) this.#says.setHeld(this.#wearer.heldCount, holdReason(change.after));
  }

  #showWearer(): void {
    const nowMs = Date.now();
    this.#holdChanged(this.#wearer.tick(nowMs), nowMs);
    this.#wearerNotice.show(
      this.#wearer.view(nowMs),
      ceilingNote(this.#wearer.ceiling, this.#settings.intensity),
      nowMs,
      this.#wearerStopped !== null && this.#wearerStopped === (this.#session.drawing?.id ?? null),
    );
    if (this.#wearerTimer !== null) clearTimeout(this.#wearerTimer);
    this.#wearerTimer = null;
    const hold = this.#wearer.hold(nowMs);
    if (hold !== null) {
      // Again when "do not disturb" runs out, and at midnight, when "tomorrow at 07:00" becomes
      // "07:00". setTimeout holds at most 2^31 - 1 ms; a "do not disturb" is at most 24 h.
      const midnight = new Date(nowMs);
      midnight.setHours(24, 0, 0, 0);
      const ends = hold.untilMs === null ? [] : [hold.untilMs];
      const waitMs = Math.min(Math.min(midnight.getTime(), ...ends) - nowMs + 50, 2 ** 31 - 1);
      this.#wearerTimer = setTimeout(() => {
        this.#wearerTimer = null;
        this.#showWearer();
      }, waitMs);
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

/**
 * The note Play again leaves: `strokes` sent all at once, which the sleeve plays back to back, in
 * `playsMs` (the timeline's prediction) where the drawing took `drawnMs`.
 */
export function playAgainNote(strokes: number, playsMs: number, drawnMs: number): string {
  const s = (ms: number) => (ms / 1000).toFixed(1);
  return (
    `Played again: ${strokes} strokes sent all at once. With no pen to keep pace with, the sleeve ` +
    `plays them back to back and caught up, the pauses between strokes left out; the timeline shows ` +
    `them so (${s(playsMs)} s, where the drawing took ${s(drawnMs)} s).`
  );
}

/** How long the drawing took to draw: its first sample to its last, pen lifts included. */
function drawnMs(drawing: Drawing): number {
  const times = drawing.paths.flatMap((path) =>
    path.length > 0 ? [path[0]!.t_ms, path[path.length - 1]!.t_ms] : [],
  );
  return times.length === 0 ? 0 : Math.max(...times) - Math.min(...times);
}
