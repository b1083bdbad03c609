/** The wearer's API (python/src/feelmysign/wearer_api.py), on the page's own server. */

export interface Controls {
  paused: boolean;
  paused_by: string | null;
  ceiling: number | null;
  do_not_disturb_until_ms: number | null;
}

export interface Sender {
  name: string;
  blocked: boolean;
  blockable: boolean;
}

export interface WearerState {
  sleeve_id: string;
  online: boolean;
  /** Null while the sleeve starts. */
  controls: Controls | null;
  max_intensity: number;
  senders: Sender[];
  blocking: boolean;
}

/** A refusal from the server: its sentence, for the wearer. */
export class WearerApiError extends Error {
  constructor(
    message: string,
    readonly status: number,
  ) {
    super(message);
  }
}

async function answer(response: Response): Promise<WearerState> {
  let body: unknown = null;
  try {
    body = await response.json();
  } catch {
    // Not JSON (a proxy's page, a server gone): said below with the status.
  }
  if (!response.ok) {
    const error = (body as { error?: unknown } | null)?.error;
    throw new WearerApiError(
      typeof error === "string" ? error : `The sleeve's server answered ${response.status}.`,
      response.status,
    );
  }
  return body as WearerState;
}

export async function readState(): Promise<WearerState> {
  return answer(await fetch("/api/wearer/state", { cache: "no-store", credentials: "same-origin" }));
}

export type Action = "pause" | "resume" | "stop" | "ceiling" | "do-not-disturb" | "block" | "unblock";

export async function act(action: Action, body: object = {}): Promise<WearerState> {
  return answer(
    await fetch(`/api/wearer/${action}`, {
      method: "POST",
      credentials: "same-origin",
      headers: { "Content-Type": "application/json" },
      body: JSON.stringify(body),
    }),
  );
}
