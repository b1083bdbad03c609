"""``feelmysign up``: everything on one machine: broker, sleeve, and the drawing client."""

from __future__ import annotations

import argparse
import socket
import threading
from contextlib import AbstractContextManager, nullcontext
from pathlib import Path
from typing import TYPE_CHECKING

from feelmysign.backends.factory import BACKEND_NAMES
from feelmysign.broker import (
    DEFAULT_MQTT_PORT,
    DEFAULT_SLEEVE_ID,
    DEFAULT_WS_PORT,
    Broker,
    Credentials,
    default_state_dir,
)
from feelmysign.broker.instance import InstanceLock
from feelmysign.broker.tls import LanOptions
from feelmysign.cli._page_server import page_server, qr_text
from feelmysign.cli.options.emulation import add_emulate_state_option
from feelmysign.cli.options.lan import add_lan_options, lan_from_args
from feelmysign.cli.options.layout import add_layout_options, layout_from_args
from feelmysign.cli.options.parser import Subcommands
from feelmysign.cli.options.values import output_file, port, sleeve_id
from feelmysign.cli.options.wearer import add_wearer_option, wearer_from_args
from feelmysign.cli.sleeve import run_sleeve
from feelmysign.daemon import Sleeve, SleeveOptions
from feelmysign.services.drawing_log import DrawingLog
from feelmysign.services.stop_signals import call_on_stop_signals
from feelmysign.services.watchdog import Watchdog
from feelmysign.wearer_api import Blocking, WearerApi
from feelmysign.webserver import WEB_DIST, Api, check_built, listen

if TYPE_CHECKING:
    from feelmysign.layout import Layout
    from feelmysign.wearer import Wearer

DEFAULT_HTTP_PORT = 8000


