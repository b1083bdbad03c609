"""Options to serve off loopback, shared by ``feelmysign broker`` and ``feelmysign up``.

    --lan                 listen on this machine's LAN address (the default route's)
    --host ADDRESS        listen on this address (implies --lan)
    --tls-port P          the broker's MQTT-over-TLS port (default 8883)
    --tls-cert FILE --tls-key FILE   your own certificate instead of the local CA's

Off loopback everything is TLS; see ``feelmysign.broker.tls``.
"""

from __future__ import annotations

import argparse
import socket
from pathlib import Path

from feelmysign.broker.tls import DEFAULT_MQTTS_PORT, LanOptions
from feelmysign.errors import BrokerError

# Any address outside this machine: connecting a UDP socket sends nothing, but makes the
# kernel pick the source address of the default route (RFC 5737's TEST-NET-2).
_ROUTE_PROBE = ("198.51.100.1", 9)


def add_lan_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group(
        "off loopback", "Serve other devices on the network; everything is then TLS."
    )
    group.add_argument(
        "--lan",
        action="store_true",
        help="listen on this machine's LAN address (the one of the default route) with TLS",
    )
    group.add_argument(
        "--host",
        metavar="ADDRESS",
        help="listen on this address of the machine with TLS (implies --lan)",
    )
    group.add_argument(
        "--tls-port",
        type=int,
        default=DEFAULT_MQTTS_PORT,
        metavar="P",
        help=f"MQTT over TLS port; 0 picks a free one (default: {DEFAULT_MQTTS_PORT})",
    )
    group.add_argument(
        "--tls-cert",
        type=Path,
        metavar="FILE",
        help="your certificate chain (PEM, e.g. fullchain.pem) instead of one from the local "
        "CA in the state directory",
    )
    group.add_argument(
        "--tls-key", type=Path, metavar="FILE", help="the private key of --tls-cert (PEM)"
    )


def lan_from_args(args: argparse.Namespace) -> LanOptions | None:
    """The LAN options asked for, or None to stay on loopback."""
    if not (args.lan or args.host):
        if args.tls_cert or args.tls_key:
            raise BrokerError("bad-option", "--tls-cert and --tls-key need --lan or --host.")
        return None
    host = args.host or default_route_address()
    return LanOptions(host=host, port=args.tls_port, cert=args.tls_cert, key=args.tls_key)


def default_route_address() -> str:
    """This machine's address on the network of its default route."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        try:
            probe.connect(_ROUTE_PROBE)
        except OSError:
            raise BrokerError(
                "bad-option",
                "This machine has no network route, so --lan cannot find its LAN address: "
                "connect it to the network, or give the address with --host.",
            ) from None
        address: str = probe.getsockname()[0]
    return address
