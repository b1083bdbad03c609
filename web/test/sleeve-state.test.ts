/** What the page says about the broker and the sleeve, from the sender's news and the clock. */
import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";
import { offlineAdvice, SleeveWatch, STATUS_WAIT_MS, type SleeveStateHost } from "../src/sleeve-state";

type Shown = Parameters<SleeveStateHost["showSleeve"]>[0];

/** A host that keeps the last thing shown of each kind. */
function host(sleeveId = "sleeve1") {
  const seen = {
    id: sleeveId,
    broker: null as string | null,
    sleeve: null as Shown | null,
    notice: null as { text: string | null; level: string } | null,
  };
  const target: SleeveStateHost = {
    sleeveId: () => seen.id,
    offlineAdvice: (detail) => `advice: ${detail ?? "none"}`,
    showBroker: (state) => {
      seen.broker = state;
    },
    showSleeve: (sleeve) => {
      seen.sleeve = sleeve;
    },
    showNotice: (text, level) => {
      seen.notice = { text, level };
    },
  };
  return { seen, target };
}

const ONLINE = JSON.stringify({ online: true, layout: { rows: 3, columns: 4 }, version: "1.2" });
const OFFLINE = JSON.stringify({ online: false });

beforeEach(() => {
  vi.useFakeTimers();
});
afterEach(() => {
  vi.useRealTimers();
});

describe("the sleeve's state", () => {
  it("starts unknown, without a broker, and shows the config's note", () => {
    const { seen, target } = host();
    const watch = new SleeveWatch(target, "No config.json.");
    expect(watch.state).toBe("unknown");
    expect(seen.sleeve).toMatchObject({ state: "unknown", brokerConnected: false });
    expect(seen.sleeve!.caption).toBe("Not connected to the broker: the sleeve cannot be seen.");
    expect(seen.notice).toEqual({ text: "No config.json.", level: "info" });
  });

  it("says none listens when no status came within the wait after connecting", () => {
    const { seen, target } = host();
    const watch = new SleeveWatch(target, null);
    watch.onBroker("connected", null);
    expect(seen.broker).toBe("connected");
    vi.advanceTimersByTime(STATUS_WAIT_MS - 1);
    expect(watch.state).toBe("unknown");
    vi.advanceTimersByTime(1);
    expect(watch.state).toBe("absent");
    expect(seen.notice!.level).toBe("warn");
    expect(seen.notice!.text).toContain("No sleeve listens on id 'sleeve1'");
  });

  it("stays online when the status comes in time", () => {
    const { seen, target } = host();
    const watch = new SleeveWatch(target, null);
    watch.onBroker("connected", null);
    expect(watch.onStatus(ONLINE)).toEqual({ back: true });
    vi.advanceTimersByTime(STATUS_WAIT_MS * 2);
    expect(watch.state).toBe("online");
    expect(watch.status?.layout).toMatchObject({ rows: 3, columns: 4 });
    expect(seen.sleeve).toMatchObject({
      state: "online",
      detail: "Online, 3 × 4 actuators, version 1.2",
      caption: "Sleeve sleeve1 online: 3 × 4 actuators, waiting for strokes.",
    });
    expect(seen.notice).toEqual({ text: null, level: "info" });
    // Online again is not "back".
    expect(watch.onStatus(ONLINE)).toEqual({ back: false });
  });

  it("says the sleeve plays nothing while the wearer paused it or asked not to be disturbed", () => {
    const { seen, target } = host();
    const watch = new SleeveWatch(target, null);
    watch.onBroker("connected", null);
    const withControls = (controls: Record<string, unknown>): string =>
      JSON.stringify({ ...JSON.parse(ONLINE), controls });
    const none = { paused: false, paused_by: null, ceiling: null, do_not_disturb_until_ms: null };
    watch.onStatus(withControls({ ...none, paused: true, paused_by: "button" }));
    expect(seen.sleeve!.caption).toBe(
      "Sleeve sleeve1 online: 3 × 4 actuators, playing nothing. The wearer paused the sleeve.",
    );
    const untilMs = Date.now() + 30 * 60_000; // tomorrow's when the test runs near midnight
    watch.onStatus(withControls({ ...none, do_not_disturb_until_ms: untilMs }));
    expect(seen.sleeve!.caption).toMatch(
      /^Sleeve sleeve1 online: 3 × 4 actuators, playing nothing\. The wearer asked not to be disturbed until (tomorrow at )?\d\d:\d\d\.$/,
    );
    // A "do not disturb" already over holds nothing; resumed, the sleeve waits for strokes.
    watch.onStatus(withControls({ ...none, do_not_disturb_until_ms: Date.now() - 1000 }));
    expect(seen.sleeve!.caption).toBe("Sleeve sleeve1 online: 3 × 4 actuators, waiting for strokes.");
  });

  it("warns of an offline sleeve, and says when it is back", () => {
    const { seen, target } = host();
    const watch = new SleeveWatch(target, null);
    watch.onBroker("connected", null);
    watch.onStatus(ONLINE);
    expect(watch.onStatus(OFFLINE)).toEqual({ back: false });
    expect(seen.notice).toEqual({
      text:
        "Sleeve 'sleeve1' is offline: strokes wait at the broker and play if it is back within its age limit " +
        "(10 s unless set; older ones are refused as stale). If it crashed, a motor it was driving may run " +
        "until it restarts (docs/sleeve-hardware.md: the enable line).",
      level: "warn",
    });
    expect(watch.onStatus(ONLINE)).toEqual({ back: true });
  });

  it("reads an empty status as none listening, and a garbled one as not known", () => {
    const { seen, target } = host();
    const watch = new SleeveWatch(target, null);
    watch.onBroker("connected", null);
    watch.onStatus(ONLINE);
    expect(watch.onStatus("  ")).toBeNull();
    expect(watch.state).toBe("absent");
    expect(watch.status).toBeNull();
    expect(watch.onStatus("{not json")).toBeNull();
    expect(watch.state).toBe("unknown");
    expect(seen.sleeve!.detail).toContain("not understood");
  });

  it("forgets the sleeve when the broker goes, and shows the advice before the sleeve's warning", () => {
    const { seen, target } = host();
    const watch = new SleeveWatch(target, "No config.json.");
    watch.onBroker("connected", null);
    watch.onStatus(OFFLINE);
    watch.onBroker("offline", "socket closed");
    expect(seen.broker).toBe("offline");
    expect(watch.state).toBe("unknown");
    expect(seen.sleeve).toMatchObject({ state: "unknown", brokerConnected: false });
    expect(seen.notice).toEqual({ text: "No config.json. advice: socket closed", level: "error" });
    // Reconnecting is not back yet: the advice stays.
    watch.onBroker("connecting", null);
    expect(seen.notice!.level).toBe("error");
    // And no "none listens" from a wait started before the broker went.
    vi.advanceTimersByTime(STATUS_WAIT_MS * 2);
    expect(watch.state).toBe("unknown");
    watch.onBroker("connected", null);
    expect(seen.notice).toEqual({ text: "No config.json.", level: "info" });
  });

  it("waits again for another sleeve's status", () => {
    const { seen, target } = host();
    const watch = new SleeveWatch(target, null);
    watch.onBroker("connected", null);
    watch.onStatus(ONLINE);
    seen.id = "sleeve2";
    watch.sleeveChanged();
    watch.awaitStatus();
    expect(watch.status).toBeNull();
    expect(seen.sleeve).toMatchObject({ state: "unknown", id: "sleeve2" });
    vi.advanceTimersByTime(STATUS_WAIT_MS);
    expect(watch.state).toBe("absent");
    expect(seen.notice!.text).toContain("'sleeve2'");
  });

  it("does not wait for a status without a broker", () => {
    const { target } = host();
    const watch = new SleeveWatch(target, null);
    watch.awaitStatus();
    vi.advanceTimersByTime(STATUS_WAIT_MS * 2);
    expect(watch.state).toBe("unknown");
  });
});

