/**
 * The wearer's page, served at /wearer by `feelmysign up` (and the sleeve): pause and
 * resume, stop, the strongest vibration allowed, "do not disturb", and blocking senders.
 * Made for a phone and a screen reader: large real buttons, a live region saying what
 * changed. It reads the sleeve's state every second; each button's answer is the new state.
 */
import "./wearer.css";
import { act, readState, WearerApiError, type Action, type Sender, type WearerState } from "./api";
import {
  ceilingChoiceLabel,
  ceilingChoices,
  ceilingLine,
  doNotDisturbLine,
  blockedSaid,
  playLine,
  sendersLine,
  STOPPED_SAID,
  summary,
  UNREACHABLE_LINE,
  UNREACHABLE_SAID,
  untilHint,
  untilTime,
} from "./words";

const POLL_INTERVAL_MS = 1000;
const MINUTE_MS = 60_000;

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
const ceilingLineElement = byId<HTMLParagraphElement>("ceiling-line");
const ceilingChoicesElement = byId<HTMLDivElement>("ceiling-choices");
const dndLine = byId<HTMLParagraphElement>("dnd-line");
const dndUntil = byId<HTMLFormElement>("dnd-until");
const dndTime = byId<HTMLInputElement>("dnd-time");
const dndTimeHint = byId<HTMLParagraphElement>("dnd-time-hint");
const dndEnd = byId<HTMLButtonElement>("dnd-end");
const sendersLineElement = byId<HTMLParagraphElement>("senders-line");
const sendersList = byId<HTMLUListElement>("senders");

let state: WearerState | null = null;
// Changes under way: while any is, a poll's older state is not shown over what the wearer did.
let pending = 0;
// Changes run one after the other, in the order tapped (a second tap waits for the first's
// answer, never lost); Pause and Stop never wait behind another change.
let queue: Promise<unknown> = Promise.resolve();
let lastSaid = "";
// A refused change stays on screen until the next change succeeds (a poll does not hide it).
let changeRefused = false;

