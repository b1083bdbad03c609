/**
 * What the browser tests run against, all on 127.0.0.1 and all stopped by the
 * tests: a real Mosquitto started by `feelmysign broker`, a tiny static server
 * for the built page and its /config.json, Debian's Chromium driven by
 * playwright-core with a fresh profile, and an MQTT client playing the sleeve.
 */
import { spawn, type ChildProcess } from "node:child_process";
import { existsSync, mkdtempSync, readFileSync, rmSync } from "node:fs";
import { createServer, type Server } from "node:http";
import type { AddressInfo } from "node:net";
import { tmpdir } from "node:os";
import { extname, join, normalize, resolve, sep } from "node:path";
import { fileURLToPath } from "node:url";
import mqtt, { type MqttClient } from "mqtt";
import { chromium, type BrowserContext } from "playwright-core";

export const WEB_DIR = fileURLToPath(new URL("..", import.meta.url));
export const REPO_DIR = resolve(WEB_DIR, "..");
export const DIST_DIR = join(WEB_DIR, "dist");
export const RESULTS_DIR = join(WEB_DIR, "test-results");
export const FEELMYSIGN = process.env["FEELMYSIGN_BIN"] ?? join(REPO_DIR, ".venv", "bin", "feelmysign");
export const CHROMIUM = process.env["CHROMIUM_BIN"] ?? "/usr/bin/chromium";
export const SLEEVE_ID = "sleeve1";

// Generous: on a loaded two-core machine the Python start-up alone can take half a minute.
const BROKER_READY_TIMEOUT_MS = 60_000;
const STOP_TIMEOUT_MS = 5_000;

export interface Credentials {
  mqtt_url: string;
  ws_url: string;
  sleeve: { id: string; username: string; password: string };
  sender: { username: string; password: string };
}

export function tempDir(prefix: string): string {
  return mkdtempSync(join(tmpdir(), `feelmysign-${prefix}-`));
}

export function checkPrerequisites(): void {
  const missing: string[] = [];
  if (!existsSync(join(DIST_DIR, "index.html")))
    missing.push(`${DIST_DIR}/index.html (run 'make web-build')`);
  if (!existsSync(FEELMYSIGN)) missing.push(`${FEELMYSIGN} (run 'make' to set up the Python venv)`);
  if (!existsSync(CHROMIUM)) missing.push(`${CHROMIUM} (run 'make system' to install Debian's chromium)`);
  if (missing.length > 0) throw new Error(`The browser tests need: ${missing.join("; ")}`);
}

// ---- the broker ----------------------------------------------------------------------------

export class Broker {
  readonly stateDir: string;
  readonly #process: ChildProcess;
  readonly #exited: Promise<number | null>;
  credentials!: Credentials;

  private constructor(stateDir: string, child: ChildProcess) {
    this.stateDir = stateDir;
    this.#process = child;
    this.#exited = new Promise((done) => child.once("exit", (code) => done(code)));
  }

  /** Starts `feelmysign broker` and waits for its "Ready." line. Ports 0 pick free ones. */
  static async start(
    stateDir: string,
    ports: { port: number; wsPort: number } = { port: 0, wsPort: 0 },
  ): Promise<Broker> {
    const child = spawn(
      FEELMYSIGN,
      [
        "broker",
        "--state-dir",
        stateDir,
        "--port",
        String(ports.port),
        "--ws-port",
        String(ports.wsPort),
        "--sleeve-id",
        SLEEVE_ID,
      ],
      { stdio: ["ignore", "pipe", "pipe"] },
    );
    const broker = new Broker(stateDir, child);
    let output = "";
    await new Promise<void>((ready, fail) => {
      const timer = setTimeout(
        () =>
          fail(new Error(`feelmysign broker was not ready after ${BROKER_READY_TIMEOUT_MS} ms:\n${output}`)),
        BROKER_READY_TIMEOUT_MS,
      );
      const collect = (chunk: Buffer) => {
        output += chunk.toString();
        if (/^Ready\./m.test(output)) {
          clearTimeout(timer);
          ready();
        }
      };
      child.stdout!.on("data", collect);
      child.stderr!.on("data", collect);
      child.once("exit", (code) => {
        clearTimeout(timer);
        fail(new Error(`feelmysign broker exited with ${code} before it was ready:\n${output}`));
      });
    });
    broker.credentials = JSON.parse(readFileSync(join(stateDir, "credentials.json"), "utf8")) as Credentials;
    return broker;
  }

