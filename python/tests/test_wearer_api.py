"""The wearer's API and its key, through a real WebServer on loopback: its own key (the
sender's does not open it, nor does it open the broker's login), the Host check, each
control, and bad bodies answered 400 with a sentence."""

from __future__ import annotations

import http.client
import json
import time
from pathlib import Path
from typing import Any

import pytest

from feelmysign.broker._config import StateFiles, render_acl
from feelmysign.broker.credentials import Account, Credentials
from feelmysign.broker.senders import add_sender, load_senders
from feelmysign.sleeve.controls import WearerControls
from feelmysign.wearer_api import Blocking, WearerApi, wearer_key
from feelmysign.webserver import WebServer

SENDER_KEY = "sender-key-0123456789"
WEARER_KEY = "wearer-key-0123456789"
CONFIG = {"ws_url": "ws://127.0.0.1:9001", "password": "broker-secret"}
MAX_INTENSITY = 0.8


@pytest.fixture
def site(tmp_path: Path) -> Path:
    (tmp_path / "site").mkdir()
    (tmp_path / "site" / "index.html").write_text("<p>sender</p>")
    (tmp_path / "site" / "wearer.html").write_text("<p>wearer</p>")
    return tmp_path / "site"


def api(state_dir: Path, blocking: Blocking | None = None) -> WearerApi:
    controls = WearerControls(str(state_dir / "controls.json"), max_intensity=MAX_INTENSITY)
    return WearerApi(
        sleeve_id="sleeve1",
        max_intensity=MAX_INTENSITY,
        controls=lambda: controls,
        online=lambda: True,
        blocking=blocking,
    )


def request(
    server: WebServer,
    method: str,
    path: str,
    *,
    cookie: str = f"feelmysign_wearer_key={WEARER_KEY}",
    body: Any = None,
    host: str | None = None,
    content_type: str = "application/json",
    raw: bytes | None = None,
) -> tuple[int, dict[str, str], bytes]:
    connection = http.client.HTTPConnection("127.0.0.1", server.port, timeout=30)
    data = raw if raw is not None else (None if body is None else json.dumps(body).encode())
    headers = {"Cookie": cookie, "Content-Type": content_type}
    if host is not None:
        headers["Host"] = host
    connection.request(method, path, body=data, headers=headers)
    answer = connection.getresponse()
    result = answer.status, dict(answer.getheaders()), answer.read()
    connection.close()
    return result


def served(site: Path, wearer: WearerApi) -> WebServer:
    return WebServer(
        port=0,
        config=CONFIG,
        directory=site,
        access_key=SENDER_KEY,
        wearer_api=wearer,
        wearer_key=WEARER_KEY,
    )


def test_the_wearer_key_opens_the_api_and_nothing_else(site: Path) -> None:
    with served(site, api(site.parent)) as server:
        status, headers, _ = request(server, "GET", f"/wearer?key={WEARER_KEY}", cookie="")
        assert status == 303 and headers["Location"] == "/wearer"
        assert f"feelmysign_wearer_key={WEARER_KEY};" in headers["Set-Cookie"]
        assert "SameSite=Strict" in headers["Set-Cookie"]
        status, _, body = request(server, "GET", "/wearer", cookie="")
        assert (status, body) == (200, b"<p>wearer</p>")  # the page is public; its API is not
        status, _, body = request(server, "GET", "/api/wearer/state")
        assert status == 200 and json.loads(body)["controls"]["paused"] is False
        # The wearer's key gives neither the broker's login nor the sender's cookie.
        status, _, body = request(server, "GET", "/config.json")
        assert status == 403 and b"broker-secret" not in body
        status, headers, _ = request(server, "GET", f"/?key={WEARER_KEY}", cookie="")
        assert status == 200 and "Set-Cookie" not in headers


def test_the_sender_key_does_not_open_the_wearer_api(site: Path) -> None:
    with served(site, api(site.parent)) as server:
        status, headers, _ = request(server, "GET", f"/wearer?key={SENDER_KEY}", cookie="")
        assert status == 200 and "Set-Cookie" not in headers
        for cookie in ("", f"feelmysign_key={SENDER_KEY}", "feelmysign_wearer_key=guess"):
            status, _, body = request(server, "POST", "/api/wearer/pause", cookie=cookie, body={})
            assert status == 403, cookie
            assert "wearer's key" in json.loads(body)["error"]
        status, _, body = request(server, "GET", "/api/wearer/state")
        assert json.loads(body)["controls"]["paused"] is False  # nothing was paused


def test_a_foreign_host_is_refused_even_with_the_key(site: Path) -> None:
    with served(site, api(site.parent)) as server:
        status, _, body = request(server, "POST", "/api/wearer/pause", body={}, host="evil.test")
        assert status == 403 and b"evil.test" in body
        status, _, body = request(server, "GET", "/api/wearer/state")
        assert json.loads(body)["controls"]["paused"] is False


def test_each_control_answers_the_new_state(site: Path) -> None:
    with served(site, api(site.parent)) as server:

        def post(action: str, body: Any = None) -> dict[str, Any]:
            status, _, answer = request(server, "POST", f"/api/wearer/{action}", body=body)
            assert status == 200, answer
            result: dict[str, Any] = json.loads(answer)
            return result

        assert post("pause")["controls"]["paused_by"] == "page"
        assert post("pause")["controls"]["paused"] is True  # idempotent
        assert post("resume")["controls"] == {
            "paused": False,
            "paused_by": None,
            "ceiling": None,
            "do_not_disturb_until_ms": None,
        }
        assert post("ceiling", {"ceiling": 0.5})["controls"]["ceiling"] == 0.5
        assert post("ceiling", {"ceiling": None})["controls"]["ceiling"] is None
        until_ms = int(time.time() * 1000) + 15 * 60_000
        state = post("do-not-disturb", {"until_ms": until_ms})
        assert state["controls"]["do_not_disturb_until_ms"] == until_ms
        state = post("do-not-disturb", {"until_ms": None})
        assert state["controls"]["do_not_disturb_until_ms"] is None
        assert post("stop", {})["max_intensity"] == MAX_INTENSITY
        assert state["blocking"] is False and state["senders"] == []


