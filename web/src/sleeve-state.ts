/**
 * What the page knows of the broker and the sleeve, and what it says about
 * them: the two chips, the preview's caption and the one notice line above
 * the drawing. The sleeve's retained status tells whether it is online; a
 * sleeve that never reported has none, so the page waits `STATUS_WAIT_MS`
 * after connecting before it says that nothing listens. No DOM: the page
 * shows what this says through `SleeveStateHost`.
 */
import { parseStatus, type SleeveFloor, type SleeveStatus } from "./events";
import { holdHeadline, NO_CONTROLS, wearerHold } from "./wearer-status";
import type { BrokerState } from "./mqtt/sender";
import type { SleeveState } from "./ui/status";

/** A sleeve that listens has its retained status at the broker: none after this, none listens. */
export const STATUS_WAIT_MS = 2500;

export type NoticeLevel = "info" | "warn" | "error";

export interface SleeveStateHost {
  /** The sleeve this page draws on. */
  sleeveId(): string;
  /** What to do about a lost broker, for the way the page was started (`offlineAdvice`). */
  offlineAdvice(detail: string | null): string;
  showBroker(state: BrokerState, detail: string | null): void;
  /** The sleeve's chip (`detail`: its tooltip) and the preview's caption. */
  showSleeve(sleeve: {
    state: SleeveState;
    id: string;
    detail: string | null;
    brokerConnected: boolean;
    caption: string;
  }): void;
  /** The line above the drawing; null hides it. */
  showNotice(text: string | null, level: NoticeLevel): void;
}

export class SleeveWatch {
  readonly #host: SleeveStateHost;
  #status: SleeveStatus | null = null;
  /** The sleeve's last known floor: kept while it is offline or out of reach (`floor`). */
  #floor: SleeveFloor | null = null;
  #state: SleeveState = "unknown";
  #broker: BrokerState = "connecting";
  #timer: ReturnType<typeof setTimeout> | null = null;
  #notices: { broker: string | null; config: string | null; sleeve: string | null };

  /** `configNote`: what is wrong with the server's config, shown until something more urgent. */
  constructor(host: SleeveStateHost, configNote: string | null) {
    this.#host = host;
    this.#notices = { broker: null, config: configNote, sleeve: null };
    this.#showNotice();
    this.#setSleeve("unknown");
  }

  /** The sleeve's last status, or null when none is known. */
  get status(): SleeveStatus | null {
    return this.#status;
  }

  /**
   * The sleeve's floor, as its last status that could say it said it: kept while the broker is
   * out of reach, while the broker holds no status (one restarted without its saved state), and
   * through an offline status without one (an older sleeve's last will): a sleeve's floor does
   * not change because it or the network went away. Only its online status (with a floor, or
   * without: an older sleeve has none) or another sleeve replaces it.
   */
  get floor(): SleeveFloor | null {
    return this.#floor;
  }

  get state(): SleeveState {
    return this.#state;
  }

  get brokerState(): BrokerState {
    return this.#broker;
  }

  onBroker(state: BrokerState, detail: string | null): void {
    const wasOffline = this.#broker === "offline" || this.#notices.broker !== null;
    this.#broker = state;
    this.#host.showBroker(state, detail);
    if (state === "connected") {
      this.#notices.broker = null;
      this.#waitForStatus();
    } else if (state === "offline") {
      this.#notices.broker = this.#host.offlineAdvice(detail);
    } else if (!wasOffline) {
      this.#notices.broker = null;
    }
    // A reconnection attempt ("connecting") keeps the offline notice: it is not back yet.
    this.#showNotice();
    if (state !== "connected") {
      this.#stopWaiting();
      // Without the broker nothing is known about the sleeve any more.
      this.#setSleeve("unknown", "Not known while the broker is not connected.");
    }
  }

