/**
 * One participant's session, as section 6.1 of the paper orders it: consent, the comfort
 * check, the trials (send the shape, type the free answer), the questionnaire. The step
 * comes from the server every time, so a reload or a restarted server resumes exactly.
 */
import { api, type Overview, type SendSummary, type State, type Trial } from "./api";
import { h, plural } from "./dom";

export interface SessionHooks {
  overview: () => Overview;
  changed: () => void;
  fail: (error: unknown) => void;
}

const CONFIDENCE_POINTS = 5;

export function sentText(sent: SendSummary): string {
  const parts = [`played ${sent.played} of ${plural(sent.strokes, "stroke")}`];
  if ((sent.cut_short ?? 0) > 0) parts.push(`${sent.cut_short} cut short`);
  if ((sent.cancelled ?? 0) > 0) parts.push(`${sent.cancelled} cancelled`);
  if (sent.adjusted > 0) parts.push(`${sent.adjusted} slowed to be felt`);
  if ((sent.compressed ?? 0) > 0) {
    parts.push(
      `${sent.compressed} faster to catch up (${Math.round(sent.compressed_ms ?? 0)} ms shorter in all)`,
    );
  }
  if (sent.rejected.length > 0) parts.push(`rejected: ${sent.rejected.join(", ")}`);
  if (sent.latency_ms_max !== null) parts.push(`latency at most ${sent.latency_ms_max.toFixed(1)} ms`);
  if (sent.error) parts.push(`error: ${sent.error}`);
  return parts.join(" · ");
}

/**
 * What the trial sends, after its shape: its resolution and strokes, and its drawing speed
 * when the design compares speeds (a design of one speed shows what it always showed).
 */
export function trialDetail(trial: Trial, speedIsFactor: boolean): string {
  const parts = [
    trial.resolution
      ? `${trial.resolution}, ${plural(trial.segments, "stroke")}`
      : plural(trial.segments, "stroke"),
  ];
  if (speedIsFactor && trial.speed_cm_s !== null) parts.push(`${trial.speed_cm_s} cm/s`);
  return ` · ${parts.join(" · ")}`;
}

export class SessionView {
  readonly #root: HTMLElement;
  readonly #hooks: SessionHooks;
  #code: string | null = null;

  constructor(root: HTMLElement, hooks: SessionHooks) {
    this.#root = root;
    this.#hooks = hooks;
    this.#root.replaceChildren(h("p", { class: "hint" }, "Choose or add a participant."));
  }

  get code(): string | null {
    return this.#code;
  }

  async open(code: string): Promise<void> {
    this.#code = code;
    history.replaceState(null, "", `#${encodeURIComponent(code)}`);
    this.render(await api.state(code));
  }

  render(state: State): void {
    const head = h(
      "header",
      { class: "session-head" },
      h("h2", { "data-testid": "participant-code" }, state.participant),
      h("span", { class: "chip" }, state.simulated ? "simulated participant" : "participant"),
      h(
        "span",
        { class: "progress", "data-testid": "progress" },
        `${state.answered} of ${state.total} answered`,
      ),
      state.step === "trial" ? this.#pauseButton(state) : null,
    );
    const body = state.paused ? this.#paused(state) : this.#step(state);
    this.#root.replaceChildren(head, body);
    this.#root.dataset["step"] = state.paused ? "paused" : state.step;
    this.#hooks.changed();
  }

  #run(action: () => Promise<{ state: State } | State>): void {
    action()
      .then((result) => this.render("state" in result ? result.state : result))
      .catch(this.#hooks.fail);
  }

