"""``feelmysign sleeve``: the daemon that plays strokes on the sleeve (or its simulator)."""

from __future__ import annotations

import argparse
import logging
import os
import sys
from collections.abc import Callable, Mapping
from contextlib import nullcontext
from typing import TYPE_CHECKING

from feelmysign.backends.base import Backend
from feelmysign.backends.factory import BACKEND_NAMES, BackendName, button_inputs, open_backend
from feelmysign.backends.sim import SimBackend
from feelmysign.backends.telemetry import ActuatorFrame, ActuatorTelemetry
from feelmysign.cli.options.broker import add_broker_options, broker_settings_from_args
from feelmysign.cli.options.emulation import add_emulate_state_option
from feelmysign.cli.options.layout import add_layout_options, layout_from_args
from feelmysign.cli.options.parser import Subcommands
from feelmysign.cli.options.values import number, output_file, topic
from feelmysign.cli.options.wearer import add_wearer_option, wearer_from_args
from feelmysign.cli.options.wearer_page import add_wearer_page_options
from feelmysign.connection import BrokerSettings
from feelmysign.daemon import Sleeve, SleeveOptions
from feelmysign.errors import FeelMySignError
from feelmysign.fates import Fate
from feelmysign.layout import Layout
from feelmysign.pace import MAX_AGE_MS, MAX_LAG_MS
from feelmysign.services.stop_signals import call_on_stop_signals
from feelmysign.sleeve.admission import BURST, RATE_PER_S
from feelmysign.topics import LEGACY_TOPIC

if TYPE_CHECKING:
    from feelmysign.backends.button import ButtonWatcher

TELEMETRY_RATE_HZ = 20.0  # previews look smooth at 20 frames a second; more only costs traffic
MAX_AGE_RANGE_MS = (100.0, 3_600_000.0)
MAX_LAG_RANGE_MS = (10.0, 600_000.0)

MIN_RATE_PER_S = 0.1  # one stroke in 10 s: slower is a sleeve that refuses everything
MAX_RATE_PER_S = 10_000.0  # far above what a person draws; the planner is the limit


def register(subparsers: Subcommands) -> None:
    parser = subparsers.add_parser(
        "sleeve",
        help="run the sleeve: play every stroke sent to it",
        description=(
            "Run the sleeve daemon: subscribe to this sleeve's strokes (JSON v1) and to the "
            "legacy topic, plan each stroke with Tactile Brush and play it on the motors "
            "(--backend drv2605) or the simulator (--backend sim), publishing status, "
            "actuator telemetry and one event per stroke. Ctrl-C or SIGTERM stops it with "
            "every motor off. On the motors it holds their I2C bus while it runs (a lock, "
            "/run/lock/feelmysign-i2c-N.lock, or FILE.lock beside --emulate-state FILE): a "
            "second sleeve, 'feelmysign buzz' and 'feelmysign scan' on that bus are refused, "
            "naming it, and 'feelmysign off' says it drives the motors again."
        ),
    )
    add_broker_options(parser, role="sleeve")
    add_layout_options(parser)
    add_wearer_option(parser)
    add_wearer_page_options(parser)
    parser.add_argument(
        "--backend",
        choices=BACKEND_NAMES,
        default="sim",
        help="sim: the simulator; drv2605: DRV2605L chips over I2C (default: sim)",
    )
    parser.add_argument(
        "--emulate",
        action="store_true",
        help="with --backend drv2605: an emulated I2C bus wired as the layout says",
    )
    add_emulate_state_option(parser)
    parser.add_argument(
        "--legacy-topic",
        default=LEGACY_TOPIC,
        type=topic,
        metavar="TOPIC",
        help=f"also play legacy text strokes from this topic (default: {LEGACY_TOPIC})",
    )
    parser.add_argument(
        "--no-legacy", action="store_true", help="do not listen on the legacy topic"
    )
    parser.add_argument(
        "--record",
        metavar="FILE",
        help="with --backend sim: write every actuator change as JSON lines",
    )
    parser.add_argument(
        "--strict",
        action="store_true",
        help="reject strokes too fast to render instead of slowing them",
    )
    parser.add_argument(
        "--rate-per-s",
        type=number(MIN_RATE_PER_S, MAX_RATE_PER_S, unit="strokes per second"),
        default=RATE_PER_S,
        metavar="R",
        help=f"strokes accepted per second on average (default: {RATE_PER_S:g}; bursts of {BURST})",
    )
    _add_limit_ms(
        parser,
        "--max-age-ms",
        MAX_AGE_MS,
        MAX_AGE_RANGE_MS,
        "refuse strokes sent longer ago than this, by the sender's clock",
        reason="stale",
    )
    _add_limit_ms(
        parser,
        "--max-lag-ms",
        MAX_LAG_MS,
        MAX_LAG_RANGE_MS,
        "skip strokes that would start later than this after they were due, to catch up after "
        "a stall",
        reason="late",
    )
    parser.add_argument(
        "--log-level",
        default="info",
        choices=["debug", "info", "warning", "error"],
        help="how much to log on stderr (default: info)",
    )
    parser.set_defaults(handler=run)