  /**
   * The sleeve's retained status (an empty payload: the broker holds none). Null when none was
   * read (none held, or not understood); otherwise whether the sleeve has just come back online.
   */
  onStatus(payload: string): { back: boolean } | null {
    if (payload.trim() === "") {
      this.#status = null;
      this.#setSleeve("absent");
      return null;
    }
    const status = parseStatus(payload);
    if (status === null) {
      this.#setSleeve(
        "unknown",
        'The sleeve\'s status message is not understood (expected JSON with "online").',
      );
      return null;
    }
    const wasOnline = this.#state === "online";
    this.#status = status;
    if (status.floor !== undefined || status.online) this.#floor = status.floor ?? null;
    this.#setSleeve(
      status.online ? "online" : "offline",
      status.online
        ? `Online${status.layout ? `, ${status.layout.rows} × ${status.layout.columns} actuators` : ""}${status.version ? `, version ${status.version}` : ""}`
        : "Offline: strokes sent now reach the sleeve when it is back (if its session is kept), and play if they are not older than its age limit by then.",
    );
    return { back: status.online && !wasOnline };
  }

  /** Another sleeve is drawn on: nothing is known of it until its status comes. */
  sleeveChanged(): void {
    this.#status = null;
    this.#floor = null;
    this.#setSleeve("unknown");
  }

  /** The connection to the broker is kept for another sleeve: its status, if any, comes at once. */
  awaitStatus(): void {
    if (this.#broker === "connected") this.#waitForStatus();
  }

  #waitForStatus(): void {
    this.#stopWaiting();
    this.#timer = setTimeout(() => {
      this.#timer = null;
      if (this.#state === "unknown" && this.#broker === "connected") this.#setSleeve("absent");
    }, STATUS_WAIT_MS);
  }

  #stopWaiting(): void {
    if (this.#timer !== null) clearTimeout(this.#timer);
    this.#timer = null;
  }

  /** The chip, the preview's caption and the notice say the same thing about the sleeve. */
  #setSleeve(state: SleeveState, detail: string | null = null): void {
    this.#state = state;
    const id = this.#host.sleeveId();
    const connected = this.#broker === "connected";
    const layout = this.#status?.layout;
    // The wearer's pause or "do not disturb": the sleeve is online but takes no strokes.
    const nowMs = Date.now();
    const hold = wearerHold(this.#status?.controls ?? NO_CONTROLS, nowMs);
    const grid = layout ? `: ${layout.rows} × ${layout.columns} actuators` : "";
    const caption = {
      online:
        hold === null
          ? `Sleeve ${id} online${grid}, waiting for strokes.`
          : `Sleeve ${id} online${grid}, playing nothing. ${holdHeadline(hold, nowMs)}`,
      offline: `Sleeve ${id} is offline: no new stroke is felt.`,
      absent: `No sleeve answers on id ${id}: nothing is felt.`,
      unknown: connected
        ? `Waiting for sleeve ${id} to report…`
        : `Not connected to the broker: the sleeve cannot be seen.`,
    }[state];
    this.#host.showSleeve({ state, id, detail, brokerConnected: connected, caption });
    this.#notices.sleeve =
      state === "absent"
        ? `No sleeve listens on id '${id}': nothing has ever reported there, so strokes sent now are not felt. ` +
          "Check the sleeve id in Settings → Sleeve (a sleeve prints its id when it starts)."
        : state === "offline"
          ? `Sleeve '${id}' is offline: strokes wait at the broker and play if it is back within its age limit ` +
            "(10 s unless set; older ones are refused as stale). If it crashed, a motor it was driving may " +
            "run until it restarts (docs/sleeve-hardware.md: the enable line)."
          : null;
    this.#showNotice();
  }

  #showNotice(): void {
    const { broker, config, sleeve } = this.#notices;
    // The missing config explains the broker problem that usually follows it: both, config first.
    if (broker !== null) this.#host.showNotice(config === null ? broker : `${config} ${broker}`, "error");
    else if (sleeve !== null) this.#host.showNotice(sleeve, "warn");
    else this.#host.showNotice(config, "info");
  }
}

/**
 * What to do about a lost broker: `startedByUp` when the page came from `feelmysign up` and
 * uses its broker (not one set in Settings → Connection).
 */
export function offlineAdvice(detail: string | null, wsUrl: string, startedByUp: boolean): string {
  if (detail !== null && detail.includes("refused the login")) return detail;
  if (startedByUp) {
    return (
      `No connection to ${wsUrl}; retrying every 2 s. The broker runs inside 'feelmysign up' ` +
      "(make up): its terminal says whether it is restarting; if that stopped, start it again."
    );
  }
  return `No connection to ${wsUrl}; retrying every 2 s. Start a broker with 'make up', or set yours in Settings → Connection.`;
}
