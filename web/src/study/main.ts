/** The researcher's page of the recognition study, served by `feelmysign up --study FILE` at /study. */
import "./study.css";
import { api, StudyApiError, type Overview } from "./api";
import { byId, h } from "./dom";
import { ResultsView } from "./results-view";
import { ReviewView } from "./review-view";
import { SessionView } from "./session-view";
import { ThresholdView } from "./threshold-view";

let overview: Overview | null = null;
const notice = byId<HTMLDivElement>("notice");

function fail(error: unknown): void {
  notice.textContent = error instanceof Error ? error.message : String(error);
  notice.hidden = false;
}

function clearNotice(): void {
  notice.hidden = true;
}

const session = new SessionView(byId("view-session"), {
  overview: () => overview!,
  changed: () => {
    clearNotice();
    void refresh();
  },
  fail,
});
const review = new ReviewView(
  byId("view-review"),
  () => overview?.shapes ?? [],
  () => void refresh(),
  fail,
);
new ResultsView(byId("view-results"), fail);
const threshold = new ThresholdView(byId("view-threshold"), () => session.code, fail);

function renderParticipants(data: Overview): void {
  byId("study-name").textContent = data.name;
  byId("review-count").textContent = String(data.review);
  const list = byId("participant-list");
  list.replaceChildren(
    ...data.participants.map((p) =>
      h(
        "li",
        { class: p.participant === session.code ? "selected" : "", "data-code": p.participant },
        h(
          "button",
          {
            type: "button",
            class: "participant",
            onclick: () =>
              void session
                .open(p.participant)
                .then(() => (byId("view-threshold").hidden ? undefined : threshold.show()))
                .catch(fail),
          },
          h("strong", {}, p.participant),
          ` ${p.simulated ? "simulated · " : ""}${p.paused ? "paused" : p.step} · ${p.answered}/${p.total}`,
        ),
      ),
    ),
  );
}

async function refresh(): Promise<void> {
  try {
    overview = await api.overview();
    renderParticipants(overview);
  } catch (error) {
    fail(error);
  }
}

async function add(simulated: boolean): Promise<void> {
  try {
    const { code } = await api.addParticipant(simulated);
    await refresh();
    await session.open(code);
  } catch (error) {
    fail(error);
  }
}

function showView(name: string): void {
  for (const tab of document.querySelectorAll<HTMLButtonElement>(".tab")) {
    const active = tab.dataset["view"] === name;
    tab.setAttribute("aria-pressed", String(active));
    byId(`view-${tab.dataset["view"]}`).hidden = !active;
  }
  if (name === "review") void review.show().catch(fail);
  if (name === "threshold") void threshold.show().catch(fail);
}

byId("new-participant").addEventListener("click", () => void add(false));
byId("new-simulated").addEventListener("click", () => void add(true));
for (const tab of document.querySelectorAll<HTMLButtonElement>(".tab")) {
  tab.addEventListener("click", () => showView(tab.dataset["view"] ?? "session"));
}

void refresh().then(() => {
  // Reopen the participant of the URL (#P-XXXXX) after a reload or a server restart.
  const code = decodeURIComponent(location.hash.slice(1));
  if (code && overview?.participants.some((p) => p.participant === code)) void session.open(code).catch(fail);
});
window.addEventListener("error", (event) => fail(event.error ?? event.message));
export { StudyApiError };
