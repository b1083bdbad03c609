"""``/config.json`` (the broker login) only for pages opened from this server: DNS rebinding."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from host_header import get

from feelmysign.webserver import WebServer, host_header_names

CONFIG = {"url": "ws://127.0.0.1:9001", "username": "sender", "password": "s3cret-password"}


@pytest.fixture
def site(tmp_path: Path) -> Path:
    (tmp_path / "index.html").write_text("<!doctype html><title>feelmysign</title>")
    return tmp_path


def _get(server: WebServer, path: str, host: str) -> tuple[int, bytes]:
    return get(_port(server), path, host, timeout_s=10)


def _port(server: WebServer) -> int:
    return int(server.url.rstrip("/").rsplit(":", 1)[1])


@pytest.mark.parametrize("name", ["127.0.0.1", "localhost", "LOCALHOST", "[::1]"])
def test_config_is_served_to_loopback_names_with_the_port(site: Path, name: str) -> None:
    with WebServer(port=0, config=CONFIG, directory=site) as server:
        status, body = _get(server, "/config.json", f"{name}:{_port(server)}")
    assert status == 200 and json.loads(body) == CONFIG


@pytest.mark.parametrize(
    "host",
    ["attacker.example", "attacker.example:{port}", "127.0.0.1:1", "localhost", "", "127.0.0.1"],
)
def test_config_is_refused_to_a_foreign_host(site: Path, host: str) -> None:
    with WebServer(port=0, config=CONFIG, directory=site) as server:
        status, body = _get(server, "/config.json?x=1", host.format(port=_port(server)))
        page_status, _ = _get(server, "/", "attacker.example")
    assert status == 403
    assert b"s3cret" not in body and b"Forbidden" in body and b"127.0.0.1:" in body
    assert page_status == 200  # the page itself holds no secret


def test_hosts_it_was_told_to_serve_on_are_allowed(site: Path) -> None:
    with WebServer(port=0, config=CONFIG, directory=site, hosts=["192.168.1.20"]) as server:
        port = _port(server)
        assert _get(server, "/config.json", f"192.168.1.20:{port}")[0] == 200
        assert _get(server, "/config.json", f"192.168.1.21:{port}")[0] == 403


def test_a_bug_in_the_server_keeps_its_traceback_in_the_debug_log(
    site: Path, tmp_path: Path
) -> None:
    """Peer faults are one debug line each (test_page_server_peers); a bug of the server's own
    is still logged as an error with its traceback."""

    def broken_api(
        method: str, path: str, host: str, body: bytes, kind: str
    ) -> tuple[int, str, bytes]:
        raise ZeroDivisionError("a bug in the API")

    log = tmp_path / "page-server.log"
    with WebServer(port=0, config=CONFIG, directory=site, api=broken_api, debug_log=log) as server:
        status, _ = _get(server, "/api/study", f"127.0.0.1:{_port(server)}")
    text = log.read_text()
    assert status == 500
    assert (
        " ERROR " in text and "Traceback" in text and "ZeroDivisionError: a bug in the API" in text
    )


def test_host_header_names() -> None:
    assert host_header_names(["::1", "Example.org"], 80) == {
        "[::1]:80",
        "[::1]",
        "example.org:80",
        "example.org",
    }
    assert host_header_names(["localhost"], 8000) == {"localhost:8000"}
