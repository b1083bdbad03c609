/** Answers the synonyms could not code, decided by the researcher without seeing what was sent. */
import { api } from "./api";
import { h } from "./dom";

export class ReviewView {
  readonly #root: HTMLElement;
  readonly #shapes: () => string[];
  readonly #changed: () => void;
  readonly #fail: (error: unknown) => void;

  constructor(
    root: HTMLElement,
    shapes: () => string[],
    changed: () => void,
    fail: (error: unknown) => void,
  ) {
    this.#root = root;
    this.#shapes = shapes;
    this.#changed = changed;
    this.#fail = fail;
  }

  async show(): Promise<void> {
    const items = await api.review();
    const intro = h(
      "p",
      { class: "hint" },
      "Each answer names no shape clearly. Decide which shape it means, or none; the shape that was sent is hidden so that the decision stays blind. Every decision is kept.",
    );
    const list = h("ol", { class: "review-list", "data-testid": "review-list" });
    for (const item of items) {
      const decide = (shape: string | null) =>
        api
          .decide(item.trial, shape)
          .then(() => this.show())
          .then(this.#changed)
          .catch(this.#fail);
      list.append(
        h(
          "li",
          { "data-trial": item.trial },
          h("q", {}, item.answer || "(empty)"),
          h("span", { class: "hint" }, ` ${item.rule}`),
          h(
            "div",
            { class: "row" },
            ...this.#shapes().map((shape) =>
              h("button", { type: "button", class: "button", onclick: () => void decide(shape) }, shape),
            ),
            h(
              "button",
              { type: "button", class: "button button-quiet", onclick: () => void decide(null) },
              "no shape",
            ),
          ),
        ),
      );
    }
    this.#root.replaceChildren(
      h("h2", {}, "Review"),
      intro,
      items.length ? list : h("p", { "data-testid": "review-empty" }, "Nothing to review."),
    );
  }
}
