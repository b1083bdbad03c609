/**
 * What the sleeve publishes, typed: its events (`feelmysign/<id>/events`) and
 * its retained status. The mirror of `python/src/feelmysign/events.py`: the
 * same fields, the same rules (unknown keys ignored, `null` for an optional
 * field means absent, 3.0 is the whole number 3), kept equal by the vectors
 * in testdata/events. A message that is not one gives null, never an
 * exception: the page must survive whatever a broker delivers.
 *
 * `interpretEvent` says what an event means for the drawing on the page (what
 * to count, note, place in time or mark): this module is the only one that
 * tells events apart by their type.
 */

interface StrokeRef {
  readonly topic: string | null;
  readonly drawing: string | null;
  readonly seq: number | null;
  readonly sent_at_ms: number | null;
  /** Received minus sent_at_ms: how old the stroke was on arrival (docs/protocol.md, pace). */
  readonly age_ms: number | null;
  /** How much later than due it starts (or would have: a `late` rejection). */
  readonly lag_ms: number | null;
}

interface Timing {
  readonly received_at_ms: number;
  /** The planned start, the sleeve's wall clock. */
  readonly start_at_ms: number;
  readonly first_command_at_ms: number;
  /** Receive -> first command. */
  readonly latency_ms: number;
  readonly start_error_ms: number;
  /** Time spent waiting for the strokes before it. */
  readonly queued_ms: number;
  readonly duration_ms: number;
  readonly commands: number;
  /** How much shorter it played to catch up with its drawing (null: as planned). */
  readonly compressed_ms: number | null;
}

export interface PlayedEvent extends StrokeRef, Timing {
  readonly type: "played";
}

/** Played, but changed to be felt (slowed: `reason` "too_fast"). */
export interface AdjustedEvent extends StrokeRef, Timing {
  readonly type: "adjusted";
  readonly reason: string;
  readonly requested_duration_ms: number;
}

export interface RejectedEvent extends StrokeRef {
  readonly type: "rejected";
  readonly reason: string;
  readonly message: string;
  readonly received_at_ms: number;
  /**
   * A `duplicate` only: whether the stroke it is a copy of started playing (felt once, and it stays
   * played) or not. Null for other reasons and from a sleeve older than the field.
   */
  readonly original_played: boolean | null;
}

/**
 * A control message cancelled it: `started` when it was cut short while playing. `by` is "wearer"
 * when the wearer paused or stopped the sleeve; absent for a sender's cancel (and from older
 * sleeves).
 */
export interface CancelledEvent extends StrokeRef {
  readonly type: "cancelled";
  readonly reason: string;
  readonly message: string;
  readonly received_at_ms: number;
  readonly cancelled_at_ms: number;
  readonly started: boolean;
  readonly by?: string;
}

/**
 * A motor was protected: `duty_cycle`, a stroke the duty-cycle cap kept from playing (with
 * the stroke's fields, the motor's would-be duty cycle and the limit); `chip_lost` or
 * `chip_back`, a DRV2605L that stopped answering or answers again; `silenced`, a stroke cut
 * while the sleeve's enable line is held low; `stopped` and `crashed`, a stroke cut short after its
 * `played` because the sleeve stopped, or its process ended (said by the sleeve started next),
 * while it played (docs/protocol.md).
 */
export interface SafetyEvent extends StrokeRef {
  readonly type: "safety";
  readonly reason: string;
  readonly row: number;
  readonly column: number;
  readonly message: string | null;
  readonly received_at_ms: number | null;
  readonly duty_cycle: number | null;
  readonly max_duty_cycle: number | null;
  readonly window_ms: number | null;
}

export interface ErrorEvent {
  readonly type: "error";
  readonly reason: string;
  readonly message: string | null;
  readonly row: number | null;
  readonly column: number | null;
}

export type SleeveEvent =
  PlayedEvent | AdjustedEvent | RejectedEvent | CancelledEvent | SafetyEvent | ErrorEvent;
