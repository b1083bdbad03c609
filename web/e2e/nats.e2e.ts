/**
 * feelmysign on a real 3-node NATS cluster (deploy/nats/node.conf, JetStream and its
 * MQTT listeners): the sleeve on node a (failing over to b and c), the CLI sender on
 * b, and the page in Chromium on c's MQTT-over-WebSocket listener. Node a is killed
 * while the CLI's drawing plays: the sleeve moves to another node, and every stroke of
 * that drawing is played exactly once (the sleeve runs with the pace limits docs/deploy.md
 * gives for a cluster, so the strokes JetStream held back while it elected new leaders
 * play late rather than being skipped); the page's drawing then plays in full.
 */
import { spawn, type ChildProcess } from "node:child_process";
import { rmSync } from "node:fs";
import { join } from "node:path";
import mqtt, { type MqttClient } from "mqtt";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import {
  checkPrerequisites,
  FEELMYSIGN,
  launchBrowser,
  REPO_DIR,
  serveDist,
  SLEEVE_ID,
  stopChild,
  tempDir,
  type Credentials,
} from "./harness";
import { screenshot, waitForData } from "./page";
import { drawSquare } from "./strokes";

const PYTHON = join(REPO_DIR, ".venv", "bin", "python");
/** Longer than the cluster's own limit for settling (120 s), so that its error, with the logs, is what fails. */
const READY_TIMEOUT_MS = 150_000;
/** The sleeve's pace limits on a cluster (docs/deploy.md): a failover may hold strokes ~10 s. */
const CLUSTER_PACE = ["--max-lag-ms", "30000", "--max-age-ms", "60000"];

interface Cluster {
  nodes: { name: string; mqtt_url: string; ws_url: string }[];
  credentials: Credentials;
}

function output(child: ChildProcess): { text: () => string; until: (pattern: RegExp) => Promise<string> } {
  let text = "";
  const waiters: (() => void)[] = [];
  const collect = (chunk: Buffer) => {
    text += chunk.toString();
    for (const wake of waiters.splice(0)) wake();
  };
  child.stdout?.on("data", collect);
  child.stderr?.on("data", collect);
  return {
    text: () => text,
    until: async (pattern) => {
      const deadline = Date.now() + READY_TIMEOUT_MS;
      while (!pattern.test(text)) {
        if (Date.now() > deadline) throw new Error(`nothing matched ${pattern}:\n${text}`);
        if (child.exitCode !== null) throw new Error(`exited with ${child.exitCode}:\n${text}`);
        await new Promise<void>((wake) => {
          waiters.push(wake);
          setTimeout(wake, 500);
        });
      }
      return text;
    },
  };
}

/**
 * The sleeve's strokes by drawing and seq: played (a QoS 1 repeat is the same payload,
 * a second play a different one), or refused for a reason other than being a duplicate.
 */
class PlayedEvents {
  readonly byKey = new Map<string, Set<string>>();
  readonly refused = new Map<string, string>();
  constructor(readonly client: MqttClient) {
    client.on("message", (_topic, payload) => {
      const text = payload.toString("utf8");
      const event = JSON.parse(text) as { type: string; reason?: string; drawing: string; seq: number };
      const key = `${event.drawing}/${event.seq}`;
      if (event.type === "rejected" && event.reason !== "duplicate")
        this.refused.set(key, event.reason ?? "");
      if (event.type !== "played" && event.type !== "adjusted") return;
      this.byKey.set(key, (this.byKey.get(key) ?? new Set()).add(text));
    });
  }
  /** Strokes of `drawing` played. */
  count(drawing: string): number {
    return [...this.byKey.keys()].filter((key) => key.startsWith(`${drawing}/`)).length;
  }
  async waitFor(drawing: string, count: number, timeoutMs = 60_000): Promise<void> {
    const deadline = Date.now() + timeoutMs;
    while (this.count(drawing) < count) {
      if (Date.now() > deadline) throw new Error(`${this.count(drawing)} of ${count} played for ${drawing}`);
      await new Promise((wake) => setTimeout(wake, 100));
    }
  }
}