  /** SIGINT, as Ctrl-C: the broker stops Mosquitto and exits. */
  async stop(): Promise<void> {
    if (this.#process.exitCode !== null || this.#process.signalCode !== null) return;
    this.#process.kill("SIGINT");
    const timeout = new Promise<"timeout">((done) => setTimeout(() => done("timeout"), STOP_TIMEOUT_MS));
    if ((await Promise.race([this.#exited, timeout])) === "timeout") {
      this.#process.kill("SIGKILL");
      await this.#exited;
    }
  }
}

export function portOf(url: string): number {
  return Number(new URL(url).port);
}

// ---- the page's server ---------------------------------------------------------------------

const CONTENT_TYPES: Record<string, string> = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".css": "text/css; charset=utf-8",
  ".json": "application/json",
  ".svg": "image/svg+xml",
};

/** Serves dist/ and a /config.json (or none, when `config` is null) on 127.0.0.1. */
export async function serveDist(config: object | null): Promise<{ url: string; stop: () => Promise<void> }> {
  const server: Server = createServer((request, response) => {
    const path = decodeURIComponent(new URL(request.url ?? "/", "http://127.0.0.1").pathname);
    if (path === "/config.json" && config !== null) {
      response.writeHead(200, { "content-type": "application/json", "cache-control": "no-store" });
      response.end(JSON.stringify(config));
      return;
    }
    const file = normalize(join(DIST_DIR, path === "/" ? "index.html" : path));
    if (!file.startsWith(DIST_DIR + sep) || !existsSync(file)) {
      response.writeHead(404, { "content-type": "text/plain" });
      response.end("not found");
      return;
    }
    response.writeHead(200, { "content-type": CONTENT_TYPES[extname(file)] ?? "application/octet-stream" });
    response.end(readFileSync(file));
  });
  await new Promise<void>((listening) => server.listen(0, "127.0.0.1", listening));
  const { port } = server.address() as AddressInfo;
  return {
    url: `http://127.0.0.1:${port}/`,
    stop: () =>
      new Promise<void>((closed) => {
        server.closeAllConnections();
        server.close(() => closed());
      }),
  };
}

export function pageConfig(credentials: Credentials): object {
  return {
    ws_url: credentials.ws_url,
    sleeve_id: SLEEVE_ID,
    username: credentials.sender.username,
    password: credentials.sender.password,
  };
}

// ---- the browser ---------------------------------------------------------------------------

export const CHROMIUM_ARGS = [
  "--headless",
  "--no-sandbox",
  "--disable-gpu",
  "--disable-background-networking",
  "--disable-quic",
  "--no-first-run",
  "--disable-component-update",
  "--disable-sync",
];

export interface BrowserOptions {
  viewport: { width: number; height: number };
  deviceScaleFactor?: number;
  hasTouch?: boolean;
  isMobile?: boolean;
  /** The browser's locale (e.g. "en-US", whose own clock says "10:11 PM"). */
  locale?: string;
  /** Another Chromium, e.g. a wrapper that starts it in a network namespace. */
  executablePath?: string;
  /** Flags beyond the usual ones, e.g. the one certificate to trust. */
  extraArgs?: string[];
}

/** Chromium with a fresh profile; `close` also removes the profile. */
export async function launchBrowser(
  options: BrowserOptions,
): Promise<{ context: BrowserContext; close: () => Promise<void> }> {
  const profile = tempDir("chromium");
  const { executablePath, extraArgs, ...contextOptions } = options;
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: executablePath ?? CHROMIUM,
    headless: true,
    args: [...CHROMIUM_ARGS, ...(extraArgs ?? [])],
    acceptDownloads: true,
    ...contextOptions,
  });
  return {
    context,
    close: async () => {
      await context.close();
      rmSync(profile, { recursive: true, force: true });
    },
  };
}

// ---- feelmysign up ----------------------------------------------------------------------------

const UP_READY_TIMEOUT_MS = 90_000;

/**
 * Resolves with the first match of `pattern` in what `child` prints (stdout and stderr
 * together); fails, with the output, if it exits first or nothing matches in `timeoutMs`.
 */
export function collectUntil(
  child: ChildProcess,
  pattern: RegExp,
  what: string,
  timeoutMs: number,
): Promise<RegExpExecArray> {
  let output = "";
  return new Promise((ready, fail) => {
    const timer = setTimeout(
      () => fail(new Error(`${what}: nothing matched ${pattern} in ${timeoutMs} ms:\n${output}`)),
      timeoutMs,
    );
    const collect = (chunk: Buffer) => {
      output += chunk.toString();
      const match = pattern.exec(output);
      if (match) {
        clearTimeout(timer);
        ready(match);
      }
    };
    child.stdout?.on("data", collect);
    child.stderr?.on("data", collect);
    child.once("exit", (code) => {
      clearTimeout(timer);
      fail(new Error(`${what} exited with ${code}:\n${output}`));
    });
  });
}

/**
 * Starts `feelmysign up` on free ports and resolves with its page URL once it prints it
 * (`url`: the first group of another pattern, e.g. the study's page); `detached`: in its
 * own process group, so that `stopChild(..., { group: true })` takes its broker too.
 */
export async function startUp(
  stateDir: string,
  extraArgs: readonly string[] = [],
  options: { url?: RegExp; detached?: boolean; timeoutMs?: number } = {},
): Promise<{ child: ChildProcess; url: string; match: RegExpExecArray }> {
  const child = spawn(
    FEELMYSIGN,
    ["up", "--state-dir", stateDir, "--http-port", "0", "--port", "0", "--ws-port", "0", ...extraArgs],
    { stdio: ["ignore", "pipe", "pipe"], detached: options.detached ?? false },
  );
  const url = options.url ?? /(http:\/\/127\.0\.0\.1:\d+\/)/;
  // The URL, then the last line it prints once everything runs.
  const ready = new RegExp(`${url.source}[\\s\\S]*Ctrl-C`);
  const match = await collectUntil(child, ready, "feelmysign up", options.timeoutMs ?? UP_READY_TIMEOUT_MS);
  return { child, url: match[1]!, match };
}

/**
 * Stops `child` (SIGINT, or `signal`; to its whole process group with `group`), SIGKILL
 * after `killAfterMs` unless null; resolves once it has exited.
 */
export async function stopChild(
  child: ChildProcess,
  options: { signal?: NodeJS.Signals; group?: boolean; killAfterMs?: number | null } = {},
): Promise<void> {
  if (child.exitCode !== null || child.signalCode !== null) return;
  const exited = new Promise((done) => child.once("exit", done));
  const send = (signal: NodeJS.Signals) =>
    options.group ? process.kill(-child.pid!, signal) : child.kill(signal);
  send(options.signal ?? "SIGINT");
  const killAfterMs = options.killAfterMs === undefined ? 10_000 : options.killAfterMs;
  const timer = killAfterMs === null ? undefined : setTimeout(() => send("SIGKILL"), killAfterMs);
  await exited;
  clearTimeout(timer);
}

// ---- the sleeve, played by the test ----------------------------------------------------------

export interface Received {
  topic: string;
  payload: string;
}

export class FakeSleeve {
  readonly client: MqttClient;
  readonly sleeveId: string;
  readonly received: Received[] = [];
  #waiters: (() => void)[] = [];

