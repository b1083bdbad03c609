"""The study's HTTP JSON API under ``/api/study/``, for the researcher's page ``/study``.

Served by ``feelmysign up --study FILE`` on 127.0.0.1 only. Requests must name
this machine in their Host header (a page on another site cannot reach it by
DNS rebinding), and every POST must be JSON (a cross-site form cannot post
JSON without the browser asking first, which this server never allows).

    GET  /api/study                                   design, participants, answers to review
    POST /api/study/participants                      {"simulated": bool} -> {"code"}
    GET  /api/study/participants/CODE                 the session's step and current trial
    POST /api/study/participants/CODE/consent         {"consent": bool}
    POST /api/study/participants/CODE/comfort         {"answers": [bool], "adjusted": bool}
    POST /api/study/participants/CODE/send            {"trial": id} -> what the sleeve did
    POST /api/study/participants/CODE/answer          {"trial", "answer", "felt_nothing",
                                                       "confidence"}
    POST /api/study/participants/CODE/pause           {"paused": bool}
    POST /api/study/participants/CODE/questionnaire   {"values": [int]}
    GET  /api/study/participants/CODE/simulated-answer
    GET  /api/study/participants/CODE/threshold       SQ2.2: runs, estimate, next trial
    POST /api/study/participants/CODE/threshold-send  {"dimension": "length" | "duration"}
    POST /api/study/participants/CODE/threshold-answer {"dimension", "position", "response"}
    POST /api/study/participants/CODE/threshold-discard {"dimension"}: the run under way
    GET  /api/study/review                            answers waiting for a decision (blind)
    POST /api/study/review/TRIAL                      {"shape": name or null}
    POST /api/study/analyse                           starts export + analysis (or joins the
                                                      one running) -> 202 {"job", "state"}
    GET  /api/study/analysis                          that job: state, then files and report
    GET  /api/study/results/NAME                      a file of the latest analysis
"""

from __future__ import annotations

import json
import logging
import re
import threading
import time
from pathlib import Path
from typing import Any

from feelmysign.errors import FeelMySignError, StudyError
from feelmysign.study.runner import Session
from feelmysign.study.threshold_desk import ThresholdDesk, dimension_of

log = logging.getLogger(__name__)

Response = tuple[int, str, bytes]
JSON = "application/json"
_RESULT_TYPES = {
    ".png": "image/png",
    ".csv": "text/csv; charset=utf-8",
    ".md": "text/markdown; charset=utf-8",
    ".json": JSON,
}
_LOCAL_HOSTS = ("127.0.0.1", "localhost")
_PARTICIPANT = re.compile(r"^/api/study/participants/([A-Za-z0-9-]{1,16})(/[a-z-]+)?$")
_REVIEW = re.compile(r"^/api/study/review/(\d{1,12})$")
_RESULT = re.compile(r"^/api/study/results/([a-z0-9-]+\.(png|csv|md|json))$")
MAX_BODY_BYTES = 64 * 1024


def _json(status: int, data: Any) -> Response:
    return status, JSON, json.dumps(data).encode()