def register(subparsers: Subcommands) -> None:
    parser = subparsers.add_parser(
        "up",
        help="start the broker, a sleeve and the drawing client, all on this machine",
        description=(
            "Start Mosquitto with generated credentials, a sleeve (simulated, or the real one "
            "on a Raspberry Pi), and serve the drawing client on http://127.0.0.1:PORT (with "
            "--lan or --host: https://ADDRESS:PORT) with the broker's address and the sender's "
            "login built in. Ctrl-C stops everything. One instance per state directory: "
            "while another up or broker runs on it, up says so and changes nothing."
        ),
    )
    parser.add_argument(
        "--state-dir",
        type=Path,
        metavar="DIR",
        help="where the broker keeps credentials.json and its data "
        "(default: the same as 'feelmysign broker')",
    )
    parser.add_argument(
        "--http-port",
        type=port(),
        default=DEFAULT_HTTP_PORT,
        metavar="P",
        help=f"drawing client port (default: {DEFAULT_HTTP_PORT}; 0 = any free)",
    )
    parser.add_argument(
        "--port",
        type=port(),
        metavar="P",
        help=f"MQTT port (default: {DEFAULT_MQTT_PORT}, or any free one if taken; 0 = any free)",
    )
    parser.add_argument(
        "--ws-port",
        type=port(),
        metavar="W",
        help=f"MQTT over WebSockets port (default: {DEFAULT_WS_PORT}, or any free one if taken)",
    )
    parser.add_argument(
        "--sleeve-id",
        default=DEFAULT_SLEEVE_ID,
        type=sleeve_id,
        metavar="ID",
        help=f"the sleeve's id (default: {DEFAULT_SLEEVE_ID})",
    )
    parser.add_argument(
        "--sleeve-backend",
        choices=BACKEND_NAMES,
        default="sim",
        help="sim: the simulator; drv2605: the motors over I2C (default: sim)",
    )
    parser.add_argument(
        "--record",
        metavar="FILE",
        help="with the sim backend: write every actuator change as JSON lines",
    )
    parser.add_argument(
        "--web-dir",
        type=Path,
        default=WEB_DIST,
        metavar="DIR",
        help="the built drawing client (default: web/dist of this checkout)",
    )
    parser.add_argument(
        "--study",
        type=Path,
        metavar="FILE",
        help="serve this study file's researcher page at /study (make one with "
        "'feelmysign study new DESIGN.toml --out FILE')",
    )
    add_emulate_state_option(parser)
    add_layout_options(parser)
    add_wearer_option(parser)
    add_lan_options(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    if args.record is not None:
        output_file(args.record, option="--record")
    layout = layout_from_args(args)
    wearer = wearer_from_args(args, layout)
    lan = lan_from_args(args)
    check_built(args.web_dir)
    state_dir = args.state_dir if args.state_dir is not None else default_state_dir()
    # The state directory is this run's alone (another up or broker there: refused before
    # anything is written), and the page's port is bound before the broker writes a file:
    # a start that fails leaves the state, and any instance using it, as they were.
    with InstanceLock(state_dir, "feelmysign up") as lock:
        page_socket = listen(lan.host if lan is not None else "127.0.0.1", args.http_port)
        try:
            return _run(args, layout, wearer, lan, lock, page_socket)
        finally:
            page_socket.close()


def _run(
    args: argparse.Namespace,
    layout: Layout,
    wearer: Wearer | None,
    lan: LanOptions | None,
    lock: InstanceLock,
    page_socket: socket.socket,
) -> int:
    port = _port_or_free(args.port, DEFAULT_MQTT_PORT, "MQTT")
    ws_port = _port_or_free(args.ws_port, DEFAULT_WS_PORT, "WebSocket")
    broker = Broker(
        state_dir=lock.state_dir,
        port=port,
        ws_port=ws_port,
        sleeve_id=args.sleeve_id,
        lan=lan,
        lock=lock,
    )
    watchdog = Watchdog(broker)
    with broker, watchdog, _study_api(args.study, broker.credentials) as api:
        c = broker.credentials
        running: list[Sleeve] = []  # the sleeve, once started: the wearer's page controls it
        wearer_api = WearerApi(
            sleeve_id=c.sleeve_id,
            max_intensity=layout.max_intensity,
            controls=lambda: running[0].controls if running else None,
            online=lambda: bool(running) and running[0].connected.is_set(),
            blocking=Blocking(broker.files, c),
        )
        server, page_url, wearer_url = page_server(
            broker,
            http_port=args.http_port,
            directory=args.web_dir,
            api=api,
            wearer_api=wearer_api,
            sock=page_socket,
        )
        lock.describe(page=page_url)
        with server:
            settings = c.settings("sleeve")
            options = SleeveOptions(
                sleeve_id=c.sleeve_id, backend_name=args.sleeve_backend, wearer=wearer
            )

            log = DrawingLog(c.settings("sender"), c.sleeve_id)  # a line per drawing
            limits = _wearer_limits(wearer, layout, args.wearer)

            def started(sleeve: Sleeve) -> None:
                running.append(sleeve)
                _stop_on_signals(sleeve, watchdog)
                watchdog.watch(sleeve, log.listening)
                threading.Thread(
                    target=_announce,
                    args=(sleeve, page_url, broker, api is not None, wearer_url, limits),
                    kwargs={"backend": args.sleeve_backend},
                    daemon=True,
                ).start()

            with log:
                run_sleeve(
                    settings,
                    layout,
                    options,
                    backend=args.sleeve_backend,
                    record=args.record,
                    emulate_state=args.emulate_state,
                    on_start=started,
                    # The simulated sleeve has no GPIO: a layout's buttons are emulated.
                    sim_buttons=True,
                )
    print("Stopped: sleeve (every motor off), drawing client and broker.", flush=True)
    return 0


def _study_api(path: Path | None, credentials: Credentials) -> AbstractContextManager[Api | None]:
    """The study page's API with --study, else nothing.

    Imported only when asked for: the study's analysis needs the [research] extra
    (pandas, statsmodels), which 'make up' does not install.
    """
    if path is None:
        return nullcontext(None)
    from feelmysign.study.served import study_api

    return study_api(path, credentials)


def _port_or_free(asked: int | None, default: int, name: str) -> int:
    """The port asked for; else the default, or any free port when something else has it.

    Debian starts its own Mosquitto on 1883 when the package is installed: ``make up``
    must still come up with nothing typed (the page learns the ports from /config.json).
    """
    if asked is not None:
        return asked
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        try:
            probe.bind(("127.0.0.1", default))
        except OSError:
            print(
                f"Port {default} is taken (another {name} server?); using a free port instead.",
                flush=True,
            )
            return 0
    return default


def _wearer_limits(wearer: Wearer | None, layout: Layout, path: str | None) -> str:
    """The banner's line for ``--wearer FILE``: whose limits, from which file, and the floor
    the sleeve's status then asks senders to keep ("" without a wearer)."""
    if wearer is None:
        return ""
    from feelmysign.wearer import sleeve_floor

    floor = sleeve_floor(layout, wearer)
    return (
        f"  Wearer:      {wearer.name}'s limits from {path}: the sleeve asks senders for strokes "
        f"of at least {floor.min_duration_ms:g} ms and {floor.min_length:g} grid units\n"
    )


def _announce(
    sleeve: Sleeve,
    url: str,
    broker: Broker,
    study: bool = False,
    wearer_url: str | None = None,
    limits: str = "",
    *,
    backend: str = "sim",
) -> None:
    if not sleeve.connected.wait(15):
        print("The sleeve has not reached the broker after 15 s; see the log above.", flush=True)
        return
    c = broker.credentials
    lan = ""
    if c.mqtts_url is not None:
        fingerprint = f" (CA SHA-256 {c.ca_fingerprint[:16]}...)" if c.ca_fingerprint else ""
        lan = (
            f"  Phone:       scan this code, accept the certificate{fingerprint} once:\n"
            f"{qr_text(url)}"
            f"  Sleeves:     {c.mqtts_url}; for a sleeve on another machine run\n"
            f"               feelmysign broker --state-dir {broker.state_dir} add-sleeve ID\n"
        )
    print(
        f"feelmysign is up.\n"
        f"  Draw here:   {url}\n"
        + (f"  Study:       {url.split('?')[0]}study\n" if study else "")
        + lan
        + _for_the_wearer(wearer_url, lan=bool(lan))
        + f"  Sleeve:      {c.sleeve_id} ({_sleeve_kind(backend)})\n"
        + _controls_at_start(sleeve)
        + limits
        + f"  Broker:      {c.mqtt_url} and {c.ws_url}\n"
        f"  Credentials: {broker.credentials_path}\n"
        f"One line per drawing follows here once it has been played.\n"
        f"Press Ctrl-C to stop.",
        flush=True,
    )


def _sleeve_kind(backend: str) -> str:
    """What drives the motors, for the banner."""
    if backend == "sim":
        return "simulated: no motors; --sleeve-backend drv2605 drives DRV2605L chips"
    if backend == "drv2605":
        return "DRV2605L chips over I2C"
    return f"the {backend} backend"


def _controls_at_start(sleeve: Sleeve) -> str:
    """The wearer's choices kept from before (a pause, a ceiling, do not disturb): said, so
    that whoever runs up knows why the sleeve plays nothing, or less; "" when none."""
    from feelmysign.sleeve.controls import BY_SLEEVE, NOT_PAUSED, describe

    state = sleeve.controls.state()
    if state == NOT_PAUSED:
        return ""
    if state.paused and state.paused_by == BY_SLEEVE:
        return (
            "  The sleeve started paused at the least strength: it could not read the wearer's "
            "last choices (its settings file); the wearer's page resumes it and sets the "
            "strength again\n"
        )
    return (
        f"  The wearer's choices kept from before: {describe(state)} (the wearer's page "
        "changes them)\n"
    )


def _for_the_wearer(url: str | None, *, lan: bool) -> str:
    """The wearer's page: their own URL and key (pause, stop, a ceiling, block a sender)."""
    if url is None:
        return ""
    code = f"{qr_text(url)}" if lan else ""
    return (
        "  For the wearer's phone (pause, stop, a ceiling, do not disturb, block a sender;\n"
        "               keep this key from senders):\n"
        f"               {url}\n{code}"
    )


def _stop_on_signals(sleeve: Sleeve, watchdog: Watchdog) -> None:
    def stop() -> None:
        watchdog.stopping()  # first: the sleeve leaving the broker is then no fault
        sleeve.stop()

    call_on_stop_signals(stop)
