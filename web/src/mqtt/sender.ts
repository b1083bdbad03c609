/**
 * The page's MQTT side: publishes strokes (QoS 1) and listens to the sleeve's
 * telemetry, over WebSockets with mqtt.js. Strokes wait in an outbox while the
 * broker is out of reach and go out in order when it is back; one leaves the
 * outbox only on the broker's PUBACK, so the count of unsent strokes shown is
 * honest. `sent_at_ms` is stamped when a stroke actually goes out.
 *
 * Several sleeves may share the broker. The page hears every sleeve's retained
 * status (for the sleeve picker) and the chosen one's actuators and events.
 * Choosing another sleeve swaps those two subscriptions on the same connection;
 * each stroke keeps the sleeve it was drawn for, so one drawn offline for the
 * first still goes to the first.
 */
import mqtt, { type IClientOptions, type MqttClient } from "mqtt";
import { CANCEL_ALL, formatControl } from "../control";
import { Outbox } from "../outbox";
import { formatJson, formatLegacy, StrokeError, type Stroke } from "../protocol";
import { ANY_SLEEVE, controlTopic, strokesTopic, telemetryTopic, TOPIC_ROOT } from "./topics";

export type BrokerState = "connecting" | "connected" | "offline";
export type WireProtocol = "json" | "legacy";

export interface SenderTarget {
  readonly ws_url: string;
  readonly username: string;
  readonly password: string;
  readonly sleeve_id: string;
  readonly protocol: WireProtocol;
  readonly legacy_topic: string;
}

export interface SenderListener {
  broker(state: BrokerState, detail: string | null): void;
  /** The chosen sleeve's retained status ("" when it was cleared). */
  status(payload: string): void;
  /** Any sleeve's retained status, the chosen one's included: what the picker shows. */
  sleeveStatus(sleeveId: string, payload: string): void;
  actuators(payload: string): void;
  event(payload: string): void;
  unsent(count: number): void;
  /** The broker acknowledged this stroke (QoS 1 PUBACK). */
  acked(stroke: Stroke): void;
  /** A stroke that could not be formatted: reported, never silently dropped. */
  refused(stroke: Stroke, error: StrokeError): void;
  /** Strokes that waited longer than the late limit and were dropped (the "drop late" policy). */
  late(strokes: Stroke[]): void;
}

/** How long to wait between reconnection attempts. */
const RECONNECT_PERIOD_MS = 2000;
/** A broker that does not answer the CONNECT in this time is treated as unreachable. */
const CONNECT_TIMEOUT_MS = 8000;
/** The broker notices a vanished page after 1.5 x this. */
const KEEPALIVE_S = 20;
/**
 * CONNACK codes that retrying cannot fix, told by code, never by the broker's wording: bad
 * user name or password, not authorized (MQTT 3.1.1: 4, 5; MQTT 5: 134, 135).
 */
export const BAD_LOGIN_CODES: ReadonlySet<number> = new Set([4, 5, 134, 135]);
/** Every sleeve's status, retained: who is online, for the picker. */
const EVERY_STATUS = telemetryTopic(ANY_SLEEVE, "status");
/**
 * The chosen sleeve's events at QoS 1 on a persistent session: the broker keeps them while
 * the page reconnects (a broker restarted from its saved state too), so the page counts every
 * stroke the sleeve played. Statuses are retained (heard again on subscribing) and actuator
 * frames only matter live, so those stay QoS 0 and nothing is queued for them.
 */
const EVENTS_QOS = 1;

/** A stroke and the sleeve it was drawn for. */
interface Addressed {
  readonly stroke: Stroke;
  readonly sleeveId: string;
}

/** The chosen sleeve's own telemetry: swapped when another sleeve is chosen. */
const ownTopics = (sleeveId: string): string[] =>
  (["actuators", "events"] as const).map((name) => telemetryTopic(sleeveId, name));

/** Subscriptions with their QoS: the chosen sleeve's events at EVENTS_QOS, the rest at 0. */
function subscriptions(topics: readonly string[]): Record<string, { qos: 0 | 1 }> {
  return Object.fromEntries(
    topics.map((topic) => [topic, { qos: topic.endsWith("/events") ? EVENTS_QOS : 0 }]),
  );
}

/**
 * A client id of its own for each sender (one per page load): the same on every reconnect,
 * so the broker resumes the session and hands over the events it kept; never shared with
 * another tab, whose connection would otherwise take this one's session over.
 */
function newClientId(): string {
  const bytes = crypto.getRandomValues(new Uint8Array(8));
  return `feelmysign-web-${Array.from(bytes, (b) => b.toString(16).padStart(2, "0")).join("")}`;
}

/** `feelmysign/<id>/<name>` -> [id, name]; null for any other topic. */
function sleeveTopicParts(topic: string): [string, string] | null {
  const parts = topic.split("/");
  return parts.length === 3 && parts[0] === TOPIC_ROOT ? [parts[1]!, parts[2]!] : null;
}