class StudyApi:
    def __init__(self, session: Session, results_dir: Path, *, bootstrap: int = 1000) -> None:
        self.session = session
        self.store = session.store
        self.results_dir = results_dir
        self._bootstrap = bootstrap
        self._latest: Path | None = None
        # The analysis runs in its own thread, one at a time, and the page polls for it: it
        # takes a minute or two, longer than the page server lets a request run, and a
        # request the browser re-sends after a cut-off joins the running job.
        self._analysing = threading.Lock()
        self._job = 0
        self._job_state = "idle"  # idle, running, done or failed
        self._job_result: dict[str, Any] | None = None
        self._job_error: str | None = None
        self.threshold = ThresholdDesk(session.store, session.player, session.layout)

    def handle(self, method: str, path: str, host: str, body: bytes, content_type: str) -> Response:
        """Answer one request; never raises."""
        if host.rsplit(":", 1)[0].strip("[]") not in _LOCAL_HOSTS:
            return _json(403, {"error": "the study API answers only requests to 127.0.0.1"})
        try:
            if method == "POST":
                if not content_type.startswith(JSON):
                    return _json(415, {"error": "send JSON (Content-Type: application/json)"})
                if len(body) > MAX_BODY_BYTES:
                    return _json(413, {"error": f"a request is at most {MAX_BODY_BYTES} bytes"})
                data = json.loads(body or b"{}")
                if not isinstance(data, dict):
                    return _json(400, {"error": "the body must be a JSON object"})
                return self._post(path, data)
            return self._get(path)
        except StudyError as error:
            return _json(400, {"error": str(error)})
        except FeelMySignError as error:
            return _json(502, {"error": str(error)})
        except (ValueError, KeyError, TypeError) as error:
            return _json(400, {"error": f"bad request: {error}"})
        except Exception as error:  # a bug must not take the server down, and must be seen
            log.exception("study API: %s %s failed", method, path)
            return _json(500, {"error": f"internal error: {error}"})

    # ---- GET -------------------------------------------------------------------------------

    def _get(self, path: str) -> Response:
        if path == "/api/study":
            return _json(200, self.overview())
        if path == "/api/study/review":
            return _json(200, self.review())
        if path == "/api/study/analysis":
            return _json(200, self.analysis_status())
        if match := _PARTICIPANT.match(path):
            code, action = match.group(1), match.group(2)
            if action is None:
                return _json(200, self.session.state(code))
            if action == "/simulated-answer":
                return _json(200, self.session.simulated_answer(code))
            if action == "/threshold":
                return _json(200, self.threshold.state(code))
        if (match := _RESULT.match(path)) and self._latest is not None:
            file = self._latest / match.group(1)
            if file.is_file():
                return 200, _RESULT_TYPES["." + match.group(2)], file.read_bytes()
        return _json(404, {"error": f"no such study resource: {path}"})

    def overview(self) -> dict[str, Any]:
        design = self.store.design
        participants = []
        for row in self.store.participants():
            state = self.session.state(row["code"])
            participants.append(
                {
                    k: state[k]
                    for k in ("participant", "simulated", "step", "paused", "answered", "total")
                }
            )
        return {
            "name": design.name,
            "file": str(self.store.path),
            "shapes": list(design.shape_names),
            "resolutions": list(design.resolutions),
            "speeds_cm_s": list(design.speeds),
            "comfort": list(design.comfort),
            "questionnaire": {
                "items": list(design.questionnaire.items),
                "points": design.questionnaire.points,
                "labels": list(design.questionnaire.labels),
            },
            "participants": participants,
            "review": len(self.review()),
            "results": None if self._latest is None else self._latest.name,
        }

    def review(self) -> list[dict[str, Any]]:
        """Unclear answers, without the shape that was sent: the decision is made blind."""
        codings = self.store.latest_codings()
        return [
            {"trial": t, "answer": self.store.trial(t)["answer"], "rule": codings[t]["rule"]}
            for t in self.store.awaiting_review()
        ]

    # ---- POST ------------------------------------------------------------------------------

    def _post(self, path: str, data: dict[str, Any]) -> Response:
        if path == "/api/study/participants":
            code = self.store.add_participant(simulated=bool(data.get("simulated", False)))
            return _json(201, {"code": code})
        if path == "/api/study/analyse":
            return _json(202, self.start_analysis())
        if match := _REVIEW.match(path):
            shape = data.get("shape")
            rule = f"researcher: {shape}" if shape else "researcher: no shape named"
            self.store.decide(int(match.group(1)), shape if shape else None, rule)
            return _json(200, {"review": len(self.review())})
        match = _PARTICIPANT.match(path)
        if match is None or match.group(2) is None:
            return _json(404, {"error": f"no such study action: {path}"})
        return self._participant_action(match.group(1), match.group(2)[1:], data)

    def _participant_action(self, code: str, action: str, data: dict[str, Any]) -> Response:
        s = self.session
        trial = data.get("trial")
        trial_id = int(trial) if trial is not None else None
        if action == "consent":
            s.consent(code, bool(data["consent"]))
        elif action == "comfort":
            s.comfort(code, [bool(a) for a in data["answers"]], bool(data.get("adjusted", False)))
        elif action == "send":
            return _json(200, {"sent": s.send(code, trial_id), "state": s.state(code)})
        elif action == "answer":
            confidence = data.get("confidence")
            coding = s.answer(
                code,
                trial_id,
                answer=str(data.get("answer", "")),
                felt_nothing=bool(data.get("felt_nothing", False)),
                confidence=int(confidence) if confidence is not None else None,
            )
            return _json(200, {"coding": coding, "state": s.state(code)})
        elif action == "pause":
            s.pause(code, bool(data["paused"]))
        elif action == "questionnaire":
            s.questionnaire(code, [int(v) for v in data["values"]])
        elif action == "threshold-send":
            return _json(200, self.threshold.send(code, dimension_of(data.get("dimension"))))
        elif action == "threshold-answer":
            dimension = dimension_of(data.get("dimension"))
            position, response = int(data["position"]), str(data.get("response", ""))
            return _json(200, self.threshold.answer(code, dimension, position, response))
        elif action == "threshold-discard":
            return _json(200, self.threshold.discard(code, dimension_of(data.get("dimension"))))
        else:
            return _json(404, {"error": f"no such participant action: {action}"})
        return _json(200, {"state": s.state(code)})

    def start_analysis(self) -> dict[str, Any]:
        """Start an export and analysis in the background, or join the one running."""
        with self._analysing:
            if self._job_state != "running":
                self._job += 1
                self._job_state, self._job_result, self._job_error = "running", None, None
                threading.Thread(
                    target=self._run_job, args=(self._job,), name="study-analysis", daemon=True
                ).start()
        return self.analysis_status()

    def analysis_status(self) -> dict[str, Any]:
        with self._analysing:
            return {
                "job": self._job,
                "state": self._job_state,
                "result": self._job_result,
                "error": self._job_error,
            }

    def wait_for_analysis(self, timeout_s: float | None = None) -> dict[str, Any]:
        """The job's status once it is no longer running (for tests and callers in-process)."""
        deadline = None if timeout_s is None else time.monotonic() + timeout_s
        while True:
            status = self.analysis_status()
            if status["state"] != "running":
                return status
            if deadline is not None and time.monotonic() > deadline:
                return status
            time.sleep(0.05)

    def _run_job(self, job: int) -> None:
        result: dict[str, Any] | None = None
        error: str | None = None
        try:
            result = self.analyse()
        except FeelMySignError as failure:
            error = str(failure)
        except Exception as failure:  # a bug must be seen, and the page told, not left polling
            log.exception("study API: the analysis failed")
            error = f"internal error: {failure}"
        with self._analysing:
            if job == self._job:
                self._job_result, self._job_error = result, error
                self._job_state = "failed" if error is not None else "done"

    def analyse(self) -> dict[str, Any]:
        """Export and analyse now, in the calling thread; the page uses start_analysis."""
        # Imported here: the analysis needs pandas, statsmodels and matplotlib (seconds
        # to import), and serving the study page needs none of them until this button.
        from feelmysign.study.analysis import analyse_study

        out = self.results_dir / time.strftime("%Y%m%d-%H%M%S")
        analysis = analyse_study(self.store, out, samples=self._bootstrap)
        self._latest = out
        return {
            "folder": str(out),
            # The files the page can fetch (GET results/NAME): the folder's own, not bids/.
            "files": [p.name for p in analysis.files if p.parent == out],
            "report": (out / "report.md").read_text(encoding="utf-8"),
            "participants": analysis.participants,
            "unclear": analysis.unclear,
        }
