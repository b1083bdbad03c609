"""The pace's time lines, kept across a restart of the sleeve.

The pace rules (``feelmysign.pace``) measure how late a stroke is against the smallest
delay (receipt minus ``sent_at_ms``) seen in its drawing. A sleeve that restarts (a crash,
``kill -9``, a power cut) used to forget them: the strokes of a drawing that the broker held
while it was down then arrived first, the first of them set the drawing's time line, so they
all played (seconds late, each said *delayed on the way*), and the strokes drawn after the
restart, queued behind them, were skipped as ``late``. Now the sleeve keeps each drawing's
smallest delay and when it last played a stroke of it in a small file,
``$XDG_STATE_HOME/feelmysign/pace/<sleeve-id>.json``::

    {"format": "feelmysign-pace/1",
     "drawings": [["d81f...", 4.2, 1795705807950], ...]}

(drawing, smallest delay in ms, wall-clock ms of its last stroke played; oldest first). At
start the sleeve takes back the drawings that played a stroke within ``max_age_ms`` (older
ones have nothing left the broker could hold that is not ``stale``), so held strokes are late
by how long they were held and skipped until the sleeve has caught up, as after a stall, and
the drawing goes on in real time.

The file is written by the sleeve's publishing thread, off the path from a stroke to its
first command: when the sleeve is quiet (no event to publish for a quarter second), and at
most every ``SAVE_EVERY_MS`` while strokes play; written whole to a temporary file and
renamed over the old one, and at every stop, a clean one too (a service restarted in the middle
of a drawing takes its time line back, as after a crash; entries older than ``max_age_ms`` are
left out at the next start, and at most ``REMEMBERED_DRAWINGS`` are kept). Best effort:
a file that cannot be read or written is said in one log line and the sleeve goes on as if
it had none (the pace rules then work as they did without it).
"""

from __future__ import annotations

import json
import logging
import os
from collections import OrderedDict
from collections.abc import Callable

from feelmysign.clock import wall_ms
from feelmysign.events import Played
from feelmysign.sleeve.queue import REMEMBERED_DRAWINGS
from feelmysign.state_home import state_path

log = logging.getLogger(__name__)

PACE_FORMAT = "feelmysign-pace/1"
MAX_PACE_BYTES = 64 * 1024  # 64 drawings of at most 64 characters: under 8 KiB
# While strokes play, how often the file is brought up to date at most; else it is written
# when the sleeve is quiet (its publishing thread idle for a quarter second).
SAVE_EVERY_MS = 1000.0


def pace_path(sleeve_id: str) -> str:
    """``$XDG_STATE_HOME/feelmysign/pace/<sleeve-id>.json``: one file per sleeve."""
    return state_path("pace", f"{sleeve_id}.json")


class PaceMemory:
    """Each drawing's smallest delay and last stroke played, kept in ``path``. ``load`` at
    start, ``played`` for every stroke played and ``save`` when quiet (one thread),
    ``forget`` at a clean stop."""

    def __init__(self, path: str, *, clock_ms: Callable[[], float] = wall_ms) -> None:
        self._path = path
        self._clock_ms = clock_ms
        # drawing -> [smallest delay, last played (wall ms)], the least recently played first.
        self._drawings: OrderedDict[str, list[float]] = OrderedDict()
        self._saved_ms = -float("inf")
        self._unsaved = False
        self._failed = False

    def load(self, max_age_ms: float) -> list[tuple[str, float]]:
        """The drawings kept that played a stroke within ``max_age_ms``, oldest first, as
        (drawing, smallest delay); nothing if there is no file or it cannot be used (said)."""
        try:
            with open(self._path, encoding="utf-8") as file:
                text = file.read(MAX_PACE_BYTES + 1)
        except FileNotFoundError:
            return []
        except OSError as error:
            self._say_unusable(error.strerror or str(error))
            return []
        entries = _entries(text)
        if entries is None:
            self._say_unusable(f"not a {PACE_FORMAT} file")
            return []
        now_ms = self._clock_ms()
        for drawing, delay_ms, played_ms in entries[-REMEMBERED_DRAWINGS:]:
            if now_ms - played_ms <= max_age_ms:
                self._drawings[drawing] = [delay_ms, played_ms]
        return [(drawing, line[0]) for drawing, line in self._drawings.items()]

    def played(self, event: Played) -> None:
        """A stroke played: its drawing's smallest delay and last stroke, written if the last
        write is ``SAVE_EVERY_MS`` old (else by ``save`` when the sleeve is quiet)."""
        drawing, age_ms = event.drawing, event.age_ms
        if drawing is None or age_ms is None:
            return
        now_ms = self._clock_ms()
        line = self._drawings.get(drawing)
        if line is None:
            self._drawings[drawing] = [age_ms, now_ms]
            while len(self._drawings) > REMEMBERED_DRAWINGS:
                self._drawings.popitem(last=False)
        else:
            self._drawings.move_to_end(drawing)
            line[0] = min(line[0], age_ms)
            line[1] = now_ms
        self._unsaved = True
        if now_ms - self._saved_ms >= SAVE_EVERY_MS:
            self.save()

    def save(self) -> None:
        """The file written whole, if anything changed since the last write."""
        if not self._unsaved:
            return
        self._unsaved = False
        self._saved_ms = self._clock_ms()
        drawings = [[d, round(line[0], 3), round(line[1])] for d, line in self._drawings.items()]
        text = json.dumps({"format": PACE_FORMAT, "drawings": drawings}) + "\n"
        temporary = f"{self._path}.{os.getpid()}.tmp"
        try:
            os.makedirs(os.path.dirname(self._path), mode=0o700, exist_ok=True)
            with open(temporary, "w", encoding="utf-8") as file:
                file.write(text)
            os.replace(temporary, self._path)
        except OSError as error:
            if not self._failed:  # once: the next writes would fail the same way
                log.warning(
                    "the sleeve's time lines could not be kept in %s (%s): after a restart, "
                    "strokes the broker held may play late; check that the sleeve's state "
                    "directory can be written",
                    self._path,
                    error.strerror or error,
                )
            self._failed = True

    def _say_unusable(self, problem: str) -> None:
        log.warning(
            "the sleeve's time lines in %s cannot be used (%s): strokes the broker held while "
            "the sleeve was away are timed as if they were new",
            self._path,
            problem,
        )


def _entries(text: str) -> list[tuple[str, float, float]] | None:
    """The file's (drawing, smallest delay, last played) entries, or None if it is not one."""
    if len(text) > MAX_PACE_BYTES:
        return None
    try:
        document = json.loads(text)
    except ValueError:
        return None
    if not isinstance(document, dict) or document.get("format") != PACE_FORMAT:
        return None
    drawings = document.get("drawings")
    if not isinstance(drawings, list):
        return None
    entries = []
    for item in drawings:
        if not (
            isinstance(item, list)
            and len(item) == 3
            and isinstance(item[0], str)
            and all(_finite(v) for v in item[1:])
        ):
            return None
        entries.append((item[0], float(item[1]), float(item[2])))
    return entries


def _finite(value: object) -> bool:
    return (
        isinstance(value, int | float)
        and not isinstance(value, bool)
        and value == value
        and abs(value) != float("inf")
    )