  private constructor(client: MqttClient, sleeveId: string) {
    this.client = client;
    this.sleeveId = sleeveId;
    client.on("message", (topic, payload) => {
      this.received.push({ topic, payload: payload.toString("utf8") });
      for (const wake of this.#waiters.splice(0)) wake();
    });
  }

  /** Logs in as the sleeve user and subscribes to its strokes (QoS 1); `sleeveId`: another sleeve's. */
  static async connect(
    credentials: Credentials,
    options: { clientId?: string; clean?: boolean; sleeveId?: string } = {},
  ): Promise<FakeSleeve> {
    const client = await mqtt.connectAsync(credentials.mqtt_url, {
      username: credentials.sleeve.username,
      password: credentials.sleeve.password,
      clientId: options.clientId ?? `test-sleeve-${process.pid}-${Date.now()}`,
      clean: options.clean ?? true,
      reconnectPeriod: 200,
    });
    const sleeve = new FakeSleeve(client, options.sleeveId ?? SLEEVE_ID);
    await client.subscribeAsync(`feelmysign/${sleeve.sleeveId}/strokes`, { qos: 1 });
    return sleeve;
  }

  strokes(): Record<string, unknown>[] {
    return this.received
      .filter((message) => message.topic.endsWith("/strokes"))
      .map((message) => JSON.parse(message.payload) as Record<string, unknown>);
  }

  /** Resolves when `count` strokes have arrived; fails after `timeoutMs` saying how many did. */
  async waitForStrokes(count: number, timeoutMs = 30_000): Promise<Record<string, unknown>[]> {
    const deadline = Date.now() + timeoutMs;
    while (this.strokes().length < count) {
      const left = deadline - Date.now();
      if (left <= 0) {
        throw new Error(
          `expected ${count} strokes, got ${this.strokes().length}: ${JSON.stringify(this.strokes())}`,
        );
      }
      await new Promise<void>((wake) => {
        const timer = setTimeout(wake, left);
        this.#waiters.push(() => {
          clearTimeout(timer);
          wake();
        });
      });
    }
    return this.strokes();
  }