def _add_limit_ms(
    parser: argparse.ArgumentParser,
    flag: str,
    default_ms: float,
    range_ms: tuple[float, float],
    what: str,
    *,
    reason: str,
) -> None:
    """A limit in milliseconds, its help ending with the refusal's reason, default and range."""
    low_ms, high_ms = range_ms
    parser.add_argument(
        flag,
        type=number(low_ms, high_ms, unit="milliseconds"),
        default=default_ms,
        metavar="MS",
        help=f"{what} (reason {reason}; default: {default_ms:g}, in [{low_ms:g}, {high_ms:g}])",
    )


def run(args: argparse.Namespace) -> int:
    logging.basicConfig(
        level=args.log_level.upper(),
        stream=sys.stderr,
        format="%(asctime)s %(levelname)s %(message)s",
    )
    if args.record is not None:
        output_file(args.record, option="--record")
    layout = layout_from_args(args)
    wearer = wearer_from_args(args, layout)
    settings = broker_settings_from_args(args, "sleeve")
    options = SleeveOptions(
        sleeve_id=settings.sleeve_id,
        legacy_topic=None if args.no_legacy else args.legacy_topic,
        rate_per_s=args.rate_per_s,
        strict=args.strict,
        backend_name=args.backend
        + (" (emulated bus)" if args.emulate or args.emulate_state else ""),
        max_age_ms=args.max_age_ms,
        max_lag_ms=args.max_lag_ms,
        wearer=wearer,
    )
    print(
        f"Sleeve {options.sleeve_id}: {layout.rows} x {layout.columns} actuators, "
        f"{options.backend_name} backend, broker {settings.url}; Ctrl-C to stop",
        flush=True,
    )
    if wearer is not None:
        from feelmysign.wearer import sleeve_floor

        floor = sleeve_floor(layout, wearer)
        print(
            f"Wearer {wearer.name}: its status asks senders for strokes of at least "
            f"{floor.min_duration_ms:g} ms and {floor.min_length:g} grid units",
            flush=True,
        )
    running: list[Sleeve] = []  # the sleeve once started: the wearer's page controls it
    page = None
    if args.wearer_host is not None and args.wearer_page is None:
        raise FeelMySignError(
            f"--wearer-host {args.wearer_host} needs --wearer-page [PORT]: add it to serve the "
            "wearer's page, or leave --wearer-host out."
        )
    if args.wearer_page is not None:
        from feelmysign.cli._wearer_page import wearer_page_server

        page = wearer_page_server(args, options.sleeve_id, layout, running, settings)

    def started(sleeve: Sleeve) -> None:
        running.append(sleeve)
        _on_start(sleeve, settings, options)

    with page[0] if page is not None else nullcontext():
        if page is not None:
            print(page[1], end="", flush=True)
        sleeve = run_sleeve(
            settings,
            layout,
            options,
            backend=args.backend,
            record=args.record,
            emulate=args.emulate,
            emulate_state=args.emulate_state,
            on_start=started,
        )
    totals = stop_totals(sleeve.stroke_totals())
    print(f"Sleeve {options.sleeve_id} stopped, every motor off ({totals})", flush=True)
    return 0


def stop_totals(totals: Mapping[Fate, int]) -> str:
    """What the sleeve did with every stroke, by fate (feelmysign.fates, as ``up``'s lines and
    the page count): played and rejected always, cut short and cancelled when there were any."""
    parts = [f"{totals['played']} played"]
    if totals["cut"]:
        parts.append(f"{totals['cut']} cut short")
    if totals["cancelled"]:
        parts.append(f"{totals['cancelled']} cancelled")
    parts.append(f"{totals['refused']} rejected")
    return ", ".join(parts)


