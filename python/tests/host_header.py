"""One GET to a local web server with the Host header a browser (or an attacker's page
after DNS rebinding) would send."""

from __future__ import annotations

import http.client


def get(port: int, path: str, host: str, timeout_s: float = 30.0) -> tuple[int, bytes]:
    """The status and body of ``GET path`` on 127.0.0.1:``port``, sent with ``Host: host``."""
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout_s)
    try:
        connection.putrequest("GET", path, skip_host=True)
        connection.putheader("Host", host)
        connection.endheaders()
        response = connection.getresponse()
        return response.status, response.read()
    finally:
        connection.close()