  async publish(subtopic: "status" | "actuators" | "events", payload: object, retain = false): Promise<void> {
    await this.client.publishAsync(`feelmysign/${this.sleeveId}/${subtopic}`, JSON.stringify(payload), {
      qos: 1,
      retain,
    });
  }

  async close(): Promise<void> {
    await this.client.endAsync(true);
  }
}

/** Everything the sleeve says on its events topic, read with the sender's account. */
export class EventWatcher {
  readonly events: Record<string, unknown>[] = [];
  readonly client: MqttClient;

  private constructor(client: MqttClient) {
    this.client = client;
    client.on("message", (_topic, payload) => this.events.push(JSON.parse(payload.toString("utf8"))));
  }

  static async connect(credentials: Credentials): Promise<EventWatcher> {
    const client = await mqtt.connectAsync(credentials.mqtt_url, {
      username: credentials.sender.username,
      password: credentials.sender.password,
      clientId: `test-events-${process.pid}-${Date.now()}`,
      // A persistent session, as the page's and up's: events the sleeve publishes while this
      // reader reconnects after a broker restart are kept for it, not lost before it subscribes.
      clean: false,
    });
    const watcher = new EventWatcher(client);
    await client.subscribeAsync(`feelmysign/${credentials.sleeve.id}/events`, { qos: 1 });
    return watcher;
  }

  async waitFor(
    what: string,
    test: (events: Record<string, unknown>[]) => boolean,
    timeoutMs = 30_000,
  ): Promise<Record<string, unknown>[]> {
    const deadline = Date.now() + timeoutMs;
    while (!test(this.events)) {
      if (Date.now() > deadline)
        throw new Error(`no ${what} after ${timeoutMs} ms: ${JSON.stringify(this.events.slice(-5))}`);
      await new Promise((wake) => setTimeout(wake, 20));
    }
    return this.events;
  }

  of(drawing: string, type?: string): Record<string, unknown>[] {
    return this.events.filter((e) => e["drawing"] === drawing && (type === undefined || e["type"] === type));
  }
}