def run_sleeve(
    settings: BrokerSettings,
    layout: Layout,
    options: SleeveOptions,
    *,
    backend: BackendName = "sim",
    record: str | None = None,
    emulate: bool = False,
    emulate_state: str | None = None,
    on_start: Callable[[Sleeve], None] = lambda sleeve: None,
    sim_buttons: bool = False,
) -> Sleeve:
    """Open the backend with its telemetry, run the sleeve until it stops; every motor off after.
    Returns the stopped sleeve (its counts, its strokes by fate). ``sim_buttons``: with the
    simulator, the layout's buttons are emulated, pressed through a pipe beside the sleeve's
    controls file (``feelmysign up``), instead of read from GPIO lines."""
    sleeves: list[Sleeve] = []

    def publish(frame: ActuatorFrame) -> None:
        if sleeves:
            sleeves[0].publish_actuators(frame.as_dict())

    with (
        ActuatorTelemetry(publish, rate_hz=TELEMETRY_RATE_HZ) as telemetry,
        open_backend(
            backend,
            layout,
            record=record,
            telemetry=telemetry,
            emulate=emulate,
            emulate_state=emulate_state,
        ) as opened,
    ):
        sleeve = Sleeve(settings, layout, opened, options, telemetry=telemetry)
        sleeves.append(sleeve)
        watchers = _watch_buttons(layout, opened, sleeve, sim_buttons=sim_buttons)
        if sim_buttons and isinstance(opened, SimBackend) and layout.enable is not None:
            print(
                f"The layout's enable line ({layout.enable.name}) is left alone: the "
                "simulated sleeve drives no GPIO.",
                flush=True,
            )
        try:
            on_start(sleeve)
            sleeve.run()
        finally:
            for watcher in watchers:
                watcher.stop()
    return sleeve


def _watch_buttons(
    layout: Layout, backend: Backend, sleeve: Sleeve, *, sim_buttons: bool = False
) -> list[ButtonWatcher]:
    """The wearer's buttons ([controls]) watched, each on a thread; HardwareError (what to
    check) for one that cannot be had: the wearer's control is never silently absent."""
    from feelmysign.backends.button import ButtonWatcher
    from feelmysign.backends.emulated_button import PIPE_SUFFIX, pipe_path, press_command

    watchers: list[ButtonWatcher] = []
    sim_pipe = os.path.splitext(sleeve.controls.path)[0] + PIPE_SUFFIX if sim_buttons else None
    bus_state = getattr(getattr(backend, "bus", None), "state_path", None)
    pipe = sim_pipe if isinstance(backend, SimBackend) else bus_state and pipe_path(bus_state)
    try:
        for button, line in button_inputs(layout, backend, sim_pipe=sim_pipe):
            watcher = ButtonWatcher(line, button.role, sleeve.controls)
            watcher.start()
            watchers.append(watcher)
            kind = "pause button (press: pause/resume, hold 1 s: stop)"
            if button.role != "pause":
                kind = "turn-down button (each press: a step down)"
            print(f"The wearer's {kind}: {line.description}", flush=True)
            if pipe:
                print(
                    f"  press it:  {press_command(pipe, button.chip, button.line)}\n"
                    f"  let go:    {press_command(pipe, button.chip, button.line, 'release')}",
                    flush=True,
                )
    except BaseException:
        for watcher in watchers:
            watcher.stop()
        raise
    return watchers


def _on_start(sleeve: Sleeve, settings: BrokerSettings, options: SleeveOptions) -> None:
    _stop_on_signals(sleeve)
    _check_clock_meanwhile(settings, options)


def _check_clock_meanwhile(settings: BrokerSettings, options: SleeveOptions) -> None:
    """Compare this machine's clock with the broker's (feelmysign.broker_clock), on a thread
    of its own, once the motors are open and off: the motors and the strokes never wait for
    it; the log says what it found."""
    import threading

    from feelmysign.broker_clock import check_clock

    threading.Thread(
        target=check_clock,
        args=(settings,),
        kwargs={"max_age_ms": options.max_age_ms, "sleeve_id": options.sleeve_id},
        name="feelmysign-clock-check",
        daemon=True,
    ).start()


def _stop_on_signals(sleeve: Sleeve) -> None:
    call_on_stop_signals(sleeve.stop)
