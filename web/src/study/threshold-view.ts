/**
 * SQ2.2 on the researcher's page: the QUEST+ direction-threshold procedure for the chosen
 * participant. Send the stroke QUEST+ chose, ask "Which way did it move?", click (or press
 * the arrow key of) the direction the wearer named. The running estimate, its 95% interval
 * and the stopping rule are shown after every answer; every trial is in the study file.
 * The direction sent is hidden until the answer is in, so the researcher records blind.
 */
import { sentText } from "./session-view";
import {
  thresholdApi,
  type Dimension,
  type Direction,
  type ThresholdDimension,
  type ThresholdEstimate,
  type ThresholdRun,
  type ThresholdState,
} from "./api";
import { h, plural } from "./dom";

const DIRECTIONS: Direction[] = ["up", "down", "left", "right"];
const ARROWS: Record<string, Direction> = {
  ArrowUp: "up",
  ArrowDown: "down",
  ArrowLeft: "left",
  ArrowRight: "right",
};
const SYMBOL: Record<Direction, string> = { up: "↑", down: "↓", left: "←", right: "→" };

const number = (value: number) => String(Number(value.toPrecision(3)));

/**
 * A run's estimate in words: the threshold and its 95% interval, or, where the interval reaches
 * an end of the tested range, what the run says instead (Python `Estimate.words`).
 */
export function estimateWords(estimate: ThresholdEstimate, unit: string, bracketed = false): string {
  const interval = `95% interval ${number(estimate.low)} to ${number(estimate.high)}`;
  if (estimate.censored === "above") {
    return `not measured: the ${interval} reaches the top of the tested range, so the threshold may lie above it (the wearer told the direction hardly better than by chance)`;
  }
  if (estimate.censored === "below") {
    return `at most ${number(estimate.threshold)} ${unit}: the ${interval} reaches the bottom of the tested range (a bound, not a measurement)`;
  }
  return bracketed
    ? `${number(estimate.threshold)} ${unit} (${interval})`
    : `${number(estimate.threshold)} ${unit}, ${interval}`;
}

export class ThresholdView {
  readonly #root: HTMLElement;
  readonly #code: () => string | null;
  readonly #fail: (error: unknown) => void;
  #dimension: Dimension = "length";
  #busy = false;
  #answerKey: ((event: KeyboardEvent) => void) | null = null;

  constructor(root: HTMLElement, code: () => string | null, fail: (error: unknown) => void) {
    this.#root = root;
    this.#code = code;
    this.#fail = fail;
    // Arrow keys answer only while this view is shown.
    document.addEventListener("keydown", (event) => {
      if (!this.#root.hidden) this.#answerKey?.(event);
    });
  }

  async show(): Promise<void> {
    const code = this.#code();
    if (code === null) {
      this.#answerKey = null;
      this.#root.replaceChildren(
        h("h2", {}, "Threshold (SQ2.2)"),
        h("p", { class: "hint" }, "Choose or add a participant (with consent) first."),
      );
      return;
    }
    this.render(await thresholdApi.state(code));
  }