export type SleeveEventType = SleeveEvent["type"];

export interface StatusLayout {
  readonly name: string | null;
  readonly rows: number;
  readonly columns: number;
  readonly spacing_cm: number | null;
  readonly actuator_type: string | null;
  readonly default_intensity: number | null;
  readonly max_intensity: number | null;
  readonly max_stroke_duration_ms: number | null;
}

/** The retained status: `online` is all a last will must carry. */
export interface SleeveStatus {
  readonly online: boolean;
  readonly sleeve_id: string | null;
  readonly version: string | null;
  readonly backend: string | null;
  readonly legacy_topic: string | null;
  readonly layout: StatusLayout | null;
  readonly at_ms: number | null;
  /** Came later than the other fields: absent from an older sleeve's status. */
  readonly floor?: SleeveFloor;
  /** The wearer's controls; absent from the last will and older sleeves (not paused, no ceiling). */
  readonly controls?: SleeveControls;
}

/**
 * The wearer's controls (Python `StatusControls`): while `paused`, or until
 * `do_not_disturb_until_ms` (wall clock, ms since 1970), the sleeve refuses every stroke (reasons
 * `paused`, `do_not_disturb`); no motor is driven above `ceiling`.
 */
export interface SleeveControls {
  readonly paused: boolean;
  /** "button", "page", "cli" (or "sleeve": it started paused, its controls file unreadable). */
  readonly paused_by: string | null;
  readonly ceiling: number | null;
  readonly do_not_disturb_until_ms: number | null;
}

/** Refusal reasons of the wearer's controls. */
export const PAUSED_REASON = "paused";
export const DO_NOT_DISTURB_REASON = "do_not_disturb";
/** The `by` of the events of strokes the wearer cut. */
export const BY_WEARER = "wearer";

/**
 * The least a stroke should be for the sleeve to play it as sent and its wearer to feel it
 * (Python `StatusFloor`): a sender raises its simplifier's minimums to at least these.
 */
export interface SleeveFloor {
  readonly min_duration_ms: number;
  readonly min_length: number;
  /** Whose measured limits are in it, when any. */
  readonly wearer: string | null;
}

// ---- the field tables: names in publishing order, as in events.py -----------------------------

type Kind = "text" | "number" | "index" | "flag";
type Field = readonly [name: string, kind: Kind, required: boolean];

const STROKE: readonly Field[] = [
  ["topic", "text", false],
  ["drawing", "text", false],
  ["seq", "index", false],
  ["sent_at_ms", "number", false],
  ["age_ms", "number", false],
  ["lag_ms", "number", false],
];
const TIMING: readonly Field[] = [
  ["received_at_ms", "number", true],
  ["start_at_ms", "number", true],
  ["first_command_at_ms", "number", true],
  ["latency_ms", "number", true],
  ["start_error_ms", "number", true],
  ["queued_ms", "number", true],
  ["duration_ms", "number", true],
  ["commands", "index", true],
  ["compressed_ms", "number", false],
];
const REASON_MESSAGE: readonly Field[] = [
  ["reason", "text", true],
  ["message", "text", true],
];

