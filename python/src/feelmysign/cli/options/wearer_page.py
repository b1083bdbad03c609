"""``--wearer-page [PORT]`` and ``--wearer-host``: the wearer's page served by the sleeve.

Only the options: the server itself (``feelmysign.cli._wearer_page``) is imported when
asked for, so a sleeve without the page does not load the web server at start-up.
"""

from __future__ import annotations

import argparse

from feelmysign.cli.options.values import port

DEFAULT_WEARER_PORT = 8001


def add_wearer_page_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group(
        "the wearer's page", "Pause, stop and turn down the sleeve from the wearer's phone."
    )
    group.add_argument(
        "--wearer-page",
        type=port(),
        nargs="?",
        const=DEFAULT_WEARER_PORT,
        metavar="PORT",
        help="serve the wearer's page at /wearer on this port (default with no PORT: "
        f"{DEFAULT_WEARER_PORT}; 0 = any free) and print its URL with the wearer's key",
    )
    group.add_argument(
        "--wearer-host",
        metavar="ADDRESS",
        help="with --wearer-page: the address to serve on (default: this machine's LAN "
        "address, over HTTPS; 127.0.0.1 serves plain HTTP on this machine only)",
    )