  #act(action: () => Promise<ThresholdState>): void {
    if (this.#busy) return;
    this.#busy = true;
    this.#root.dataset["busy"] = "true";
    action()
      .then((state) => this.render(state))
      .catch(this.#fail)
      .finally(() => {
        this.#busy = false;
        delete this.#root.dataset["busy"];
      });
  }

  render(state: ThresholdState): void {
    const dimension = state.dimensions[this.#dimension];
    const choose = h(
      "div",
      { class: "row", role: "group", "aria-label": "What varies" },
      ...(["length", "duration"] as Dimension[]).map((d) =>
        h(
          "button",
          {
            type: "button",
            class: "button",
            "aria-pressed": String(d === this.#dimension),
            "data-testid": `threshold-${d}`,
            onclick: () => {
              this.#dimension = d;
              this.render(state);
            },
          },
          d === "length" ? "Shortest stroke (length)" : "Briefest stroke (duration)",
        ),
      ),
    );
    const fixed =
      this.#dimension === "length"
        ? `Each stroke lasts ${dimension.fixed} ms; its length varies from ${dimension.range[0]} to ${dimension.range[1]} grid units.`
        : `Each stroke is ${dimension.fixed} grid units long; its duration varies from ${dimension.range[0]} to ${dimension.range[1]} ms.`;
    this.#root.replaceChildren(
      h("h2", {}, `Threshold (SQ2.2) · ${state.participant}`),
      h(
        "p",
        { class: "hint" },
        "A straight stroke through the middle of the sleeve, up, down, left or right; the wearer says which way it moved (four alternatives). QUEST+ chooses each stroke.",
      ),
      choose,
      h("p", { class: "hint" }, `${fixed} The run ${state.stopping_rule}.`),
      dimension.run ? this.#run(state, dimension, dimension.run) : this.#start(state, dimension),
      ...(dimension.finished_runs.length + dimension.discarded_runs.length > 0
        ? [this.#finished(dimension)]
        : []),
    );
    this.#root.dataset["dimension"] = this.#dimension;
  }

  #start(state: ThresholdState, dimension: ThresholdDimension): HTMLElement {
    this.#answerKey = null;
    const finished = dimension.finished_runs.length;
    const start = () => this.#act(() => thresholdApi.send(state.participant, this.#dimension));
    const card = h("div", { class: "card", "data-testid": "threshold-start" });
    if (finished === 0) {
      card.append(
        h(
          "button",
          { type: "button", class: "button button-primary", "data-testid": "threshold-send", onclick: start },
          "Start: send the first stroke",
        ),
      );
      return card;
    }
    // A participant's run is done: another one is a decision, not a stray click.
    const ask = h(
      "button",
      { type: "button", class: "button", "data-testid": "threshold-another" },
      "Start another run…",
    );
    ask.addEventListener("click", () => {
      card.replaceChildren(
        h(
          "p",
          { "data-testid": "threshold-another-question" },
          `${state.participant} has ${plural(finished, "finished run")} of the ${this.#dimension}. ` +
            "Another run is stored beside it; a run started by mistake can be discarded.",
        ),
        h(
          "div",
          { class: "row" },
          h(
            "button",
            {
              type: "button",
              class: "button button-primary",
              "data-testid": "threshold-send",
              onclick: start,
            },
            "Start another run: send the first stroke",
          ),
          h(
            "button",
            {
              type: "button",
              class: "button",
              "data-testid": "threshold-another-cancel",
              onclick: () => this.render(state),
            },
            "Cancel",
          ),
        ),
      );
    });
    card.append(ask);
    return card;
  }

  /** Discard the run under way, after a second, explicit click. */
  #discard(state: ThresholdState, run: ThresholdRun): HTMLElement {
    const row = h("div", { class: "row" });
    const ask = h(
      "button",
      { type: "button", class: "button button-quiet", "data-testid": "threshold-discard" },
      "Discard this run…",
    );
    ask.addEventListener("click", () => {
      row.replaceChildren(
        h(
          "span",
          { class: "hint" },
          `Discard this run of ${plural(run.trials.length, "trial")}? It stays in the study file, marked discarded, and is left out of the results.`,
        ),
        h(
          "button",
          {
            type: "button",
            class: "button",
            "data-testid": "threshold-discard-confirm",
            onclick: () => this.#act(() => thresholdApi.discard(state.participant, this.#dimension)),
          },
          "Discard",
        ),
        h(
          "button",
          {
            type: "button",
            class: "button",
            "data-testid": "threshold-discard-cancel",
            onclick: () => row.replaceChildren(ask),
          },
          "Keep it",
        ),
      );
    });
    row.append(ask);
    return row;
  }

  #run(state: ThresholdState, dimension: ThresholdDimension, run: ThresholdRun): HTMLElement {
    const { next } = run;
    const answer = (response: Direction) =>
      this.#act(() => thresholdApi.answer(state.participant, this.#dimension, next.position, response));
    this.#answerKey = next.sent
      ? (event) => {
          const direction = ARROWS[event.key];
          if (direction && !(event.target instanceof HTMLInputElement)) {
            event.preventDefault();
            answer(direction);
          }
        }
      : null;
    const estimate = run.estimate ? estimateWords(run.estimate, dimension.unit, true) : "none yet";
    const card = h(
      "div",
      { class: "card trial", "data-testid": "threshold-run", "data-position": next.position },
      h(
        "p",
        { class: "trial-number" },
        `Trial ${next.position + 1} · ${next.sent ? "sent: ask “Which way did it move?”" : "not sent yet"}`,
      ),
      h("p", { class: "trial-shape" }, `${number(next.value)} ${dimension.unit}`),
      h(
        "div",
        { class: "row" },
        h(
          "button",
          {
            type: "button",
            class: next.sent ? "button" : "button button-primary",
            "data-testid": "threshold-send",
            onclick: () => this.#act(() => thresholdApi.send(state.participant, this.#dimension)),
          },
          next.sent ? "Send again" : "Send to the sleeve",
        ),
      ),
      h(
        "p",
        { class: "send-status", "data-testid": "threshold-send-status" },
        run.last_send ? sentText(run.last_send) : "Not sent yet.",
      ),
      h(
        "div",
        { class: "row directions", role: "group", "aria-label": "The direction the wearer named" },
        ...DIRECTIONS.map((direction) =>
          h(
            "button",
            {
              type: "button",
              class: "button",
              disabled: !next.sent,
              "data-testid": `threshold-answer-${direction}`,
              onclick: () => answer(direction),
            },
            `${SYMBOL[direction]} ${direction}`,
          ),
        ),
      ),
      h(
        "p",
        { "data-testid": "threshold-estimate" },
        `Estimate after ${run.trials.length} trial${run.trials.length === 1 ? "" : "s"}: ${estimate}`,
      ),
    );
    if (run.simulated_answer) {
      card.append(
        h(
          "p",
          { class: "simulated", "data-testid": "threshold-simulated", "data-answer": run.simulated_answer },
          `Simulated participant: “${run.simulated_answer}”`,
        ),
      );
    }
    card.append(this.#discard(state, run));
    if (run.trials.length > 0) {
      card.append(
        h(
          "ol",
          { class: "threshold-trials", reversed: true, "data-testid": "threshold-trials" },
          ...run.trials
            .slice()
            .reverse()
            .map((t) =>
              h(
                "li",
                { class: t.correct ? "right" : "wrong" },
                `${number(t.value)} ${dimension.unit}: sent ${SYMBOL[t.direction]}, answered ${SYMBOL[t.response]} (${t.correct ? "right" : "wrong"})`,
              ),
            ),
        ),
      );
    }
    return card;
  }

  #finished(dimension: ThresholdDimension): HTMLElement {
    return h(
      "div",
      { class: "card" },
      h("h3", {}, "Finished runs"),
      h(
        "ul",
        { "data-testid": "threshold-finished" },
        ...dimension.finished_runs.map((r) =>
          h(
            "li",
            { "data-run": r.run },
            `${estimateWords(r, dimension.unit)}, after ${plural(r.trials, "trial")}${r.stop_reason === `${r.trials} trials` ? "" : ` (stopped: ${r.stop_reason})`}`,
          ),
        ),
      ),
      ...(dimension.discarded_runs.length > 0
        ? [
            h(
              "p",
              { class: "hint", "data-testid": "threshold-discarded" },
              `Discarded (kept in the study file, left out of the results): ${dimension.discarded_runs
                .map((r) => `run ${r.run} after ${plural(r.trials, "trial")}`)
                .join("; ")}.`,
            ),
          ]
        : []),
    );
  }
}