const EVENT_FIELDS: Record<SleeveEventType, readonly Field[]> = {
  played: [...STROKE, ...TIMING],
  adjusted: [...STROKE, ...TIMING, ["reason", "text", true], ["requested_duration_ms", "number", true]],
  rejected: [
    ...REASON_MESSAGE,
    ...STROKE,
    ["received_at_ms", "number", true],
    ["original_played", "flag", false],
  ],
  cancelled: [
    ...REASON_MESSAGE,
    ...STROKE,
    ["received_at_ms", "number", true],
    ["cancelled_at_ms", "number", true],
    ["started", "flag", true],
    ["by", "text", false],
  ],
  safety: [
    ["reason", "text", true],
    ["row", "index", true],
    ["column", "index", true],
    ["message", "text", false],
    ...STROKE,
    ["received_at_ms", "number", false],
    ["duty_cycle", "number", false],
    ["max_duty_cycle", "number", false],
    ["window_ms", "number", false],
  ],
  error: [
    ["reason", "text", true],
    ["message", "text", false],
    ["row", "index", false],
    ["column", "index", false],
  ],
};
const LAYOUT_FIELDS: readonly Field[] = [
  ["name", "text", false],
  ["rows", "index", true],
  ["columns", "index", true],
  ["spacing_cm", "number", false],
  ["actuator_type", "text", false],
  ["default_intensity", "number", false],
  ["max_intensity", "number", false],
  ["max_stroke_duration_ms", "number", false],
];
const STATUS_FIELDS: readonly Field[] = [
  ["online", "flag", true],
  ["sleeve_id", "text", false],
  ["version", "text", false],
  ["backend", "text", false],
  ["legacy_topic", "text", false],
];
const CONTROLS_FIELDS: readonly Field[] = [
  ["paused", "flag", true],
  ["paused_by", "text", false],
  ["ceiling", "number", false],
  ["do_not_disturb_until_ms", "index", false],
];
const FLOOR_FIELDS: readonly Field[] = [
  ["min_duration_ms", "number", true],
  ["min_length", "number", true],
  ["wearer", "text", false],
];
/** A grid side the page will draw: the layout file's own limit. */
const MAX_GRID_SIDE = 64;

function asObject(value: unknown): Record<string, unknown> | null {
  return typeof value === "object" && value !== null && !Array.isArray(value)
    ? (value as Record<string, unknown>)
    : null;
}

/** undefined: the value does not have the kind; null: absent. */
function readValue(value: unknown, kind: Kind): unknown {
  if (value === null || value === undefined) return null;
  switch (kind) {
    case "text":
      return typeof value === "string" ? value : undefined;
    case "flag":
      return typeof value === "boolean" ? value : undefined;
    case "number":
      return typeof value === "number" && Number.isFinite(value) ? value : undefined;
    case "index":
      return typeof value === "number" && Number.isInteger(value) && value >= 0 ? value : undefined;
  }
}

function readFields(data: Record<string, unknown>, fields: readonly Field[]): Record<string, unknown> | null {
  const out: Record<string, unknown> = {};
  for (const [name, kind, required] of fields) {
    const value = readValue(data[name], kind);
    if (value === undefined || (value === null && required)) return null;
    out[name] = value;
  }
  return out;
}

function writeFields(data: object, fields: readonly Field[]): Record<string, unknown> {
  const values = data as Record<string, unknown>;
  const out: Record<string, unknown> = {};
  for (const [name] of fields)
    if (values[name] !== null && values[name] !== undefined) out[name] = values[name];
  return out;
}

function parseText(text: string): unknown {
  try {
    return JSON.parse(text);
  } catch {
    return undefined;
  }
}

/** An event from its JSON value; null when it is not one. */
export function readEvent(value: unknown): SleeveEvent | null {
  const data = asObject(value);
  const type = data?.["type"];
  if (data === null || typeof type !== "string" || !Object.hasOwn(EVENT_FIELDS, type)) return null;
  const fields = readFields(data, EVENT_FIELDS[type as SleeveEventType]);
  if (fields === null) return null;
  // A field later than the others is left out when absent, as the Python reader's typed form does.
  if (type === "cancelled" && fields["by"] === null) delete fields["by"];
  return { type, ...fields } as unknown as SleeveEvent;
}

export function parseEvent(text: string): SleeveEvent | null {
  return readEvent(parseText(text));
}

/** Stroke events remembered to tell a copy from a new event: far more than one drawing sends. */
export const REMEMBERED_EVENTS = 4096;

/**
 * Tells a copy of a stroke's event from a new one. The sleeve publishes events at QoS 1,
 * so after a broker restart a reader may get the same event twice; counting it twice
 * would show a stroke played twice that was felt once. A stroke's event carries its
 * times, so a copy has exactly the same text, and two real events never do. Events that
 * name no stroke (errors, a message the sleeve could not read) are never held back.
 */
