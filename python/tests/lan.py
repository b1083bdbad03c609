"""A second machine for the LAN tests: a network namespace joined by a veth pair.

As root (and with ``ip``), :func:`lan` creates a namespace with its own network stack:
the broker listens on the host end of the pair (``host_address``), and programs
started with ``run_prefix`` run inside the namespace, reaching it as another machine
on the LAN would, never through loopback. Without root, the machine's own address
on its default route stands in (still off loopback), and ``run_prefix`` is empty.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from feelmysign.cli.options.lan import default_route_address
from feelmysign.errors import BrokerError


@dataclass(frozen=True)
class Lan:
    host_address: str
    run_prefix: list[str]

    @property
    def namespaced(self) -> bool:
        return bool(self.run_prefix)


def _ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, timeout=10)


@contextmanager
def lan() -> Iterator[Lan]:
    if os.geteuid() != 0 or shutil.which("ip") is None:
        try:
            yield Lan(default_route_address(), [])
        except BrokerError:
            import pytest

            pytest.skip("no network namespace (not root) and no LAN address to bind")
        return
    subnet = 16 + os.getpid() % 200
    namespace, host_end, guest_end = (
        f"fms-{os.getpid()}",
        f"fmsh{os.getpid()}"[:15],
        f"fmsg{os.getpid()}"[:15],
    )
    host_address, guest_address = f"10.199.{subnet}.1", f"10.199.{subnet}.2"
    _ip("netns", "add", namespace)
    try:
        _ip("link", "add", host_end, "type", "veth", "peer", "name", guest_end)
        _ip("link", "set", guest_end, "netns", namespace)
        _ip("addr", "add", f"{host_address}/24", "dev", host_end)
        _ip("link", "set", host_end, "up")
        _ip("-n", namespace, "addr", "add", f"{guest_address}/24", "dev", guest_end)
        _ip("-n", namespace, "link", "set", guest_end, "up")
        _ip("-n", namespace, "link", "set", "lo", "up")
        yield Lan(host_address, ["ip", "netns", "exec", namespace])
    finally:
        subprocess.run(["ip", "link", "del", host_end], capture_output=True, timeout=10)
        subprocess.run(["ip", "netns", "del", namespace], capture_output=True, timeout=10)
