/** Export and analyse on the server; show the report and its figures. */
import { api, StudyApiError, type AnalysisJob, type AnalysisResult } from "./api";
import { h, plural } from "./dom";
import { reportHtml } from "./report";

// How often the page asks whether the analysis is done: it takes a minute or two.
const POLL_INTERVAL_MS = 1000;

/** The analysis started on the server (or the one already running there), once it ends. */
async function analysed(): Promise<AnalysisResult> {
  let job: AnalysisJob = await api.startAnalysis();
  const mine = job.job;
  while (job.state === "running") {
    await new Promise((resolve) => setTimeout(resolve, POLL_INTERVAL_MS));
    job = await api.analysis();
  }
  if (job.job !== mine) throw new StudyApiError(409, "Another analysis was started meanwhile; ask again.");
  if (job.state === "failed" || job.result === null) {
    throw new StudyApiError(500, job.error ?? "The analysis failed; see the server's terminal.");
  }
  return job.result;
}

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
      status.textContent = "Analysing (the bootstrap can take a minute or two)…";
      analysed()
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