export class EventCopies {
  readonly #seen = new Set<string>();
  readonly #order: string[] = [];
  #next = 0;

  constructor(readonly capacity = REMEMBERED_EVENTS) {}

  /** True when `text` is a copy of a stroke's event already seen (and then remembered). */
  isCopy(text: string, event: SleeveEvent): boolean {
    if (!("seq" in event) || event.seq === null || event.drawing == null) return false;
    if (this.#seen.has(text)) return true;
    if (this.#order.length < this.capacity) {
      this.#order.push(text);
    } else {
      this.#seen.delete(this.#order[this.#next]!);
      this.#order[this.#next] = text;
      this.#next = (this.#next + 1) % this.capacity;
    }
    this.#seen.add(text);
    return false;
  }
}

/** The event as the sleeve publishes it: optional fields left out. */
export function eventToJson(event: SleeveEvent): Record<string, unknown> {
  return { type: event.type, ...writeFields(event, EVENT_FIELDS[event.type]) };
}

function readLayout(value: unknown): StatusLayout | null | undefined {
  if (value === null || value === undefined) return null;
  const data = asObject(value);
  const fields = data === null ? null : readFields(data, LAYOUT_FIELDS);
  if (fields === null) return undefined;
  const { rows, columns } = fields as { rows: number; columns: number };
  if (rows < 1 || rows > MAX_GRID_SIDE || columns < 1 || columns > MAX_GRID_SIDE) return undefined;
  return fields as unknown as StatusLayout;
}

function readFloor(value: unknown): SleeveFloor | null | undefined {
  if (value === null || value === undefined) return null;
  const data = asObject(value);
  const fields = data === null ? null : readFields(data, FLOOR_FIELDS);
  if (fields === null) return undefined;
  const { min_duration_ms, min_length } = fields as { min_duration_ms: number; min_length: number };
  if (min_duration_ms < 0 || min_length < 0) return undefined;
  return fields as unknown as SleeveFloor;
}

function readControls(value: unknown): SleeveControls | null | undefined {
  if (value === null || value === undefined) return null;
  const data = asObject(value);
  const fields = data === null ? null : readFields(data, CONTROLS_FIELDS);
  if (fields === null) return undefined;
  const ceiling = fields["ceiling"] as number | null;
  if (ceiling !== null && (ceiling < 0 || ceiling > 1)) return undefined;
  return fields as unknown as SleeveControls;
}

export function readStatus(value: unknown): SleeveStatus | null {
  const data = asObject(value);
  if (data === null) return null;
  const fields = readFields(data, STATUS_FIELDS);
  const layout = readLayout(data["layout"]);
  const atMs = readValue(data["at_ms"], "number");
  const floor = readFloor(data["floor"]);
  const controls = readControls(data["controls"]);
  if (fields === null || layout === undefined || atMs === undefined || floor === undefined) return null;
  if (controls === undefined) return null;
  const status: Record<string, unknown> = { ...fields, layout, at_ms: atMs };
  if (floor !== null) status["floor"] = floor;
  if (controls !== null) status["controls"] = controls;
  return status as unknown as SleeveStatus;
}

export function parseStatus(text: string): SleeveStatus | null {
  return readStatus(parseText(text));
}

export function statusToJson(status: SleeveStatus): Record<string, unknown> {
  const out = writeFields(status, STATUS_FIELDS);
  if (status.layout !== null) out["layout"] = writeFields(status.layout, LAYOUT_FIELDS);
  if (status.at_ms !== null) out["at_ms"] = status.at_ms;
  if (status.floor !== undefined) out["floor"] = writeFields(status.floor, FLOOR_FIELDS);
  // All four keys, null where not set, as the sleeve publishes them.
  if (status.controls !== undefined) {
    const controls = status.controls as unknown as Record<string, unknown>;
    out["controls"] = Object.fromEntries(CONTROLS_FIELDS.map(([name]) => [name, controls[name] ?? null]));
  }
  return out;
}

// ---- what an event means for the drawing on the page ------------------------------------------

/**
 * A played stroke whose delivery delay is above this was "delayed" on its way: the page marks it, as
 * the terminal of `feelmysign up` does (Python `events.DELAYED_MS`). Not the sleeve's `late`
 * refusal, which skips a stroke; a delayed stroke was played.
 */
export const DELAYED_MS = 500;
/** Adjustments smaller than this share of the duration asked for are not worth a line. */
export const NOTABLE_ADJUSTMENT = 0.05;

/** What the "Sleeve says" card counts. */
export type EventCount = "played" | "delayed" | "refused" | "cancelled" | "cut";
/** A line of the "Sleeve says" log: a refusal, a stroke played otherwise than asked, an error, news. */
export type NoteKind = "rejected" | "adjusted" | "error" | "info";

export interface Note {
  readonly kind: NoteKind;
  readonly text: string;
}

export interface EventReading {
  /** What to count, in order (a cut stroke is counted cancelled and cut). */
  readonly counts: readonly EventCount[];
  /** Its delivery delay, when `counts` has "delayed". */
  readonly delayMs: number;
  readonly notes: readonly Note[];
  /** A stroke of the drawing was played: where it is in time. */
  readonly played: PlayedEvent | AdjustedEvent | null;
  /** A stroke of the drawing was cancelled: where it stopped. */
  readonly cancelled: CancelledEvent | null;
  /** The seq of a stroke of the drawing the sleeve refused, or kept from playing: marked on the canvas. */
  readonly refusedSeq: number | null;
  /** A stroke of the drawing the sleeve will never play: what the felt timeline leaves out of it. */
  readonly unplayed: Unplayed | null;
}

/**
 * A stroke the sleeve will never play. `refused`: refused on arrival, it never entered the sleeve's
 * queue. `capped`: the duty-cycle cap kept it from playing when its turn came, and the sleeve let
 * its turn pass in silence (the strokes after it keep their starts).
 */
export interface Unplayed {
  readonly seq: number;
  readonly why: "refused" | "capped";
}

/** The refusal of a copy of a stroke already played or refused: it says nothing of that stroke's touch. */
export const DUPLICATE_REASON = "duplicate";
/** The safety event of a stroke the duty-cycle cap kept from playing. */
export const DUTY_CYCLE_REASON = "duty_cycle";
/**
 * A stroke the sleeve skipped, too far behind its sender (after a stall): said "skipped as late",
 * as the card's summary, `up`'s line and `feelmysign send` say it, not as a refusal of the stroke.
 */
export const LATE_REASON = "late";

const NOTHING: EventReading = {
  counts: [],
  delayMs: 0,
  notes: [],
  played: null,
  cancelled: null,
  refusedSeq: null,
  unplayed: null,
};

/**
 * How long a played stroke was held on its way: sent -> its first motor command, less its wait
 * behind the strokes before it (playing a drawing back to back is the design, not a delay). What
 * remains is the network, the broker holding it, the sleeve offline. Null when the stroke carried
 * no sent time. Python's `events.delivery_delay_ms`; testdata/events/delay keeps the two equal.
 */
export function deliveryDelayMs(event: PlayedEvent | AdjustedEvent): number | null {
  return event.sent_at_ms === null ? null : event.first_command_at_ms - event.sent_at_ms - event.queued_ms;
}

/** Whether a played stroke was delayed on its way (see `deliveryDelayMs`). */
export function isDelayed(event: PlayedEvent | AdjustedEvent, thresholdMs = DELAYED_MS): boolean {
  const delayMs = deliveryDelayMs(event);
  return delayMs !== null && delayMs > thresholdMs;
}

/** What `event` means for the page whose current drawing is `drawingId` (null: none). */
export function interpretEvent(event: SleeveEvent, drawingId: string | null): EventReading {
  const ref = "seq" in event ? event : null;
  const ours = drawingId !== null && ref !== null && ref.drawing === drawingId && ref.seq !== null;
  const label = strokeLabel(ref?.seq ?? null);
  switch (event.type) {
    case "played":
    case "adjusted": {
      if (!ours) return NOTHING;
      const counts: EventCount[] = ["played"];
      const notes: Note[] = [];
      const delayMs = deliveryDelayMs(event) ?? 0;
      if (isDelayed(event)) {
        counts.push("delayed");
        notes.push({
          kind: "adjusted",
          text: `${label} delayed ${seconds(delayMs)} on the way (held while the broker was out of reach, at the broker, or by the network).`,
        });
      }
      if (event.type === "adjusted") {
        const change =
          Math.abs(event.duration_ms - event.requested_duration_ms) / event.requested_duration_ms;
        // "Played in 418 ms instead of 417 ms" is noise: only changes a person could feel.
        if (change >= NOTABLE_ADJUSTMENT) {
          notes.push({
            kind: "adjusted",
            text: `${label} played in ${Math.round(event.duration_ms)} ms instead of ${Math.round(event.requested_duration_ms)} ms (${event.reason.replaceAll("_", " ")}).`,
          });
        }
      }
      return { ...NOTHING, counts, delayMs, notes, played: event };
    }
    case "rejected": {
      // A refusal of no drawing in particular (a message the sleeve could not read) is shown too.
      const shown = ours || ref?.drawing == null;
      // A copy's refusal leaves the stroke where the sleeve put it (played, or refused before).
      const unplayed = ours && event.reason !== DUPLICATE_REASON;
      const verdict = event.reason === LATE_REASON ? "skipped as late" : "refused";
      return {
        ...NOTHING,
        counts: ours ? ["refused"] : [],
        notes: shown ? [{ kind: "rejected", text: `${label} ${verdict}: ${describe(event)}` }] : [],
        refusedSeq: ours ? event.seq : null,
        unplayed: unplayed ? { seq: event.seq!, why: "refused" } : null,
      };
    }
    case "cancelled":
      if (!ours) return NOTHING;
      return {
        ...NOTHING,
        counts: event.started ? ["cancelled", "cut"] : ["cancelled"],
        notes: [
          {
            kind: "info",
            text: `${label} cancelled${event.by === BY_WEARER ? " by the wearer" : ""}${event.started ? " while playing" : " before it played"}.`,
          },
        ],
        cancelled: event,
      };
    case "safety":
      if (ours && event.reason === DUTY_CYCLE_REASON) {
        // Refused when its turn came: counted and marked as a refusal, as `up`'s terminal counts it.
        return {
          ...NOTHING,
          counts: ["refused"],
          notes: [{ kind: "rejected", text: `${label} refused by the duty-cycle cap: ${describe(event)}` }],
          refusedSeq: event.seq,
          unplayed: { seq: event.seq!, why: "capped" },
        };
      }
      return {
        ...NOTHING,
        notes: [
          {
            kind: "error",
            text: `Safety: actuator (${event.row}, ${event.column}) switched off: ${describe(event)}`,
          },
        ],
      };
    case "error":
      return {
        ...NOTHING,
        notes: [{ kind: "error", text: `The sleeve reports an error: ${describe(event)}` }],
      };
  }
}

function describe(event: SleeveEvent): string {
  const message = "message" in event ? event.message : null;
  return message ?? ("reason" in event ? event.reason.replaceAll("_", " ") : "no reason given");
}

/**
 * A stroke as the page's notes name it: "Stroke 1" for the first stroke of a drawing. The seq on
 * the wire counts from 0 (docs/protocol.md); the sender counts strokes from 1, so a note names
 * `seq + 1`, and every note of the page says it the same way.
 */
export function strokeLabel(seq: number | null): string {
  return seq === null ? "A stroke" : `Stroke ${seq + 1}`;
}

/** A duration as a person reads it: "420 ms", "1.5 s". */
export function seconds(ms: number): string {
  return ms >= 1000 ? `${(ms / 1000).toFixed(1)} s` : `${Math.round(ms)} ms`;
}