export class StrokeSender {
  readonly #listener: SenderListener;
  readonly #outbox = new Outbox<Addressed>();
  readonly #decoder = new TextDecoder();
  #client: MqttClient | null = null;
  #target: SenderTarget | null = null;
  /** Cancels not yet acknowledged by the broker, sent before any stroke when it is back. */
  #cancels: { readonly drawing: string; readonly sleeveId: string }[] = [];
  /** Every sleeve's last retained status heard on this connection. */
  readonly #statuses = new Map<string, string>();
  /** Strokes not sent within this many ms are dropped; null: they go out whenever possible. */
  #lateLimitMs: number | null = null;
  /** This page load's MQTT client id: its session on the broker (see newClientId). */
  readonly #clientId = newClientId();
  /**
   * The sleeve whose own topics the broker's session holds subscriptions for: a session
   * resumed after another sleeve was chosen offline still has the old one's, dropped then.
   */
  #sessionSleeve: string | null = null;

  constructor(listener: SenderListener) {
    this.#listener = listener;
  }

  get unsent(): number {
    return this.#outbox.size;
  }

  /**
   * (Re)connects to `target`. Strokes in flight on the old connection are sent again.
   * Only another sleeve on the same broker and login keeps the connection: its
   * subscriptions are swapped, and its status, if heard already, is told at once.
   */
  connect(target: SenderTarget): void {
    const old = this.#target;
    if (
      this.#client !== null &&
      old !== null &&
      old.ws_url === target.ws_url &&
      old.username === target.username &&
      old.password === target.password &&
      old.protocol === target.protocol &&
      old.legacy_topic === target.legacy_topic
    ) {
      this.#chooseSleeve(old.sleeve_id, target);
      return;
    }
    this.#close();
    this.#statuses.clear();
    this.#target = target;
    this.#outbox.requeueInFlight();
    const options: IClientOptions = {
      username: target.username,
      password: target.password,
      clientId: this.#clientId,
      // A persistent session (docs/protocol.md): the broker keeps the events subscription,
      // and the events published while the page is away, until the page is back or its
      // persistent_client_expiration passes.
      clean: false,
      keepalive: KEEPALIVE_S,
      reconnectPeriod: RECONNECT_PERIOD_MS,
      connectTimeout: CONNECT_TIMEOUT_MS,
      protocolVersion: 4,
      // Subscriptions are made again in the connect handler, every time.
      resubscribe: false,
    };
    this.#listener.broker("connecting", `Connecting to ${target.ws_url}…`);
    let client: MqttClient;
    try {
      client = mqtt.connect(target.ws_url, options);
    } catch (error) {
      this.#listener.broker(
        "offline",
        `Cannot connect to ${target.ws_url}: ${String(error)}. Check the broker URL in Settings.`,
      );
      return;
    }
    this.#client = client;
    client.on("connect", (connack) => {
      if (client !== this.#client) return;
      this.#listener.broker(
        "connected",
        `Connected to ${target.ws_url} as ${target.username || "anonymous"}`,
      );
      // Retained statuses come again with the subscription; one cleared meanwhile would not.
      this.#statuses.clear();
      // The target now, not at connect(): another sleeve may have been chosen since.
      const sleeveId = this.#target?.sleeve_id ?? target.sleeve_id;
      const previous = this.#sessionSleeve;
      if (connack.sessionPresent && previous !== null && previous !== sleeveId) {
        client.unsubscribe(ownTopics(previous));
      }
      this.#sessionSleeve = sleeveId;
      // Subscribed again even when the session was kept: the broker then sends the retained
      // statuses again, and a broker that lost its saved state has no subscription left.
      client.subscribe(subscriptions([EVERY_STATUS, ...ownTopics(sleeveId)]), (error) => {
        if (error)
          this.#listener.broker(
            "connected",
            `Connected, but cannot read the sleeve's telemetry: ${error.message}`,
          );
      });
      this.#flush();
    });
    client.on("reconnect", () => {
      if (client === this.#client) this.#listener.broker("connecting", `Reconnecting to ${target.ws_url}…`);
    });
    client.on("close", () => {
      if (client !== this.#client) return;
      this.#listener.broker(
        "offline",
        `No connection to ${target.ws_url}; retrying every ${RECONNECT_PERIOD_MS / 1000} s. Is the broker running? ('make up' starts it.)`,
      );
    });
    client.on("error", (error: Error & { code?: number }) => {
      if (client !== this.#client) return;
      if (error.code !== undefined && BAD_LOGIN_CODES.has(error.code)) {
        // Retrying a refused login only fills the broker's log: stop until the settings change.
        // Detached first, so that the close that follows does not overwrite this message.
        this.#client = null;
        client.end(true);
        this.#listener.broker(
          "offline",
          `The broker at ${target.ws_url} refused the login of '${target.username}' (${error.message}). Fix the username or password in Settings → Connection.`,
        );
      }
    });
    client.on("message", (topic, payload) => {
      if (client !== this.#client) return;
      const parts = sleeveTopicParts(topic);
      if (parts === null) return;
      const [sleeveId, name] = parts;
      const text = this.#decoder.decode(payload);
      const chosen = sleeveId === this.#target?.sleeve_id;
      if (name === "status") {
        if (text.trim() === "") this.#statuses.delete(sleeveId);
        else this.#statuses.set(sleeveId, text);
        this.#listener.sleeveStatus(sleeveId, text);
        if (chosen) this.#listener.status(text);
      } else if (!chosen) {
        return; // the sleeve chosen before: its last messages, in flight while unsubscribing
      } else if (name === "actuators") this.#listener.actuators(text);
      else if (name === "events") this.#listener.event(text);
    });
  }

  /** Another sleeve on this connection: its actuators and events instead of the old one's. */
  #chooseSleeve(previous: string, target: SenderTarget): void {
    this.#target = target;
    const client = this.#client;
    if (previous === target.sleeve_id || client === null) return;
    // Offline, nothing is said: the connect handler subscribes for the sleeve chosen by then.
    if (!client.connected) return;
    client.unsubscribe(ownTopics(previous));
    client.subscribe(subscriptions(ownTopics(target.sleeve_id)));
    this.#sessionSleeve = target.sleeve_id;
    const status = this.#statuses.get(target.sleeve_id);
    if (status !== undefined) this.#listener.status(status);
  }

  /** Queues a stroke for the chosen sleeve and sends it now if the broker is connected. */
  send(stroke: Stroke): void {
    if (this.#target === null) throw new Error("send before connect");
    this.#outbox.add({ stroke, sleeveId: this.#target.sleeve_id });
    this.#flush();
  }

  /**
   * Cancels a drawing (or everything: "*") on the sleeve: its strokes still in
   * the outbox are dropped here, and a control message tells the sleeve to stop
   * playing and drop the rest. Returns the unsent strokes dropped (never sent).
   */
  cancel(drawing: string): Stroke[] {
    const sleeveId = this.#target?.sleeve_id;
    if (sleeveId === undefined) return [];
    const dropped = this.#outbox.dropQueued(
      ({ stroke, sleeveId: to }) => to === sleeveId && (drawing === CANCEL_ALL || stroke.drawing === drawing),
    );
    const same = (c: { drawing: string; sleeveId: string }) =>
      c.drawing === drawing && c.sleeveId === sleeveId;
    this.#cancels = [...this.#cancels.filter((c) => !same(c)), { drawing, sleeveId }];
    this.#flush();
    return dropped.map(({ stroke }) => stroke);
  }

  /** The timing policy for strokes drawn while the broker is out of reach. */
  setLateLimit(limitMs: number | null): void {
    this.#lateLimitMs = limitMs;
  }

  stop(): void {
    this.#close();
  }

  #close(): void {
    const client = this.#client;
    this.#client = null;
    client?.end(true);
  }

  #flush(): void {
    const client = this.#client;
    const target = this.#target;
    if (client !== null && target !== null && client.connected) {
      const limit = this.#lateLimitMs;
      if (limit !== null) {
        const now = performance.now();
        const late = this.#outbox.dropQueued((_item, entry) => now - entry.added_ms > limit);
        if (late.length > 0) this.#listener.late(late.map((item) => item.stroke));
      }
      for (const cancel of this.#cancels) {
        // QoS 1 as strokes: published in order, ahead of what is queued now.
        const topic = controlTopic(cancel.sleeveId);
        client.publish(topic, formatControl(cancel.drawing), { qos: 1 }, (error) => {
          if (client === this.#client && !error) this.#cancels = this.#cancels.filter((c) => c !== cancel);
        });
      }
      for (const entry of this.#outbox.takeQueued()) {
        const message = this.#format(entry.item, target);
        if (message instanceof StrokeError) {
          this.#outbox.ack(entry.id);
          this.#listener.refused(entry.item.stroke, message);
          continue;
        }
        client.publish(message.topic, message.payload, { qos: 1 }, (error) => {
          // A replaced connection's late callbacks must not touch strokes the new one carries.
          if (client !== this.#client) return;
          if (error) this.#outbox.fail(entry.id);
          else {
            this.#outbox.ack(entry.id);
            this.#listener.acked(entry.item.stroke);
          }
          this.#listener.unsent(this.#outbox.size);
        });
      }
    }
    this.#listener.unsent(this.#outbox.size);
  }

  #format(
    { stroke, sleeveId }: Addressed,
    target: SenderTarget,
  ): { topic: string; payload: string } | StrokeError {
    try {
      if (target.protocol === "legacy") {
        return { topic: target.legacy_topic, payload: formatLegacy(stroke) };
      }
      return {
        topic: strokesTopic(sleeveId),
        payload: formatJson({ ...stroke, sent_at_ms: Date.now() }),
      };
    } catch (error) {
      if (error instanceof StrokeError) return error;
      throw error;
    }
  }
}
