"""The study's HTTP API: only for this machine, JSON only, every step of a session, blind review."""

from __future__ import annotations

import json
import threading
import urllib.error
import urllib.request
from pathlib import Path
from typing import Any

from study_helpers import new_study, pilot_study

from feelmysign.errors import StudyError
from feelmysign.study.api import StudyApi
from feelmysign.study.dry_run import dry_run
from feelmysign.study.runner import Session
from feelmysign.study.simulated_sleeve import offline_player
from feelmysign.webserver import WebServer

HOST = "127.0.0.1:8000"


def _api(tmp_path: Path) -> StudyApi:
    store = new_study(tmp_path)
    layout = Session(store, None).layout
    return StudyApi(Session(store, offline_player(layout)), tmp_path / "results", bootstrap=50)


def _call(
    api: StudyApi, method: str, path: str, body: dict[str, Any] | None = None
) -> tuple[int, Any]:
    raw = json.dumps(body or {}).encode()
    status, _kind, payload = api.handle(method, path, HOST, raw, "application/json")
    return status, json.loads(payload)


def test_requests_for_another_host_or_not_json_are_refused(tmp_path: Path) -> None:
    api = _api(tmp_path)
    status, _, body = api.handle("GET", "/api/study", "evil.example:8000", b"", "")
    assert status == 403 and b"127.0.0.1" in body
    status, _, body = api.handle("POST", "/api/study/participants", HOST, b"a=1", "text/plain")
    assert status == 415
    assert api.store.participants() == []


def test_a_session_through_the_api_and_a_blind_review(tmp_path: Path) -> None:
    api = _api(tmp_path)
    status, created = _call(api, "POST", "/api/study/participants", {"simulated": False})
    code = created["code"]
    assert status == 201 and code.startswith("P-")
    base = f"/api/study/participants/{code}"
    status, refused = _call(api, "POST", f"{base}/comfort", {"answers": [True, True]})
    assert status == 400 and "consent" in refused["error"]
    _call(api, "POST", f"{base}/consent", {"consent": True})
    _call(api, "POST", f"{base}/comfort", {"answers": [True, True], "adjusted": False})
    status, state = _call(api, "GET", base)
    trial = state["trial"]
    assert state["step"] == "trial" and trial["block"] == "practice"
    # Practice answers, however unclear, are not analysed and never wait for review.
    answered_count = 0
    while trial["block"] == "practice":
        status, sent = _call(api, "POST", f"{base}/send", {"trial": trial["id"]})
        assert status == 200 and sent["sent"]["played"] == sent["sent"]["strokes"]
        status, answered = _call(
            api, "POST", f"{base}/answer", {"trial": trial["id"], "answer": "a wobbly thing"}
        )
        answered_count += 1
        assert answered["coding"]["status"] == "unclear"
        assert answered["state"]["answered"] == answered_count
        assert _call(api, "GET", "/api/study/review")[1] == []
        assert _call(api, "GET", "/api/study")[1]["review"] == 0
        status, refused = _call(api, "POST", f"/api/study/review/{trial['id']}", {"shape": None})
        assert status == 400 and "practice" in refused["error"]
        trial = answered["state"]["trial"]
    assert trial["block"] == "main"
    _call(api, "POST", f"{base}/send", {"trial": trial["id"]})
    status, answered = _call(
        api, "POST", f"{base}/answer", {"trial": trial["id"], "answer": "a wobbly thing"}
    )
    assert answered["coding"]["status"] == "unclear"
    status, review = _call(api, "GET", "/api/study/review")
    assert review == [{"trial": trial["id"], "answer": "a wobbly thing", "rule": review[0]["rule"]}]
    assert "shape" not in review[0]  # the shape that was sent is not shown: blind decision
    shape = api.store.design.shape_names[0]
    status, decided = _call(api, "POST", f"/api/study/review/{trial['id']}", {"shape": shape})
    assert decided == {"review": 0}
    decisions = api.store.codings(trial["id"])
    assert [d["decided_by"] for d in decisions] == ["auto", "researcher"]
    status, missing = _call(api, "GET", "/api/study/participants/P-NOONE")
    assert status == 400 and "no participant" in missing["error"]


def test_the_web_server_mounts_the_api_and_serves_the_study_page(tmp_path: Path) -> None:
    site = tmp_path / "site"
    site.mkdir()
    (site / "index.html").write_text("<p>draw</p>")
    (site / "study.html").write_text("<p>study page</p>")
    api = _api(tmp_path)
    with WebServer(port=0, config={}, directory=site, api=api.handle) as server:
        with urllib.request.urlopen(f"{server.url}study") as page:
            assert b"study page" in page.read()
        request = urllib.request.Request(
            f"{server.url}api/study/participants",
            data=b'{"simulated": true}',
            headers={"Content-Type": "application/json"},
        )
        with urllib.request.urlopen(request) as response:
            assert response.status == 201
        with urllib.request.urlopen(f"{server.url}api/study") as response:
            overview = json.load(response)
        assert len(overview["participants"]) == 1 and overview["participants"][0]["simulated"]
        try:
            urllib.request.urlopen(f"{server.url}api/study/nothing")
        except urllib.error.HTTPError as error:
            assert error.code == 404
        else:
            raise AssertionError("an unknown API path must be a 404")