/** Strongest first: no ceiling (the strongest this sleeve allows), then the ceilings below it. */
function renderCeilingChoices(max: number): void {
  const wanted: (number | null)[] = [null, ...ceilingChoices(max)];
  const key = (ceiling: number | null) => (ceiling === null ? "none" : String(ceiling));
  const have = [...ceilingChoicesElement.children].map((b) => (b as HTMLElement).dataset["ceiling"]);
  const labels = [...ceilingChoicesElement.children].map((b) => b.textContent);
  if (
    wanted.map(key).join() === have.join() &&
    wanted.map((c) => ceilingChoiceLabel(c, max)).join() === labels.join()
  )
    return;
  ceilingChoicesElement.replaceChildren(
    ...wanted.map((ceiling) => {
      const button = document.createElement("button");
      button.type = "button";
      button.className = "choice";
      button.dataset["ceiling"] = key(ceiling);
      button.dataset["testid"] = `ceiling-${key(ceiling)}`;
      button.textContent = ceilingChoiceLabel(ceiling, max);
      button.addEventListener("click", () => void change("ceiling", { ceiling }));
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
    button.disabled = false; // again, after the sleeve did not answer
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

function render(s: WearerState): void {
  state = s;
  const c = s.controls;
  // Not disabled while a change is under way: a disabled button would lose the focus (the
  // screen reader's place); change() queues a second press behind the first.
  const ready = c !== null;
  sleeveLine.dataset["state"] = c === null ? "starting" : s.online ? "online" : "offline";
  sleeveLine.textContent =
    c === null
      ? `Sleeve ${s.sleeve_id} is starting…`
      : s.online
        ? `Sleeve ${s.sleeve_id} is on.`
        : `Sleeve ${s.sleeve_id} is running but cannot reach the broker: senders' drawings do not reach it. Your choices here still hold.`;

  pauseButton.dataset["paused"] = String(c?.paused ?? false);
  pauseButton.textContent = c?.paused ? "Resume the sleeve" : "Pause the sleeve";
  pauseLine.textContent = c === null ? "" : playLine(c, Date.now());
  pauseButton.disabled = !ready;
  stopButton.disabled = !ready;

  renderCeilingChoices(s.max_intensity);
  for (const button of ceilingChoicesElement.querySelectorAll<HTMLButtonElement>("button")) {
    const value = button.dataset["ceiling"];
    const chosen =
      value === "none"
        ? c?.ceiling === null
        : c?.ceiling != null && Math.abs(c.ceiling - Number(value)) < 0.005;
    button.setAttribute("aria-pressed", String(chosen));
    button.disabled = !ready;
  }
  ceilingLineElement.textContent = c === null ? "" : ceilingLine(c.ceiling, s.max_intensity);

  const nowMs = Date.now();
  const until = c?.do_not_disturb_until_ms ?? null;
  dndLine.dataset["until"] = until === null ? "" : String(until);
  dndLine.textContent = doNotDisturbLine(until, nowMs);
  // The hint names the day ("tomorrow at 07:00"), which moves at midnight.
  if (dndTimeHint.dataset["state"] === "hint") showTimeHint(untilHint(dndTime.value, nowMs), false);
  dndEnd.hidden = until === null;
  dndEnd.disabled = !ready;
  for (const button of document.querySelectorAll<HTMLButtonElement>(
    "[data-minutes], [data-testid='dnd-set']",
  )) {
    button.disabled = !ready;
  }

  sendersLineElement.textContent = sendersLine(s.blocking);
  renderSenders(s.senders);

  const said = summary(s, nowMs);
  if (said !== lastSaid) {
    lastSaid = said;
    live.textContent = said;
  }
}

/**
 * The page's own server does not answer (the sleeve's page: the sleeve itself is gone). Its last
 * state is not shown as if it held: the line says so and every control is disabled, as a press
 * would reach nothing. The next answer (render) enables them again.
 */
function showUnreachable(): void {
  sleeveLine.dataset["state"] = "unreachable";
  sleeveLine.textContent = UNREACHABLE_LINE;
  // Its last state may no longer hold: not shown as if it did.
  for (const line of [pauseLine, ceilingLineElement, dndLine])
    line.textContent = "Unknown: the sleeve does not answer.";
  dndEnd.hidden = true;
  for (const button of document.querySelectorAll<HTMLButtonElement>("main button")) button.disabled = true;
  problem.hidden = true;
  if (lastSaid !== UNREACHABLE_SAID) {
    lastSaid = UNREACHABLE_SAID;
    live.textContent = UNREACHABLE_SAID;
  }
}

function showProblem(error: unknown): void {
  if (!(error instanceof WearerApiError)) {
    showUnreachable();
    return;
  }
  problem.textContent = error.message;
  problem.hidden = false;
  if (error.status === 403) sleeveLine.dataset["state"] = "no-key";
}

/** Actions that stop what the wearer feels: sent at once, never queued behind another change. */
const URGENT: ReadonlySet<Action> = new Set<Action>(["stop", "pause"]);

/**
 * True when the sleeve took the change, false when refused (said). A change tapped while another
 * is under way waits for its answer, then runs: the wearer's taps are all carried out, in order.
 */
function change(action: Action, body: object = {}): Promise<boolean> {
  const run = () => apply(action, body);
  if (URGENT.has(action)) return run();
  const result = queue.then(run, run);
  queue = result;
  return result;
}

async function apply(action: Action, body: object): Promise<boolean> {
  pending++;
  try {
    const next = await act(action, body);
    problem.hidden = true;
    changeRefused = false;
    pending--;
    render(next);
    if (action === "stop") live.textContent = STOPPED_SAID;
    if (action === "block") live.textContent = blockedSaid(String((body as { sender?: unknown }).sender));
    return true;
  } catch (error) {
    pending--;
    if (state !== null && error instanceof WearerApiError) render(state);
    changeRefused = error instanceof WearerApiError;
    showProblem(error);
    return false;
  }
}

async function poll(): Promise<void> {
  try {
    const next = await readState();
    if (pending === 0) render(next);
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
/** Under the time field: what Set will do, or why it cannot (`problem`: marked so, and the field invalid). */
function showTimeHint(text: string, isProblem: boolean, state: "hint" | "done" = "hint"): void {
  dndTimeHint.textContent = text;
  dndTimeHint.dataset["state"] = isProblem ? "problem" : state;
  if (isProblem) dndTime.setAttribute("aria-invalid", "true");
  else dndTime.removeAttribute("aria-invalid");
}

dndTime.addEventListener("input", () => showTimeHint(untilHint(dndTime.value, Date.now()), false));
dndUntil.addEventListener("submit", (event) => {
  event.preventDefault();
  const until = untilTime(dndTime.value, Date.now());
  if (!until.ok) {
    showTimeHint(until.problem, true);
    dndTime.focus();
    return;
  }
  // Set: the line above says until when; the hint waits for the next time typed.
  showTimeHint("", false, "done");
  void change("do-not-disturb", { until_ms: until.untilMs }).then((done) => {
    // The sleeve refused it (its clock, its limit): said here too, where the wearer looks.
    if (done === false) showTimeHint(problem.textContent ?? "", true);
  });
});
dndEnd.addEventListener("click", () => void change("do-not-disturb", { until_ms: null }));

void poll();