@pytest.mark.parametrize(
    ("action", "body", "content_type", "said"),
    [
        ("ceiling", {"ceiling": 0.9}, "application/json", "from 0.05 to 0.8"),
        ("ceiling", {"ceiling": 0.01}, "application/json", "from 0.05"),
        ("ceiling", {"ceiling": "half"}, "application/json", "not a number"),
        ("ceiling", {"ceiling": True}, "application/json", "not a number"),
        ("ceiling", {}, "application/json", "Give the ceiling"),
        ("ceiling", [0.5], "application/json", "must be a JSON object"),
        ("ceiling", b"{oops", "application/json", "not JSON"),
        ("ceiling", {"ceiling": 0.5}, "text/plain", "Content-Type: application/json"),
        ("do-not-disturb", {"until_ms": 1000}, "application/json", "within the next 24 hours"),
        ("do-not-disturb", {"until_ms": "soon"}, "application/json", "not a time"),
        ("do-not-disturb", {}, "application/json", "until_ms"),
        ("block", {"sender": "alice"}, "application/json", "needs the broker feelmysign runs"),
        ("block", {}, "application/json", "Name the sender"),
        ("pause", b"x" * 5000, "application/json", "over 4096 bytes"),
    ],
)
def test_a_bad_body_gets_400_and_a_sentence(
    site: Path, action: str, body: Any, content_type: str, said: str
) -> None:
    raw = body if isinstance(body, bytes) else None
    with served(site, api(site.parent)) as server:
        status, headers, answer = request(
            server,
            "POST",
            f"/api/wearer/{action}",
            body=None if raw is not None else body,
            raw=raw,
            content_type=content_type,
        )
        assert status == 400, answer
        assert headers["Content-Type"] == "application/json"
        assert said in json.loads(answer)["error"]
        _, _, state = request(server, "GET", "/api/wearer/state")
        assert json.loads(state)["controls"] == {
            "paused": False,
            "paused_by": None,
            "ceiling": None,
            "do_not_disturb_until_ms": None,
        }


def test_wrong_methods_and_paths_are_named(site: Path) -> None:
    with served(site, api(site.parent)) as server:
        status, _, body = request(server, "GET", "/api/wearer/pause")
        assert status == 405 and "POST" in json.loads(body)["error"]
        status, _, body = request(server, "POST", "/api/wearer/state", body={})
        assert status == 405 and "GET" in json.loads(body)["error"]
        status, _, body = request(server, "POST", "/api/wearer/explode", body={})
        assert status == 404 and "pause" in json.loads(body)["error"]


def test_the_sleeve_still_starting_is_said(site: Path) -> None:
    starting = WearerApi(
        sleeve_id="sleeve1", max_intensity=1.0, controls=lambda: None, online=lambda: False
    )
    with served(site, starting) as server:
        _, _, body = request(server, "GET", "/api/wearer/state")
        assert json.loads(body)["controls"] is None and json.loads(body)["online"] is False
        status, _, body = request(server, "POST", "/api/wearer/pause", body={})
        assert status == 503 and "starting" in json.loads(body)["error"]


def test_blocking_a_named_sender_without_a_running_broker(tmp_path: Path) -> None:
    files = StateFiles(tmp_path)
    credentials = Credentials(
        mqtt_url="mqtt://127.0.0.1:1883",
        ws_url="ws://127.0.0.1:9001",
        sleeve_id="sleeve1",
        sleeve=Account("sleeve-sleeve1", "p" * 24),
        sender=Account("sender", "q" * 24),
    )
    add_sender(files.senders, "alice")
    wearer = api(tmp_path, Blocking(files, credentials))

    def call(action: str, body: dict[str, Any]) -> tuple[int, dict[str, Any]]:
        status, _, answer = wearer(
            "POST", f"/api/wearer/{action}", "", json.dumps(body).encode(), "application/json"
        )
        return status, json.loads(answer)

    status, state = call("block", {"sender": "alice"})
    assert status == 200 and state["blocking"] is True
    assert state["senders"] == [
        {"name": "page", "blocked": False, "blockable": False},
        {"name": "alice", "blocked": True, "blockable": True},
    ]
    assert load_senders(files.senders)["alice"].blocked is True
    status, state = call("block", {"sender": "bob"})
    assert status == 400 and "no sender 'bob'" in state["error"] and "alice" in state["error"]
    status, state = call("block", {"sender": "page"})
    assert status == 400 and "pause the sleeve instead" in state["error"]
    status, state = call("unblock", {"sender": "alice"})
    assert status == 200 and load_senders(files.senders)["alice"].blocked is False


def test_a_named_sender_has_the_sender_s_rights_in_the_acl() -> None:
    acl = render_acl(
        sleeve_id="sleeve1",
        sleeve_username="sleeve-sleeve1",
        sender_username="sender",
        legacy_topic="deviceOne/line",
        other_senders=["sender-alice"],
    )
    assert "user sender-alice\ntopic write feelmysign/+/strokes" in acl
    assert "user sender\ntopic write feelmysign/+/strokes" in acl


def test_the_wearer_key_is_kept(tmp_path: Path) -> None:
    key = wearer_key(tmp_path)
    assert len(key) >= 16 and wearer_key(tmp_path) == key
    assert (tmp_path / "wearer-key").stat().st_mode & 0o077 == 0
