/**
 * The wearer's page, served at /wearer by `feelmysign up` (and the sleeve): pause and
 * resume, stop, the strongest vibration allowed, "do not disturb", and blocking senders.
 * Made for a phone and a screen reader: large real buttons, a live region saying what
 * changed. It reads the sleeve's state every second; each button's answer is the new state.
 */
import "./wearer.css";
import { act, readState, WearerApiError, type Action, type Sender, type WearerState } from "./api";

const POLL_INTERVAL_MS = 1000;
// The ceilings offered, as fractions of the sleeve's own maximum (below it: the wearer's cap).
const CEILING_FRACTIONS = [0.2, 0.4, 0.6, 0.8] as const;
const MIN_CEILING = 0.05; // the sleeve's lowest ceiling (feelmysign.sleeve.controls)
const MINUTE_MS = 60_000;
const DAY_MS = 24 * 60 * MINUTE_MS;

function byId<T extends HTMLElement>(id: string): T {
  const element = document.getElementById(id);
  if (element === null) throw new Error(`the wearer's page lacks #${id}`);
  return element as T;
}

const sleeveLine = byId<HTMLParagraphElement>("sleeve-line");
const live = byId<HTMLParagraphElement>("live");
const problem = byId<HTMLParagraphElement>("problem");
const pauseLine = byId<HTMLParagraphElement>("pause-line");
const pauseButton = byId<HTMLButtonElement>("pause");
const stopButton = byId<HTMLButtonElement>("stop");
const ceilingLine = byId<HTMLParagraphElement>("ceiling-line");
const ceilingChoices = byId<HTMLDivElement>("ceiling-choices");
const dndLine = byId<HTMLParagraphElement>("dnd-line");
const dndUntil = byId<HTMLFormElement>("dnd-until");
const dndTime = byId<HTMLInputElement>("dnd-time");
const dndEnd = byId<HTMLButtonElement>("dnd-end");
const sendersLine = byId<HTMLParagraphElement>("senders-line");
const sendersList = byId<HTMLUListElement>("senders");

let state: WearerState | null = null;
let busy = false; // one change at a time: a second tap is ignored until the first is answered
let lastSaid = "";
// A refused change stays on screen until the next change succeeds (a poll does not hide it).
let changeRefused = false;

function percent(fraction: number): string {
  return `${Math.round(fraction * 100)} %`;
}

function clock(ms: number): string {
  return new Date(ms).toLocaleTimeString([], { hour: "2-digit", minute: "2-digit" });
}

/** The next wall-clock time at `hhmm` ("14:30"): today, or tomorrow when it has passed. */
function nextTimeMs(hhmm: string, nowMs: number): number | null {
  const match = /^(\d{2}):(\d{2})$/.exec(hhmm);
  if (match === null) return null;
  const at = new Date(nowMs);
  at.setHours(Number(match[1]), Number(match[2]), 0, 0);
  let ms = at.getTime();
  if (ms <= nowMs) ms += DAY_MS;
  return ms;
}

function ceilingSteps(max: number): number[] {
  return CEILING_FRACTIONS.map((f) => Math.round(f * max * 100) / 100).filter((c) => c >= MIN_CEILING);
}

function renderCeilingChoices(max: number): void {
  const wanted = ["none", ...ceilingSteps(max).map(String)];
  const have = [...ceilingChoices.children].map((b) => (b as HTMLElement).dataset["ceiling"]);
  if (wanted.join() === have.join()) return;
  ceilingChoices.replaceChildren(
    ...wanted.map((value) => {
      const button = document.createElement("button");
      button.type = "button";
      button.className = "choice";
      button.dataset["ceiling"] = value;
      button.dataset["testid"] = `ceiling-${value}`;
      button.textContent = value === "none" ? "No limit" : `${percent(Number(value) / max)} at most`;
      button.addEventListener("click", () =>
        change("ceiling", { ceiling: value === "none" ? null : Number(value) }),
      );
      return button;
    }),
  );
}

function renderSenders(senders: readonly Sender[]): void {
  const byName = new Map<string, HTMLLIElement>();
  for (const item of sendersList.children)
    byName.set((item as HTMLElement).dataset["sender"]!, item as HTMLLIElement);
  // Updated in place, not rebuilt: the button the wearer just pressed keeps the focus.
  const items = senders.map((sender) => {
    let item = byName.get(sender.name);
    if (item === undefined) {
      item = document.createElement("li");
      item.dataset["sender"] = sender.name;
      const name = document.createElement("span");
      name.className = "sender-name";
      const button = document.createElement("button");
      button.type = "button";
      button.className = "choice";
      button.dataset["testid"] = `sender-${sender.name}`;
      button.addEventListener("click", () => {
        const blocked = item!.dataset["blocked"] === "true";
        void change(blocked ? "unblock" : "block", { sender: sender.name });
      });
      item.append(name, button);
    }
    item.dataset["blocked"] = String(sender.blocked);
    const [name, button] = item.children as unknown as [HTMLSpanElement, HTMLButtonElement];
    const who = sender.name === "page" ? "The drawing page on the sleeve's computer" : sender.name;
    name.textContent = sender.blocked ? `${who}: blocked` : who;
    button.hidden = !sender.blockable;
    button.textContent = sender.blocked ? "Unblock" : "Block";
    button.setAttribute("aria-label", `${sender.blocked ? "Unblock" : "Block"} ${who}`);
    return item;
  });
  if (
    items.some((item, i) => sendersList.children[i] !== item) ||
    sendersList.children.length !== items.length
  ) {
    sendersList.replaceChildren(...items);
  }
}

