/**
 * Two devices on a LAN, with TLS: `feelmysign up --lan` serves the page over HTTPS on
 * a non-loopback address; Chromium (in its own network namespace when run as root, so
 * it reaches the page as a phone on the LAN would) trusts exactly that certificate,
 * opens the printed URL, picks the sleeve and draws; a sleeve started elsewhere from a
 * join token (`broker add-sleeve`) plays the strokes. Without the certificate, the
 * page is refused.
 */
import { spawn, execFileSync } from "node:child_process";
import { createHash, X509Certificate } from "node:crypto";
import { chmodSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import {
  checkPrerequisites,
  CHROMIUM,
  collectUntil,
  FEELMYSIGN,
  launchBrowser,
  stopChild,
  tempDir,
} from "./harness";
import { screenshot, waitForData } from "./page";
import { drawSquare } from "./strokes";

const READY_TIMEOUT_MS = 40_000;
const SLEEVE_ID = "arm2";

interface Network {
  host: string;
  /** Runs a program inside the other "device" (empty: this machine). */
  prefix: string[];
  cleanup: () => void;
}

/** A network namespace joined by a veth pair when root; else this machine's LAN address. */
function network(): Network {
  const root = process.getuid?.() === 0;
  if (root) {
    const id = process.pid;
    const ns = `fmsw-${id}`;
    const [hostEnd, guestEnd] = [`fwh${id}`.slice(0, 15), `fwg${id}`.slice(0, 15)];
    const subnet = 16 + (id % 200);
    const [host, guest] = [`10.198.${subnet}.1`, `10.198.${subnet}.2`];
    const ip = (...args: string[]) => execFileSync("ip", args, { stdio: "pipe" });
    const cleanup = () => {
      for (const args of [
        ["link", "del", hostEnd],
        ["netns", "del", ns],
      ]) {
        try {
          ip(...args);
        } catch {
          // already gone
        }
      }
    };
    try {
      ip("netns", "add", ns);
      ip("link", "add", hostEnd, "type", "veth", "peer", "name", guestEnd);
      ip("link", "set", guestEnd, "netns", ns);
      ip("addr", "add", `${host}/24`, "dev", hostEnd);
      ip("link", "set", hostEnd, "up");
      ip("-n", ns, "addr", "add", `${guest}/24`, "dev", guestEnd);
      ip("-n", ns, "link", "set", guestEnd, "up");
      ip("-n", ns, "link", "set", "lo", "up");
    } catch (error) {
      cleanup();
      throw error;
    }
    return { host, prefix: ["ip", "netns", "exec", ns], cleanup };
  }
  const route = execFileSync("ip", ["-4", "route", "get", "198.51.100.1"], { encoding: "utf8" });
  const host = /\bsrc (\S+)/.exec(route)?.[1];
  if (host === undefined) throw new Error(`no LAN address on this machine: ${route}`);
  return { host, prefix: [], cleanup: () => {} };
}

/** base64 SHA-256 of the server certificate's public key: what Chromium is told to trust. */
function spkiHash(serverPem: string): string {
  const spki = new X509Certificate(serverPem).publicKey.export({ type: "spki", format: "der" });
  return createHash("sha256").update(spki).digest("base64");
}

describe("a phone and a sleeve on the LAN, over TLS", () => {
  const cleanups: (() => Promise<void> | void)[] = [];
  let net: Network;
  let page: Page;
  let pageUrl: string;
  let stateDir: string;
  let chromiumInNet: string;

  beforeAll(async () => {
    checkPrerequisites();
    net = network();
    cleanups.push(net.cleanup);
    stateDir = tempDir("lan");
    cleanups.push(() => rmSync(stateDir, { recursive: true, force: true }));
    const up = spawn(
      FEELMYSIGN,
      ["up", "--state-dir", stateDir, "--host", net.host, "--http-port", "0", "--port", "0"].concat([
        "--ws-port",
        "0",
        "--tls-port",
        "0",
      ]),
      { stdio: ["ignore", "pipe", "pipe"] },
    );
    cleanups.push(() => stopChild(up));
    const printed = await collectUntil(
      up,
      /Draw here: +(https:\/\/\S+)[\s\S]*Ctrl-C/,
      "feelmysign up",
      READY_TIMEOUT_MS,
    );
    pageUrl = printed[1]!;
    const token = execFileSync(FEELMYSIGN, ["broker", "--state-dir", stateDir, "add-sleeve", SLEEVE_ID], {
      encoding: "utf8",
    }).trim();
    const piState = tempDir("pi");
    cleanups.push(() => rmSync(piState, { recursive: true, force: true }));
    const [command, ...args] = [...net.prefix, FEELMYSIGN, "sleeve", "--join", token];
    const sleeve = spawn(command!, args, {
      stdio: ["ignore", "pipe", "pipe"],
      env: { ...process.env, XDG_STATE_HOME: piState },
    });
    cleanups.push(() => stopChild(sleeve));
    await collectUntil(sleeve, /connected to mqtts:\/\//, "the joined sleeve", READY_TIMEOUT_MS);
    chromiumInNet = join(piState, "chromium");
    writeFileSync(chromiumInNet, `#!/bin/sh\nexec ${[...net.prefix, CHROMIUM].join(" ")} "$@"\n`);
    chmodSync(chromiumInNet, 0o755);
  });

  afterAll(async () => {
    for (const cleanup of cleanups.reverse()) await cleanup();
  });

  it("refuses the page to a browser that does not trust its certificate", async () => {
    const browser = await launchBrowser({
      viewport: { width: 800, height: 600 },
      executablePath: chromiumInNet,
    });
    try {
      const untrusting = await browser.context.newPage();
      await expect(untrusting.goto(pageUrl)).rejects.toThrow(/ERR_CERT_AUTHORITY_INVALID/);
    } finally {
      await browser.close();
    }
  });

  it("draws on the page from the printed URL; the sleeve joined by token plays every stroke", async () => {
    const server = readFileSync(join(stateDir, "tls", "server.pem"), "utf8");
    const browser = await launchBrowser({
      viewport: { width: 1280, height: 800 },
      executablePath: chromiumInNet,
      extraArgs: [`--ignore-certificate-errors-spki-list=${spkiHash(server)}`],
    });
    cleanups.push(browser.close);
    page = await browser.context.newPage();
    await page.goto(pageUrl);
    expect(new URL(page.url()).search).toBe(""); // the key went into a cookie
    await waitForData(page, '[data-testid="broker-status"]', "state", "connected", 30_000);
    await page.locator('[data-testid="settings-button"]').click();
    await page.locator('[data-testid="setting-sleeve_id"]').fill(SLEEVE_ID);
    await page.locator('[data-testid="settings-save"]').click();
    await waitForData(page, '[data-testid="sleeve-status"]', "state", "online", 30_000);
    // Each side 400 ms by the clock: only its strokes being played matters here, and a step a
    // frame (hundreds of round trips to the browser) took a minute on a loaded machine.
    const { sent } = await drawSquare(page, { legMs: 400 });
    await waitForData(page, '[data-testid="played-summary"]', "played", String(sent), 60_000);
    await screenshot(page, "lan-played");
  });
});
