/**
 * The control message: cancel one drawing, or everything ("*"), on
 * `feelmysign/<sleeve-id>/control`. The mirror of
 * `python/src/feelmysign/control.py`, kept equal by testdata/control: the
 * page writes these, and reads them back the way the sleeve would (a sender
 * can check what it is about to send).
 */
import { DRAWING_ID, JSON_VERSION } from "./protocol";

export const CANCEL_ALL = "*";
/** The same limit as a stroke's payload: the sleeve checks every message alike. */
const MAX_PAYLOAD_BYTES = 512;

export interface ControlRefusal {
  readonly reason: string;
  readonly field: string | null;
}

/** The exact text senders publish: `{"v":1,"cancel":"<drawing>"}` or `{"v":1,"cancel":"*"}`. */
export function formatControl(cancel: string): string {
  if (cancel !== CANCEL_ALL && !DRAWING_ID.test(cancel)) {
    throw new Error(`Not a drawing id: ${JSON.stringify(cancel)}`);
  }
  return JSON.stringify({ v: JSON_VERSION, cancel });
}

/** The drawing id (or "*") a control message cancels, or why the sleeve would refuse it. */
export function parseControl(text: string): { cancel: string } | ControlRefusal {
  const refuse = (reason: string, field: string | null = null): ControlRefusal => ({ reason, field });
  if (new TextEncoder().encode(text).length > MAX_PAYLOAD_BYTES) return refuse("too_long");
  const body = text.replace(/^\uFEFF/, "").replace(/^[ \t\r\n]+|[ \t\r\n]+$/g, "");
  if (body === "") return refuse("empty");
  let document: unknown;
  try {
    document = JSON.parse(body);
  } catch {
    return refuse("invalid_json");
  }
  if (typeof document !== "object" || document === null || Array.isArray(document)) {
    return refuse("not_an_object");
  }
  const fields = document as Record<string, unknown>;
  for (const key of ["v", "cancel"]) {
    if (fields[key] === undefined || fields[key] === null) return refuse("missing_field", key);
  }
  if (typeof fields["v"] !== "number") return refuse("wrong_type", "v");
  if (fields["v"] !== JSON_VERSION) return refuse("unknown_version", "v");
  const cancel = fields["cancel"];
  if (typeof cancel !== "string") return refuse("wrong_type", "cancel");
  if (cancel !== CANCEL_ALL && !DRAWING_ID.test(cancel)) return refuse("bad_drawing_id", "cancel");
  return { cancel };
}