describe("on a 3-node NATS cluster: sleeve on a, CLI on b, page on c; a dies", () => {
  const cleanups: (() => Promise<void> | void)[] = [];
  let cluster: Cluster;
  let runner: ChildProcess;
  let runnerOut: ReturnType<typeof output>;
  let sleeveOut: ReturnType<typeof output>;
  let events: PlayedEvents;
  let page: Page;

  beforeAll(async () => {
    checkPrerequisites();
    const dir = tempDir("nats");
    cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
    runner = spawn(PYTHON, ["-m", "feelmysign.broker.nats_cluster", dir], {
      stdio: ["ignore", "pipe", "pipe"],
    });
    cleanups.push(() => stopChild(runner, { killAfterMs: 15_000 }));
    runnerOut = output(runner);
    const text = await runnerOut.until(/^Ready\./m);
    cluster = JSON.parse(text.split("\n").find((line) => line.startsWith("{"))!) as Cluster;
    const [a, b, c] = cluster.nodes;
    const sleeve = spawn(
      FEELMYSIGN,
      ["sleeve", "--broker", cluster.nodes.map((n) => n.mqtt_url).join(","), "--id", SLEEVE_ID].concat(
        ["--username", cluster.credentials.sleeve.username],
        CLUSTER_PACE,
      ),
      {
        stdio: ["ignore", "pipe", "pipe"],
        env: { ...process.env, FEELMYSIGN_PASSWORD: cluster.credentials.sleeve.password },
      },
    );
    cleanups.push(() => stopChild(sleeve, { killAfterMs: 15_000 }));
    sleeveOut = output(sleeve);
    await sleeveOut.until(new RegExp(`connected to ${a!.mqtt_url}`));
    const watcher = await mqtt.connectAsync(b!.mqtt_url, {
      username: cluster.credentials.sender.username,
      password: cluster.credentials.sender.password,
      protocolVersion: 4,
    });
    cleanups.push(() => watcher.endAsync(true));
    events = new PlayedEvents(watcher);
    await watcher.subscribeAsync(`feelmysign/${SLEEVE_ID}/events`, { qos: 1 });
    const server = await serveDist({
      ws_url: c!.ws_url,
      sleeve_id: SLEEVE_ID,
      username: cluster.credentials.sender.username,
      password: cluster.credentials.sender.password,
    });
    cleanups.push(server.stop);
    const browser = await launchBrowser({ viewport: { width: 1280, height: 800 } });
    cleanups.push(browser.close);
    page = await browser.context.newPage();
    await page.goto(server.url);
    await waitForData(page, '[data-testid="broker-status"]', "state", "connected", 30_000);
    await waitForData(page, '[data-testid="sleeve-status"]', "state", "online", 30_000);
  });

  afterAll(async () => {
    for (const cleanup of cleanups.reverse()) await cleanup();
  });

  // Longer than the others: a failover on a loaded machine, waits of 60 s that normally take a few.
  it(
    "plays every stroke of the CLI's drawing cut by node a's death exactly once; the page's plays",
    { timeout: 300_000 },
    async () => {
      const b = cluster.nodes[1]!;
      const send = spawn(
        FEELMYSIGN,
        [
          "send",
          "--broker",
          b.mqtt_url,
          "--id",
          SLEEVE_ID,
          "--username",
          cluster.credentials.sender.username,
          // The test reads the sleeve's events itself; send's own wait for them (on node b) can
          // miss some across the failover, and is not what this test is about.
        ].concat(["--shape", "circle", "--segments", "10", "--json", "--timeout-s", "40", "--no-wait"]),
        {
          stdio: ["ignore", "pipe", "pipe"],
          env: { ...process.env, FEELMYSIGN_PASSWORD: cluster.credentials.sender.password },
        },
      );
      const sendOut = output(send);
      const first = await sendOut.until(/drawing[\\":]+([0-9a-f-]{36})/);
      const drawing = /drawing[\\":]+([0-9a-f-]{36})/.exec(first)![1]!;
      await events.waitFor(drawing, 1);
      runner.kill("SIGUSR1"); // node a, the sleeve's, crashes
      await runnerOut.until(/Killed a\./);
      const exit = await new Promise<number | null>((done) => send.once("exit", done));
      expect(exit, sendOut.text()).toBe(0);
      await events.waitFor(drawing, 10);

      // Each side 400 ms by the clock: only its strokes being played matters here, and a step a
      // frame (hundreds of round trips to the browser) took a minute on a loaded machine.
      const { sent } = await drawSquare(page, { legMs: 400 });
      await waitForData(page, '[data-testid="played-summary"]', "played", String(sent), 60_000);
      await screenshot(page, "nats-failover");

      expect(events.count(drawing)).toBe(10);
      for (const [key, payloads] of events.byKey) expect(payloads.size, `${key} played twice`).toBe(1);
      expect([...events.refused], "refused strokes").toEqual([]);
      const moved = cluster.nodes
        .slice(1)
        .some((node) => sleeveOut.text().includes(`connected to ${node.mqtt_url}`));
      expect(moved, sleeveOut.text()).toBe(true);
    },
  );
});
