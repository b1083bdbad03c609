/**
 * The server's `/config.json`: the broker address and the sender's login, so
 * nothing has to be typed (`feelmysign up` writes it from the broker's
 * credentials.json). Absent under `vite dev`: the page then uses the settings.
 */

export interface ServerConfig {
  readonly ws_url: string;
  /** The server's own sleeve: the one drawn on until another is chosen. */
  readonly sleeve_id: string;
  /** Every sleeve with an account on the server's broker (its own first); the picker lists them. */
  readonly sleeves: readonly string[];
  readonly username: string;
  readonly password: string;
}

export type ConfigResult =
  { readonly config: ServerConfig; readonly note: null } | { readonly config: null; readonly note: string };

const CONFIG_PATH = "/config.json";

export function readConfig(value: unknown): ServerConfig | string {
  if (typeof value !== "object" || value === null || Array.isArray(value)) {
    return "is not a JSON object";
  }
  const data = value as Record<string, unknown>;
  for (const key of ["ws_url", "sleeve_id", "username", "password"]) {
    if (typeof data[key] !== "string") return `has no string "${key}"`;
  }
  const sleeves = data["sleeves"] ?? [data["sleeve_id"]];
  if (!Array.isArray(sleeves) || !sleeves.every((id) => typeof id === "string")) {
    return 'has a "sleeves" that is not a list of sleeve ids';
  }
  return {
    ws_url: data["ws_url"] as string,
    sleeve_id: data["sleeve_id"] as string,
    sleeves: sleeves as string[],
    username: data["username"] as string,
    password: data["password"] as string,
  };
}

/** Fetches and checks the config; never throws: a missing config is a normal case. */
export async function fetchConfig(fetcher: typeof fetch = fetch): Promise<ConfigResult> {
  let response: Response;
  try {
    response = await fetcher(CONFIG_PATH, { cache: "no-store" });
  } catch {
    return {
      config: null,
      note: "No server config (could not fetch /config.json): using Settings → Connection.",
    };
  }
  if (response.status === 403) {
    // The server runs with a key (feelmysign up --lan or --host) and this page was opened
    // without it, e.g. from a typed address: the key is in the printed URL and its QR code.
    return {
      config: null,
      note: "This page was opened without its key (/config.json: HTTP 403): open the URL that 'feelmysign up' printed, or scan its QR code, which hold the key.",
    };
  }
  if (!response.ok) {
    return {
      config: null,
      note: `No server config (/config.json: HTTP ${response.status}); set the broker in Settings → Connection, or start the page with 'feelmysign up'.`,
    };
  }
  // A dev server answers every path with index.html: that is no config either.
  if (!(response.headers.get("content-type") ?? "").includes("json")) {
    return {
      config: null,
      note: "No server config (this server has no /config.json, e.g. under 'vite dev'); set the broker in Settings → Connection, or start the page with 'feelmysign up'.",
    };
  }
  let body: unknown;
  try {
    body = await response.json();
  } catch {
    return {
      config: null,
      note: "The server's /config.json is not valid JSON; using Settings → Connection.",
    };
  }
  const config = readConfig(body);
  if (typeof config === "string") {
    return { config: null, note: `The server's /config.json ${config}; using Settings → Connection.` };
  }
  return { config, note: null };
}