def test_the_analysis_lists_only_the_files_the_page_can_fetch(tmp_path: Path) -> None:
    """The results folder's own files (report, tables, plots) are listed and each is served;
    the BIDS export in its subfolder is written but neither listed nor served."""
    store = pilot_study(tmp_path)
    dry_run(store, 2, seed=3)
    layout = Session(store, None).layout
    api = StudyApi(Session(store, offline_player(layout)), tmp_path / "results", bootstrap=50)
    status, started = _call(api, "POST", "/api/study/analyse")
    assert status == 202 and started["state"] in ("running", "done"), started
    api.wait_for_analysis()
    status, job = _call(api, "GET", "/api/study/analysis")
    assert status == 200 and job["state"] == "done", job
    analysis = job["result"]
    folder = Path(analysis["folder"])
    listed = analysis["files"]
    on_disk = sorted(p.name for p in folder.iterdir() if p.is_file())
    assert sorted(listed) == on_disk and "report.md" in listed
    nested = [p for p in folder.rglob("*") if p.is_file() and p.parent != folder]
    assert any(p.parent.name == "bids" for p in nested), nested  # written, in its subfolder
    assert not {p.name for p in nested} & set(listed)
    for name in listed:
        status, _kind, body = api.handle("GET", f"/api/study/results/{name}", HOST, b"", "")
        assert status == 200 and body == (folder / name).read_bytes(), name
    for path in nested:
        status, _, _ = api.handle("GET", f"/api/study/results/{path.name}", HOST, b"", "")
        assert status == 404, path


def test_no_answer_is_recorded_while_a_repeat_send_still_plays(tmp_path: Path) -> None:
    store = new_study(tmp_path)
    layout = Session(store, None).layout
    offline = offline_player(layout)
    started, release = threading.Event(), threading.Event()
    held = {"on": False}

    def play(strokes: Any) -> Any:
        if held["on"]:  # the repeat send: the sleeve is still playing until released
            started.set()
            assert release.wait(30)
        return offline(strokes)

    api = StudyApi(Session(store, play), tmp_path / "results", bootstrap=50)
    _, created = _call(api, "POST", "/api/study/participants", {"simulated": False})
    base = f"/api/study/participants/{created['code']}"
    _call(api, "POST", f"{base}/consent", {"consent": True})
    _call(api, "POST", f"{base}/comfort", {"answers": [True, True], "adjusted": False})
    trial = _call(api, "GET", base)[1]["trial"]
    assert _call(api, "POST", f"{base}/send", {"trial": trial["id"]})[0] == 200
    held["on"] = True
    repeat = threading.Thread(
        target=_call, args=(api, "POST", f"{base}/send", {"trial": trial["id"]})
    )
    repeat.start()
    try:
        assert started.wait(30)
        answer = {"trial": trial["id"], "answer": "a line"}
        status, refused = _call(api, "POST", f"{base}/answer", answer)
        assert status == 400 and "still playing" in refused["error"], refused
        status, again = _call(api, "POST", f"{base}/send", {"trial": trial["id"]})
        assert status == 400 and "still playing" in again["error"], again
        assert _call(api, "GET", base)[1]["answered"] == 0
    finally:
        release.set()
        repeat.join(30)
    status, answered = _call(api, "POST", f"{base}/answer", answer)
    assert status == 200 and answered["state"]["answered"] == 1
    assert len(store.sends(trial["id"])) == 2  # the refused third send was not stored


def test_an_analysis_request_sent_again_while_one_runs_joins_it(tmp_path: Path) -> None:
    """The browser re-sends a POST whose connection was cut: it must not start a second
    analysis of the same study, and the page learns the one result by polling."""
    store = pilot_study(tmp_path)
    dry_run(store, 2, seed=3)
    layout = Session(store, None).layout
    api = StudyApi(Session(store, offline_player(layout)), tmp_path / "results", bootstrap=20)
    release = threading.Event()
    runs: list[int] = []
    real_analyse = api.analyse

    def gated_analyse() -> dict[str, Any]:
        runs.append(1)
        release.wait()  # held running until both requests are in, whatever the machine's speed
        return real_analyse()

    api.analyse = gated_analyse  # type: ignore[method-assign]
    status, first = _call(api, "POST", "/api/study/analyse")
    assert status == 202 and first["state"] == "running"
    status, again = _call(api, "POST", "/api/study/analyse")
    assert status == 202 and again["state"] == "running" and again["job"] == first["job"]
    status, polled = _call(api, "GET", "/api/study/analysis")
    assert polled["state"] == "running" and polled["result"] is None
    release.set()
    done = api.wait_for_analysis()
    assert done["state"] == "done" and done["job"] == first["job"], done
    assert len(runs) == 1
    assert [p.name for p in (tmp_path / "results").iterdir()] == [
        Path(done["result"]["folder"]).name
    ]
    # Asked again once done: a new analysis, with its own job number.
    status, next_job = _call(api, "POST", "/api/study/analyse")
    assert status == 202 and next_job["job"] == first["job"] + 1
    assert api.wait_for_analysis()["state"] == "done" and len(runs) == 2


def test_a_failed_analysis_is_reported_to_the_polling_page(tmp_path: Path) -> None:
    api = _api(tmp_path)

    def failing() -> dict[str, Any]:
        raise StudyError("no answers to analyse yet")

    api.analyse = failing  # type: ignore[method-assign]
    _call(api, "POST", "/api/study/analyse")
    done = api.wait_for_analysis()
    assert done["state"] == "failed" and "no answers" in done["error"] and done["result"] is None
