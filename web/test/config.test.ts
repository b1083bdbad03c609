/** /config.json: used when the server gives it, and a clear note when it does not. */
import { describe, expect, it } from "vitest";
import { fetchConfig } from "../src/config";

const respond = (status: number, body: string, type = "application/json"): typeof fetch =>
  (async () => new Response(body, { status, headers: { "content-type": type } })) as typeof fetch;

describe("fetchConfig", () => {
  it("reads the server's broker and sender login", async () => {
    const body = '{"ws_url":"ws://127.0.0.1:9001","sleeve_id":"sleeve1","username":"sender","password":"x"}';
    const result = await fetchConfig(respond(200, body));
    expect(result.config).toEqual({
      ws_url: "ws://127.0.0.1:9001",
      sleeve_id: "sleeve1",
      // An older server lists no sleeves: its own is the one.
      sleeves: ["sleeve1"],
      username: "sender",
      password: "x",
    });
    expect(result.note).toBeNull();
  });

  it("reads every sleeve that shares the server's broker, and refuses a list that is not one", async () => {
    const config = { ws_url: "ws://h:1", sleeve_id: "sleeve1", username: "s", password: "p" };
    const listed = await fetchConfig(
      respond(200, JSON.stringify({ ...config, sleeves: ["sleeve1", "arm2"] })),
    );
    expect(listed.config?.sleeves).toEqual(["sleeve1", "arm2"]);
    const bad = await fetchConfig(respond(200, JSON.stringify({ ...config, sleeves: "arm2" })));
    expect(bad.config).toBeNull();
    expect(bad.note).toMatch(/"sleeves" that is not a list/);
  });

  it("says what is missing when there is no config (vite dev)", async () => {
    const result = await fetchConfig(respond(404, "not found"));
    expect(result.config).toBeNull();
    expect(result.note).toMatch(/HTTP 404.*Settings/);
  });

  it("tells a page opened without its key to open the printed URL (a typed LAN address)", async () => {
    const result = await fetchConfig(respond(403, "Forbidden", "text/plain"));
    expect(result.config).toBeNull();
    expect(result.note).toMatch(/without its key.*printed.*QR code/);
  });

  it("says so when the config is malformed", async () => {
    expect((await fetchConfig(respond(200, '{"ws_url":1}'))).note).toMatch(/no string "ws_url"/);
    expect((await fetchConfig(respond(200, "<html>"))).note).toMatch(/not valid JSON/);
  });

  it("does not take a dev server's index.html for a config", async () => {
    const result = await fetchConfig(respond(200, "<!doctype html>", "text/html"));
    expect(result.config).toBeNull();
    expect(result.note).toMatch(/vite dev/);
  });

  it("survives a network error", async () => {
    const failing = (async () => {
      throw new TypeError("Failed to fetch");
    }) as typeof fetch;
    expect((await fetchConfig(failing)).config).toBeNull();
  });
});