  #pauseButton(state: State): HTMLElement {
    const code = state.participant;
    return h(
      "button",
      {
        type: "button",
        class: "button",
        "data-testid": "pause",
        onclick: () => this.#run(() => api.pause(code, !state.paused)),
      },
      state.paused ? "Resume" : "Pause",
    );
  }

  #paused(state: State): HTMLElement {
    return h(
      "div",
      { class: "card" },
      h("p", {}, "The session is paused. Every answer so far is stored."),
      h(
        "button",
        {
          type: "button",
          class: "button button-primary",
          "data-testid": "resume",
          onclick: () => this.#run(() => api.pause(state.participant, false)),
        },
        "Resume",
      ),
    );
  }

  #step(state: State): HTMLElement {
    switch (state.step) {
      case "consent":
        return this.#consent(state.participant);
      case "comfort":
        return this.#comfort(state.participant);
      case "trial":
        return this.#trial(state.participant, state.trial!);
      case "questionnaire":
        return this.#questionnaire(state.participant);
      case "done":
        return h(
          "div",
          { class: "card", "data-testid": "done" },
          h("p", {}, "Session complete. Thank the participant."),
        );
      default:
        return h("div", { class: "card" }, h("p", {}, "This participant has withdrawn."));
    }
  }

  #consent(code: string): HTMLElement {
    const box = h("input", { type: "checkbox", id: "consent-box", "data-testid": "consent-box" });
    const start = h(
      "button",
      { type: "button", class: "button button-primary", "data-testid": "consent-yes", disabled: true },
      "Start",
    );
    box.addEventListener("change", () => (start.disabled = !box.checked));
    start.addEventListener("click", () => this.#run(() => api.consent(code, true)));
    return h(
      "div",
      { class: "card" },
      h("h3", {}, "1 · Consent"),
      h(
        "p",
        {},
        "The participant has read the information sheet and puts on the sleeve, with help if needed.",
      ),
      h("label", { class: "check" }, box, " The participant has given informed consent."),
      h(
        "div",
        { class: "row" },
        start,
        h(
          "button",
          { type: "button", class: "button", onclick: () => this.#run(() => api.consent(code, false)) },
          "Declined",
        ),
      ),
    );
  }

  #comfort(code: string): HTMLElement {
    const questions = this.#hooks.overview().comfort;
    const boxes = questions.map((_, i) => h("input", { type: "checkbox", "data-testid": `comfort-${i}` }));
    const adjusted = h("input", { type: "checkbox", "data-testid": "comfort-adjusted" });
    return h(
      "div",
      { class: "card" },
      h("h3", {}, "2 · Comfort check"),
      h("p", { class: "hint" }, "Ask, adjust the sleeve until it fits comfortably, then tick what holds."),
      ...questions.map((question, i) => h("label", { class: "check" }, boxes[i]!, ` ${question}`)),
      h("label", { class: "check" }, adjusted, " The sleeve was adjusted."),
      h(
        "button",
        {
          type: "button",
          class: "button button-primary",
          "data-testid": "comfort-done",
          onclick: () =>
            this.#run(() =>
              api.comfort(
                code,
                boxes.map((b) => b.checked),
                adjusted.checked,
              ),
            ),
        },
        "Continue to the trials",
      ),
    );
  }

  #trial(code: string, trial: Trial): HTMLElement {
    const what =
      trial.block === "practice"
        ? "practice (tell the participant the shape)"
        : `repetition ${trial.repetition}`;
    const status = h(
      "p",
      { class: "send-status", "data-testid": "send-status" },
      trial.last_send ? sentText(trial.last_send) : "Not sent yet.",
    );
    const send = h(
      "button",
      { type: "button", class: "button button-primary", "data-testid": "send" },
      trial.sends ? "Send again" : "Send to the sleeve",
    );
    const answer = h("input", {
      type: "text",
      class: "answer",
      maxlength: 200,
      autocomplete: "off",
      placeholder: "What the participant says, in their words",
      "data-testid": "answer",
    });
    const confidence = h(
      "select",
      { "data-testid": "confidence", "aria-label": "Confidence" },
      h("option", { value: "" }, "no confidence given"),
      ...Array.from({ length: CONFIDENCE_POINTS }, (_, i) =>
        h("option", { value: String(i + 1) }, `confidence ${i + 1} of ${CONFIDENCE_POINTS}`),
      ),
    );
    const record = h(
      "button",
      {
        type: "button",
        class: "button button-primary",
        "data-testid": "record",
        disabled: trial.sends === 0,
      },
      "Record answer",
    );
    const nothing = h(
      "button",
      { type: "button", class: "button", "data-testid": "felt-nothing", disabled: trial.sends === 0 },
      "Felt nothing",
    );
    const submit = (feltNothing: boolean) => {
      // Felt nothing: there is nothing to be confident of, whatever the list shows.
      const value = feltNothing || confidence.value === "" ? null : Number(confidence.value);
      this.#run(() => api.answer(code, trial.id, feltNothing ? "" : answer.value, feltNothing, value));
    };
    send.addEventListener("click", () => {
      // No answer while the shape plays (a repeat send too): it answers what was felt.
      send.disabled = record.disabled = nothing.disabled = true;
      status.textContent = "Sending… the sleeve is playing the shape.";
      api
        .send(code, trial.id)
        .then((result) => this.render(result.state))
        .catch((error: unknown) => {
          send.disabled = false;
          record.disabled = nothing.disabled = trial.sends === 0;
          this.#hooks.fail(error);
        });
    });
    record.addEventListener("click", () => submit(false));
    nothing.addEventListener("click", () => submit(true));
    answer.addEventListener("keydown", (event) => {
      if (event.key === "Enter" && !record.disabled && answer.value.trim()) submit(false);
    });
    const card = h(
      "div",
      { class: "card trial", "data-testid": "trial", "data-trial": trial.id },
      h("p", { class: "trial-number" }, `Trial ${trial.number} of ${trial.total} · ${what}`),
      h(
        "p",
        { class: "trial-shape", "data-testid": "trial-shape" },
        `${trial.shape}`,
        h("span", {}, trialDetail(trial, this.#hooks.overview().speeds_cm_s.length > 1)),
      ),
      h(
        "p",
        { class: "hint" },
        "The participant must not see this screen. Ask “What shape did you feel, if any?”, without options.",
      ),
      h("div", { class: "row" }, send),
      status,
      h(
        "div",
        { class: "row" },
        h("label", { class: "answer-label" }, "Answer, in their words ", answer),
        confidence,
      ),
      h("div", { class: "row" }, record, nothing),
    );
    if (
      trial.sends > 0 &&
      this.#hooks.overview().participants.find((p) => p.participant === code)?.simulated
    ) {
      card.append(this.#simulated(code, answer, confidence));
    }
    queueMicrotask(() => answer.focus());
    return card;
  }

  #simulated(code: string, answer: HTMLInputElement, confidence: HTMLSelectElement): HTMLElement {
    const line = h(
      "p",
      { class: "simulated", "data-testid": "simulated-answer" },
      "The simulated participant is thinking…",
    );
    api
      .simulatedAnswer(code)
      .then((reply) => {
        line.dataset["answer"] = reply.answer;
        line.dataset["feltNothing"] = String(reply.felt_nothing);
        line.dataset["confidence"] = reply.confidence === null ? "" : String(reply.confidence);
        line.textContent = reply.felt_nothing
          ? "Simulated participant: “I felt nothing.”"
          : `Simulated participant: “${reply.answer}” (confidence ${reply.confidence ?? "none"})`;
        if (!reply.felt_nothing) {
          line.append(
            " ",
            h(
              "button",
              {
                type: "button",
                class: "button button-quiet",
                onclick: () => {
                  answer.value = reply.answer;
                  confidence.value = reply.confidence === null ? "" : String(reply.confidence);
                },
              },
              "Type it in",
            ),
          );
        }
      })
      .catch(this.#hooks.fail);
    return line;
  }

  #questionnaire(code: string): HTMLElement {
    const { items, points, labels } = this.#hooks.overview().questionnaire;
    const groups = items.map((item, i) =>
      h(
        "fieldset",
        { class: "likert", "data-testid": `likert-${i}` },
        h("legend", {}, item),
        ...Array.from({ length: points }, (_, p) =>
          h(
            "label",
            {},
            h("input", { type: "radio", name: `likert-${i}`, value: String(p + 1) }),
            ` ${p + 1}${labels[p] ? ` ${labels[p]}` : ""}`,
          ),
        ),
      ),
    );
    const submit = h(
      "button",
      { type: "button", class: "button button-primary", "data-testid": "questionnaire-done" },
      "Save the questionnaire",
    );
    submit.addEventListener("click", () => {
      const values = groups.map((group) =>
        Number(group.querySelector<HTMLInputElement>("input:checked")?.value ?? 0),
      );
      if (values.some((v) => v === 0)) {
        this.#hooks.fail(new Error("Answer every item of the questionnaire."));
        return;
      }
      this.#run(() => api.questionnaire(code, values));
    });
    return h(
      "div",
      { class: "card" },
      h("h3", {}, "4 · Questionnaire"),
      // The design's own items say what is asked; the hint only says how to ask them.
      h(
        "p",
        { class: "hint" },
        `Read ${items.length === 1 ? "the statement" : `each of the ${items.length} statements`} to the participant and choose their answer` +
          ` (1 to ${points}).`,
      ),
      ...groups,
      submit,
    );
  }
}