describe("the sleeve's floor", () => {
  const floor = { min_duration_ms: 73.701, min_length: 0.05, wearer: null };
  const online = (withFloor: boolean) =>
    JSON.stringify({ online: true, layout: { rows: 3, columns: 4 }, ...(withFloor ? { floor } : {}) });

  it("is kept while the broker is away, while it holds no status, and through an offline status without one", () => {
    const { target } = host();
    const watch = new SleeveWatch(target, null);
    watch.onBroker("connected", null);
    watch.onStatus(online(true));
    expect(watch.floor).toEqual(floor);
    watch.onBroker("offline", "closed");
    watch.onBroker("connecting", null);
    expect(watch.floor).toEqual(floor);
    watch.onBroker("connected", null);
    watch.onStatus(""); // a broker restarted without its saved state: no status held
    expect(watch.status).toBeNull();
    expect(watch.floor).toEqual(floor);
    watch.onStatus(OFFLINE); // an older sleeve's last will: online false, nothing more
    expect(watch.state).toBe("offline");
    expect(watch.floor).toEqual(floor);
    watch.onStatus("not json");
    expect(watch.floor).toEqual(floor);
  });

  it("follows the sleeve's own word: an offline status with one, an online status without", () => {
    const { target } = host();
    const watch = new SleeveWatch(target, null);
    watch.onBroker("connected", null);
    watch.onStatus(online(true));
    const raised = { min_duration_ms: 150, min_length: 0.3, wearer: "W1" };
    watch.onStatus(JSON.stringify({ online: false, floor: raised }));
    expect(watch.floor).toEqual(raised);
    watch.onStatus(online(false)); // back as an older sleeve: it has none
    expect(watch.floor).toBeNull();
  });

  it("is forgotten when another sleeve is chosen", () => {
    const { target } = host();
    const watch = new SleeveWatch(target, null);
    watch.onBroker("connected", null);
    watch.onStatus(online(true));
    watch.sleeveChanged();
    expect(watch.floor).toBeNull();
  });
});

describe("advice for a lost broker", () => {
  it("passes a refused login on as it is", () => {
    const refused = "The broker at ws://x refused the login of 'sender' (bad password).";
    expect(offlineAdvice(refused, "ws://x", true)).toBe(refused);
  });

  it("points at 'feelmysign up' when the page came from it, at Settings otherwise", () => {
    expect(offlineAdvice(null, "ws://h:9001", true)).toMatch(
      /^No connection to ws:\/\/h:9001;.*'feelmysign up'/,
    );
    expect(offlineAdvice("closed", "ws://h:9001", false)).toMatch(/Settings → Connection\.$/);
  });
});