/** The words a screen reader says when they change (pause, ceiling, do not disturb, online). */
function summary(s: WearerState): string {
  const c = s.controls;
  if (c === null) return "The sleeve is starting.";
  const parts = [
    s.online ? "" : "The sleeve is offline.",
    c.paused ? "Paused: nothing plays." : "Playing what senders draw.",
    c.ceiling === null ? "" : `Strongest vibration ${percent(c.ceiling / s.max_intensity)}.`,
    c.do_not_disturb_until_ms === null ? "" : `Do not disturb until ${clock(c.do_not_disturb_until_ms)}.`,
  ];
  return parts.filter(Boolean).join(" ");
}

function render(s: WearerState): void {
  state = s;
  const c = s.controls;
  // Not disabled while a change is under way: a disabled button would lose the focus (the
  // screen reader's place); change() ignores a second press until the first is answered.
  const ready = c !== null;
  sleeveLine.dataset["state"] = c === null ? "starting" : s.online ? "online" : "offline";
  sleeveLine.textContent =
    c === null
      ? `Sleeve ${s.sleeve_id} is starting…`
      : s.online
        ? `Sleeve ${s.sleeve_id} is on.`
        : `Sleeve ${s.sleeve_id} is offline: it cannot reach the broker. Your choices here still hold.`;

  pauseButton.dataset["paused"] = String(c?.paused ?? false);
  pauseButton.textContent = c?.paused ? "Resume the sleeve" : "Pause the sleeve";
  pauseLine.textContent =
    c === null
      ? ""
      : c.paused
        ? `Paused${c.paused_by === "button" ? " with the sleeve's button" : ""}: nothing plays until you resume.`
        : "Playing: what senders draw, you feel.";
  pauseButton.disabled = !ready;
  stopButton.disabled = !ready;

  renderCeilingChoices(s.max_intensity);
  for (const button of ceilingChoices.querySelectorAll<HTMLButtonElement>("button")) {
    const value = button.dataset["ceiling"];
    const chosen =
      value === "none"
        ? c?.ceiling === null
        : c?.ceiling != null && Math.abs(c.ceiling - Number(value)) < 0.005;
    button.setAttribute("aria-pressed", String(chosen));
    button.disabled = !ready;
  }
  ceilingLine.textContent =
    c === null
      ? ""
      : c.ceiling === null
        ? "No limit: as strong as the sender draws."
        : `At most ${percent(c.ceiling / s.max_intensity)} of the sleeve's strongest.`;

  const until = c?.do_not_disturb_until_ms ?? null;
  dndLine.dataset["until"] = until === null ? "" : String(until);
  dndLine.textContent =
    until === null ? "Off: senders may draw on you." : `On until ${clock(until)}: nothing reaches you.`;
  dndEnd.hidden = until === null;
  dndEnd.disabled = !ready;
  for (const button of document.querySelectorAll<HTMLButtonElement>(
    "[data-minutes], [data-testid='dnd-set']",
  )) {
    button.disabled = !ready;
  }

  sendersLine.textContent = s.blocking
    ? "Block a sender to stop them drawing on you until you unblock them."
    : "Blocking a sender needs the broker feelmysign runs; this sleeve uses another one.";
  renderSenders(s.senders);

  const said = summary(s);
  if (said !== lastSaid) {
    lastSaid = said;
    live.textContent = said;
  }
}

function showProblem(error: unknown): void {
  problem.textContent =
    error instanceof WearerApiError
      ? error.message
      : "The sleeve's server does not answer: check that the phone is on the same network, then reload.";
  problem.hidden = false;
  if (error instanceof WearerApiError && error.status === 403) sleeveLine.dataset["state"] = "no-key";
}

async function change(action: Action, body: object = {}): Promise<void> {
  if (busy) return;
  busy = true;
  try {
    const next = await act(action, body);
    problem.hidden = true;
    changeRefused = false;
    busy = false;
    render(next);
    if (action === "stop") live.textContent = "Stopped what was playing.";
  } catch (error) {
    busy = false;
    if (state !== null) render(state);
    changeRefused = true;
    showProblem(error);
  }
}

async function poll(): Promise<void> {
  try {
    const next = await readState();
    if (!busy) render(next);
    if (!changeRefused) problem.hidden = true;
  } catch (error) {
    showProblem(error);
  } finally {
    // After the answer, not on a fixed beat: a slow network never piles up requests.
    setTimeout(() => void poll(), POLL_INTERVAL_MS);
  }
}

pauseButton.addEventListener("click", () => void change(state?.controls?.paused ? "resume" : "pause"));
stopButton.addEventListener("click", () => void change("stop"));
for (const button of document.querySelectorAll<HTMLButtonElement>("[data-minutes]")) {
  button.addEventListener("click", () =>
    change("do-not-disturb", { until_ms: Date.now() + Number(button.dataset["minutes"]) * MINUTE_MS }),
  );
}
dndUntil.addEventListener("submit", (event) => {
  event.preventDefault();
  const until = nextTimeMs(dndTime.value, Date.now());
  if (until === null) {
    showProblem(new WearerApiError("Choose a time, such as 22:30.", 400));
    return;
  }
  void change("do-not-disturb", { until_ms: until });
});
dndEnd.addEventListener("click", () => void change("do-not-disturb", { until_ms: null }));

void poll();
