/**
 * What a browser test file starts in its beforeAll and stops, last started first, in
 * its afterAll: `feelmysign up` in a fresh state directory, Chromium with the page it
 * serves, and whatever else the file adds.
 */
import type { ChildProcess } from "node:child_process";
import { readFileSync, rmSync } from "node:fs";
import { join } from "node:path";
import type { BrowserContext, Page } from "playwright-core";
import {
  Broker,
  checkPrerequisites,
  EventWatcher,
  launchBrowser,
  pageConfig,
  serveDist,
  startUp,
  stopChild,
  tempDir,
  type BrowserOptions,
  type Credentials,
} from "./harness";
import { waitForData } from "./page";

/** A desktop browser window. */
export const DESKTOP: BrowserOptions = { viewport: { width: 1280, height: 800 } };

export interface Up {
  stateDir: string;
  /** The page's URL, as `feelmysign up` printed it. */
  url: string;
  child: ChildProcess;
  /** The broker's URLs and accounts, from the state directory. */
  credentials: Credentials;
}

export class Processes {
  readonly #stops: (() => Promise<void> | void)[] = [];

  /** `stop` runs at the end, before everything added earlier. */
  add(stop: () => Promise<void> | void): void {
    this.#stops.push(stop);
  }

  /** A fresh temporary directory, removed at the end. */
  dir(prefix: string): string {
    const dir = tempDir(prefix);
    this.add(() => rmSync(dir, { recursive: true, force: true }));
    return dir;
  }

  /**
   * Checks the prerequisites, then starts `feelmysign up` (with `args`) in a fresh state
   * directory, once `prepare` has run on it; stopped at the end.
   */
  async up(
    prefix: string,
    options: { args?: readonly string[]; prepare?: (stateDir: string) => Promise<void> } = {},
  ): Promise<Up> {
    checkPrerequisites();
    const stateDir = this.dir(prefix);
    await options.prepare?.(stateDir);
    const { child, url } = await startUp(stateDir, options.args);
    this.add(() => stopChild(child));
    const credentials = JSON.parse(readFileSync(join(stateDir, "credentials.json"), "utf8")) as Credentials;
    return { stateDir, url, child, credentials };
  }

  /**
   * Checks the prerequisites, then starts `feelmysign broker` in a fresh state directory
   * and serves the built page with the broker's config beside it; both stopped at the end.
   */
  async brokerAndPage(prefix = "broker"): Promise<{ broker: Broker; url: string }> {
    checkPrerequisites();
    const broker = await Broker.start(this.dir(prefix));
    this.add(() => broker.stop());
    const server = await serveDist(pageConfig(broker.credentials));
    this.add(server.stop);
    return { broker, url: server.url };
  }

  /** A fresh Chromium (`options`: its window); closed at the end. */
  async browser(options: BrowserOptions = DESKTOP): Promise<BrowserContext> {
    const browser = await launchBrowser(options);
    this.add(browser.close);
    return browser.context;
  }

  /** A fresh Chromium (`options`: its window) with a page opened on `url`; closed at the end. */
  async page(url: string, options: BrowserOptions = DESKTOP): Promise<Page> {
    const page = await (await this.browser(options)).newPage();
    await page.goto(url);
    return page;
  }

  /** A page on `url` in a fresh desktop Chromium (one pixel per CSS pixel), once it is connected and sees the sleeve online. */
  /** The sleeve's events as a sender sees them on `credentials`' broker, closed by `stop()`. */
  async watch(credentials: Credentials): Promise<EventWatcher> {
    const watcher = await EventWatcher.connect(credentials);
    this.add(() => watcher.client.endAsync(true));
    return watcher;
  }

  async onlinePage(url: string): Promise<Page> {
    const page = await this.page(url, { ...DESKTOP, deviceScaleFactor: 1 });
    await waitForData(page, '[data-testid="broker-status"]', "state", "connected");
    await waitForData(page, '[data-testid="sleeve-status"]', "state", "online");
    return page;
  }

  /** Stops everything, last started first. */
  async stop(): Promise<void> {
    for (const stop of this.#stops.splice(0).reverse()) await stop();
  }
}
