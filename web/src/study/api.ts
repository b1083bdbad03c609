/** The study server's JSON API (python/src/feelmysign/study/api.py), typed. */

export interface ParticipantSummary {
  participant: string;
  simulated: boolean;
  step: Step;
  paused: boolean;
  answered: number;
  total: number;
}

export type Step = "consent" | "comfort" | "trial" | "questionnaire" | "done" | "withdrawn";

export interface Overview {
  name: string;
  file: string;
  shapes: string[];
  resolutions: string[];
  /** The design's drawing speeds; two or more: speed is a factor and each trial has its own. */
  speeds_cm_s: number[];
  comfort: string[];
  questionnaire: { items: string[]; points: number; labels: string[] };
  participants: ParticipantSummary[];
  review: number;
  results: string | null;
}

export interface SendSummary {
  strokes: number;
  /** Played whole (python/src/feelmysign/fates.py: each stroke under one fate). */
  played: number;
  /** Cut short by a stop while playing; absent from a record made before it was counted. */
  cut_short?: number;
  /** Dropped by a stop before it started; absent from a record made before it was counted. */
  cancelled?: number;
  adjusted: number;
  rejected: string[];
  /**
   * Played faster to catch up with the drawing, and how much shorter in all (fates.py
   * `CatchUp`); absent from a record made before they were counted. Skipped ones are among
   * `rejected` as "late".
   */
  compressed?: number;
  compressed_ms?: number;
  latency_ms_max: number | null;
  felt_duration_ms: number;
  error?: string | null;
}

export interface Trial {
  id: number;
  number: number;
  total: number;
  block: "practice" | "main";
  repetition: number;
  shape: string;
  resolution: string | null;
  segments: number;
  /** cm/s the shape is drawn at; null: a recorded drawing at its own (the hand's) timing. */
  speed_cm_s: number | null;
  sends: number;
  last_send: SendSummary | null;
}

export interface State extends ParticipantSummary {
  trial: Trial | null;
}

export interface Coding {
  status: "shape" | "none" | "unclear";
  shape: string | null;
  rule: string;
}

export interface ReviewItem {
  trial: number;
  answer: string;
  rule: string;
}

export interface AnalysisResult {
  folder: string;
  files: string[];
  report: string;
  participants: number;
  unclear: number;
}

/** The export and analysis the server runs in the background; the page polls it. */
export interface AnalysisJob {
  job: number;
  state: "idle" | "running" | "done" | "failed";
  result: AnalysisResult | null;
  error: string | null;
}

export interface SimulatedAnswer {
  answer: string;
  felt_nothing: boolean;
  confidence: number | null;
}

/** An answer of the server that says what went wrong, in its own words. */
export class StudyApiError extends Error {
  readonly status: number;
  constructor(status: number, message: string) {
    super(message);
    this.status = status;
  }
}

async function call<T>(method: "GET" | "POST", path: string, body?: object): Promise<T> {
  const init: RequestInit = { method, headers: { accept: "application/json" } };
  if (body !== undefined) {
    init.headers = { ...init.headers, "content-type": "application/json" };
    init.body = JSON.stringify(body);
  }
  let response: Response;
  try {
    response = await fetch(`/api/study${path}`, init);
  } catch {
    throw new StudyApiError(0, "The study server does not answer: is 'feelmysign up --study FILE' running?");
  }
  const data = (await response.json().catch(() => ({}))) as { error?: string };
  if (!response.ok) throw new StudyApiError(response.status, data.error ?? `HTTP ${response.status}`);
  return data as T;
}

const participant = (code: string, action = "") => `/participants/${encodeURIComponent(code)}${action}`;

export const api = {
  overview: () => call<Overview>("GET", ""),
  addParticipant: (simulated: boolean) => call<{ code: string }>("POST", "/participants", { simulated }),
  state: (code: string) => call<State>("GET", participant(code)),
  consent: (code: string, consent: boolean) =>
    call<{ state: State }>("POST", participant(code, "/consent"), { consent }),
  comfort: (code: string, answers: boolean[], adjusted: boolean) =>
    call<{ state: State }>("POST", participant(code, "/comfort"), { answers, adjusted }),
  send: (code: string, trial: number) =>
    call<{ sent: SendSummary; state: State }>("POST", participant(code, "/send"), { trial }),
  answer: (code: string, trial: number, answer: string, feltNothing: boolean, confidence: number | null) =>
    call<{ coding: Coding; state: State }>("POST", participant(code, "/answer"), {
      trial,
      answer,
      felt_nothing: feltNothing,
      confidence,
    }),
  pause: (code: string, paused: boolean) =>
    call<{ state: State }>("POST", participant(code, "/pause"), { paused }),
  questionnaire: (code: string, values: number[]) =>
    call<{ state: State }>("POST", participant(code, "/questionnaire"), { values }),
  simulatedAnswer: (code: string) => call<SimulatedAnswer>("GET", participant(code, "/simulated-answer")),
  review: () => call<ReviewItem[]>("GET", "/review"),
  decide: (trial: number, shape: string | null) =>
    call<{ review: number }>("POST", `/review/${trial}`, { shape }),
  startAnalysis: () => call<AnalysisJob>("POST", "/analyse", {}),
  analysis: () => call<AnalysisJob>("GET", "/analysis"),
};

export type Dimension = "length" | "duration";
export type Direction = "up" | "down" | "left" | "right";

export interface ThresholdEstimate {
  threshold: number;
  low: number;
  high: number;
  /**
   * Where the 95% interval reaches an end of the tested range (study/threshold.py `censored`):
   * "above", not measured; "below", a bound. Absent from a server before it was said.
   */
  censored?: "above" | "below" | null;
}

export interface ThresholdTrial {
  position: number;
  value: number;
  direction: Direction;
  response: Direction;
  correct: boolean;
}

export interface ThresholdRun {
  run: number;
  trials: ThresholdTrial[];
  estimate: ThresholdEstimate | null;
  /** The direction stays hidden until the answer is recorded. */
  next: { position: number; value: number; sent: boolean };
  last_send: SendSummary | null;
  simulated_answer?: Direction;
}

export interface FinishedThresholdRun extends ThresholdEstimate {
  run: number;
  stop_reason: string;
  trials: number;
}

export interface ThresholdDimension {
  unit: string;
  range: [number, number];
  fixed: number;
  finished_runs: FinishedThresholdRun[];
  /** Runs the researcher discarded: kept in the study file, left out of the results. */
  discarded_runs: { run: number; trials: number }[];
  run: ThresholdRun | null;
}

export interface ThresholdState {
  participant: string;
  simulated: boolean;
  stopping_rule: string;
  dimensions: Record<Dimension, ThresholdDimension>;
}

export const thresholdApi = {
  state: (code: string) => call<ThresholdState>("GET", participant(code, "/threshold")),
  send: (code: string, dimension: Dimension) =>
    call<ThresholdState>("POST", participant(code, "/threshold-send"), { dimension }),
  answer: (code: string, dimension: Dimension, position: number, response: Direction) =>
    call<ThresholdState>("POST", participant(code, "/threshold-answer"), { dimension, position, response }),
  discard: (code: string, dimension: Dimension) =>
    call<ThresholdState>("POST", participant(code, "/threshold-discard"), { dimension }),
};
