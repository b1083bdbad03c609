/**
 * The page's MQTT side: publishes strokes (QoS 1) and listens to the sleeve's
 * telemetry, over WebSockets with mqtt.js. Strokes wait in an outbox while the
 * broker is out of reach and go out in order when it is back; one leaves the
 * outbox only on the broker's PUBACK, so the count of unsent strokes shown is
 * honest. `sent_at_ms` is stamped when a stroke actually goes out.
 */
import mqtt, { type IClientOptions, type MqttClient } from "mqtt";
import { CANCEL_ALL, formatControl } from "../control";
import { Outbox } from "../outbox";
import { formatJson, formatLegacy, StrokeError, type Stroke } from "../protocol";
import { controlTopic, strokesTopic, telemetryTopic } from "./topics";

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
  status(payload: string): void;
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

export class StrokeSender {
  readonly #listener: SenderListener;
  readonly #outbox = new Outbox<Stroke>();
  readonly #decoder = new TextDecoder();
  #client: MqttClient | null = null;
  #target: SenderTarget | null = null;
  /** Cancels not yet acknowledged by the broker, sent before any stroke when it is back. */
  #cancels: string[] = [];
  /** Strokes not sent within this many ms are dropped; null: they go out whenever possible. */
  #lateLimitMs: number | null = null;

  constructor(listener: SenderListener) {
    this.#listener = listener;
  }

  get unsent(): number {
    return this.#outbox.size;
  }

  /** (Re)connects to `target`. Strokes in flight on the old connection are sent again. */
  connect(target: SenderTarget): void {
    this.#close();
    this.#target = target;
    this.#outbox.requeueInFlight();
    const options: IClientOptions = {
      username: target.username,
      password: target.password,
      clientId: `feelmysign-web-${Math.random().toString(16).slice(2, 10)}`,
      clean: true,
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
    client.on("connect", () => {
      if (client !== this.#client) return;
      this.#listener.broker(
        "connected",
        `Connected to ${target.ws_url} as ${target.username || "anonymous"}`,
      );
      const topics = (["status", "actuators", "events"] as const).map((name) =>
        telemetryTopic(target.sleeve_id, name),
      );
      client.subscribe(topics, { qos: 0 }, (error) => {
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
      const text = this.#decoder.decode(payload);
      if (topic.endsWith("/status")) this.#listener.status(text);
      else if (topic.endsWith("/actuators")) this.#listener.actuators(text);
      else if (topic.endsWith("/events")) this.#listener.event(text);
    });
  }

  /** Queues a stroke and sends it now if the broker is connected. */
  send(stroke: Stroke): void {
    this.#outbox.add(stroke);
    this.#flush();
  }

  /**
   * Cancels a drawing (or everything: "*") on the sleeve: its strokes still in
   * the outbox are dropped here, and a control message tells the sleeve to stop
   * playing and drop the rest. Returns how many unsent strokes were dropped.
   */
  cancel(drawing: string): number {
    const dropped = this.#outbox.dropQueued((stroke) => drawing === CANCEL_ALL || stroke.drawing === drawing);
    this.#cancels = [...this.#cancels.filter((d) => d !== drawing), drawing];
    this.#flush();
    return dropped.length;
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
        const late = this.#outbox.dropQueued((_stroke, entry) => now - entry.added_ms > limit);
        if (late.length > 0) this.#listener.late(late);
      }
      for (const drawing of this.#cancels) {
        // QoS 1 as strokes: published in order, ahead of what is queued now.
        client.publish(controlTopic(target.sleeve_id), formatControl(drawing), { qos: 1 }, (error) => {
          if (client === this.#client && !error) this.#cancels = this.#cancels.filter((d) => d !== drawing);
        });
      }
      for (const entry of this.#outbox.takeQueued()) {
        const message = this.#format(entry.item, target);
        if (message instanceof StrokeError) {
          this.#outbox.ack(entry.id);
          this.#listener.refused(entry.item, message);
          continue;
        }
        client.publish(message.topic, message.payload, { qos: 1 }, (error) => {
          // A replaced connection's late callbacks must not touch strokes the new one carries.
          if (client !== this.#client) return;
          if (error) this.#outbox.fail(entry.id);
          else {
            this.#outbox.ack(entry.id);
            this.#listener.acked(entry.item);
          }
          this.#listener.unsent(this.#outbox.size);
        });
      }
    }
    this.#listener.unsent(this.#outbox.size);
  }

  #format(stroke: Stroke, target: SenderTarget): { topic: string; payload: string } | StrokeError {
    try {
      if (target.protocol === "legacy") {
        return { topic: target.legacy_topic, payload: formatLegacy(stroke) };
      }
      return {
        topic: strokesTopic(target.sleeve_id),
        payload: formatJson({ ...stroke, sent_at_ms: Date.now() }),
      };
    } catch (error) {
      if (error instanceof StrokeError) return error;
      throw error;
    }
  }
}
