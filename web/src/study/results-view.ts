/** Export and analyse on the server; show the report and its figures. */
import { api, type AnalysisResult } from "./api";
import { h, plural } from "./dom";
import { reportHtml } from "./report";

export class ResultsView {
  readonly #root: HTMLElement;
  readonly #fail: (error: unknown) => void;

  constructor(root: HTMLElement, fail: (error: unknown) => void) {
    this.#root = root;
    this.#fail = fail;
    const run = h(
      "button",
      { type: "button", class: "button button-primary", "data-testid": "analyse" },
      "Export and analyse",
    );
    const status = h(
      "p",
      { class: "hint", "data-testid": "analyse-status" },
      "Writes the anonymised CSV, the design, the figures and a report.",
    );
    run.addEventListener("click", () => {
      run.disabled = true;
      status.textContent = "Analysing (the bootstrap takes a few seconds)…";
      api
        .analyse()
        .then((result) => this.#show(result, status))
        .catch(this.#fail)
        .finally(() => (run.disabled = false));
    });
    this.#root.replaceChildren(
      h("h2", {}, "Results"),
      h("div", { class: "row" }, run),
      status,
      h("div", { id: "results-body" }),
    );
  }

  #show(result: AnalysisResult, status: HTMLElement): void {
    status.textContent = `${plural(result.participants, "participant")} analysed; ${result.unclear} answer(s) await review. Files in ${result.folder}.`;
    const stamp = Date.now();
    const figureUrl = (name: string): string => `/api/study/results/${name}?t=${stamp}`;
    // The report shows its figures in place; any other figure the analysis wrote, above it.
    const figures = result.files
      .filter((name) => name.endsWith(".png") && !result.report.includes(`](${name})`))
      .map((name) => h("img", { src: figureUrl(name), alt: name, "data-testid": `figure-${name}` }));
    const links = result.files.map((name) =>
      h("li", {}, h("a", { href: `/api/study/results/${name}`, download: name }, name)),
    );
    const report = h("div", { class: "report", "data-testid": "report" });
    // Safe as markup: reportHtml renders no HTML of the report's own (html: false).
    report.innerHTML = reportHtml(result.report, figureUrl);
    const body = this.#root.querySelector("#results-body")!;
    body.replaceChildren(
      h("div", { class: "figures" }, ...figures),
      h("ul", { class: "files" }, ...links),
      report,
    );
  }
}
