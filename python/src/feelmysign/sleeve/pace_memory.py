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

The same file notes the strokes playing, so that a stroke cut short by the end of the sleeve's
process (``kill -9``, a crash, an OOM kill, a power cut) is not left recorded as played whole::

    "playing": [{"topic": "feelmysign/s1/strokes", "drawing": "d81f...", "seq": 4,
                 "sent_at_ms": 1795705807950, "received_at_ms": 1795705807954,
                 "started_at_ms": 1795705807955, "ends_at_ms": 1795705808955}],
    "alive_at_ms": 1795705807956

A stroke's ``played`` event goes out (and the stroke is acknowledged) at its first command.
The publishing thread notes the stroke here (``playing``) before it hands that event on,
so no ``played`` event leaves the sleeve for a stroke this file does not name: a process
that dies before the note neither published the event nor acknowledged the stroke (the
broker delivers it again). The note costs the path to the first command nothing (it is
written after it, on another thread). Each write also says when it was made
(``alive_at_ms``: the process ran then), and a stroke is dropped from the note once its
planned end (``ends_at_ms``) has passed at a write; while a stroke plays the file is written
again ``END_NOTE_MS`` after its end and every ``SAVE_EVERY_MS`` (a heartbeat). So a stroke
the file still names with an end after its last write had not ended, as far as anyone can
tell, when the process died: the sleeve that starts next reports each such stroke
(``interrupted``) as cut short (a ``safety`` event ``crashed``, after its ``played``), and
one that ended before the process died is not reported (the note is brought up to date
within ``END_NOTE_MS`` of its end: a death in those few milliseconds reports it cut).
"""

from __future__ import annotations

import json
import logging
import math
import os
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from feelmysign.clock import wall_ms
from feelmysign.events import Played, StrokeRef
from feelmysign.sleeve.queue import REMEMBERED_DRAWINGS
from feelmysign.state_home import state_path

log = logging.getLogger(__name__)

PACE_FORMAT = "feelmysign-pace/1"
MAX_PACE_BYTES = 64 * 1024  # 64 drawings of at most 64 characters: under 8 KiB
# While strokes play, how often the file is brought up to date at most; else it is written
# when the sleeve is quiet (its publishing thread idle for a quarter second).
SAVE_EVERY_MS = 1000.0
# How long after a noted stroke's planned end the file is written again without it: the
# sleeve's last sign of life before that end, or after it. A death in between (rare: a few
# milliseconds) reports a stroke that had ended as cut; a longer wait would report more.
END_NOTE_MS = 5.0
MAX_NOTED = 16  # strokes playing at once: one, two where one ends as the next starts


@dataclass(frozen=True)
class Playing:
    """A stroke noted as playing: what names it in its events, when its first command went
    out and when it was planned to end (the sleeve's wall clock, ms)."""

    topic: str | None
    drawing: str | None
    seq: int | None
    sent_at_ms: float | None
    received_at_ms: float
    started_at_ms: float
    ends_at_ms: float

    @property
    def key(self) -> tuple[str | None, int | None, float]:
        return (self.drawing, self.seq, self.received_at_ms)

    def ref(self) -> StrokeRef:
        return StrokeRef(
            self.topic, self.drawing, self.seq, self.sent_at_ms, received_at_ms=self.received_at_ms
        )


@dataclass(frozen=True)
class Interrupted:
    """A stroke that was playing when the sleeve's process ended: ``playing``, and the last
    time the process was known to run (``alive_at_ms``: it had played at least until then)."""

    playing: Playing
    alive_at_ms: float

    @property
    def played_at_least_ms(self) -> float:
        return max(0.0, self.alive_at_ms - self.playing.started_at_ms)

    @property
    def duration_ms(self) -> float:
        return self.playing.ends_at_ms - self.playing.started_at_ms


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
        self._saved_once = False  # the folder is made before the first write only
        # The strokes playing, by (drawing, seq, received_at_ms), as last noted.
        self._playing: dict[tuple[str | None, int | None, float], Playing] = {}
        # Noted by the process before this one and still playing when it ended (see load).
        self._interrupted: list[Interrupted] = []

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
        self._interrupted = _interrupted(text)
        if self._interrupted:
            self._unsaved = True  # the next write leaves them out: reported once
        now_ms = self._clock_ms()
        for drawing, delay_ms, played_ms in entries[-REMEMBERED_DRAWINGS:]:
            if now_ms - played_ms <= max_age_ms:
                self._drawings[drawing] = [delay_ms, played_ms]
        return [(drawing, line[0]) for drawing, line in self._drawings.items()]

    def interrupted(self) -> list[Interrupted]:
        """After ``load``: the strokes the sleeve's last process was playing when it ended
        (their planned end after its last sign of life), oldest first."""
        return list(self._interrupted)

    def playing(self, event: Played) -> None:
        """A stroke's first command went out: noted as playing, with its drawing's time line,
        and the file written now, before its ``played`` event leaves the sleeve."""
        self._remember(event)
        received_at_ms = event.received_at_ms
        if received_at_ms is not None:
            note = Playing(
                event.topic,
                event.drawing,
                event.seq,
                event.sent_at_ms,
                received_at_ms,
                event.first_command_at_ms,
                event.start_at_ms + event.duration_ms,
            )
            self._playing[note.key] = note
            while len(self._playing) > MAX_NOTED:
                del self._playing[next(iter(self._playing))]
        self._unsaved = True
        self.save()

    def settled(self, ref: StrokeRef) -> None:
        """A stroke said cut short or cancelled while it played: no longer noted as playing
        (left out at the next write)."""
        received_at_ms = ref.received_at_ms
        if received_at_ms is None:
            return
        if self._playing.pop((ref.drawing, ref.seq, received_at_ms), None) is not None:
            self._unsaved = True

    def keep_up(self) -> float:
        """Now and then (the publishing thread, whenever it wakes): the file written again
        once a noted stroke has ended (``END_NOTE_MS`` after its end) and every
        ``SAVE_EVERY_MS`` while one plays. How long until it is needed next (s; ``math.inf``
        while nothing plays)."""
        if not self._playing:
            return math.inf
        now_ms = self._clock_ms()
        ended_ms = min(note.ends_at_ms for note in self._playing.values()) + END_NOTE_MS
        if now_ms >= ended_ms or now_ms - self._saved_ms >= SAVE_EVERY_MS:
            self._unsaved = True
            self.save()
            if not self._playing:
                return math.inf
            now_ms = self._clock_ms()
            ended_ms = min(note.ends_at_ms for note in self._playing.values()) + END_NOTE_MS
        next_ms = min(ended_ms, self._saved_ms + SAVE_EVERY_MS)
        return max(0.0, next_ms - now_ms) / 1000

    def played(self, event: Played) -> None:
        """A stroke played: its drawing's smallest delay and last stroke, written if the last
        write is ``SAVE_EVERY_MS`` old (else by ``save`` when the sleeve is quiet)."""
        if self._remember(event) and self._clock_ms() - self._saved_ms >= SAVE_EVERY_MS:
            self.save()

    def _remember(self, event: Played) -> bool:
        """The drawing's time line brought up to date with ``event``; False: it has none."""
        drawing, age_ms = event.drawing, event.age_ms
        if drawing is None or age_ms is None:
            return False
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
        return True

    def save(self) -> None:
        """The file written whole, if anything changed since the last write."""
        if not self._unsaved:
            return
        self._unsaved = False
        now_ms = self._saved_ms = self._clock_ms()
        drawings = [[d, round(line[0], 3), round(line[1])] for d, line in self._drawings.items()]
        document: dict[str, object] = {"format": PACE_FORMAT, "drawings": drawings}
        for key in [key for key, note in self._playing.items() if note.ends_at_ms <= now_ms]:
            del self._playing[key]  # ended while the process ran: not cut by its end
        if self._playing:
            document["playing"] = [note.__dict__ for note in self._playing.values()]
        document["alive_at_ms"] = now_ms
        text = json.dumps(document) + "\n"
        temporary = f"{self._path}.{os.getpid()}.tmp"
        try:
            if not self._saved_once:
                os.makedirs(os.path.dirname(self._path), mode=0o700, exist_ok=True)
            with open(temporary, "w", encoding="utf-8") as file:
                file.write(text)
            os.replace(temporary, self._path)
            self._saved_once = True
        except OSError as error:
            self._saved_once = False  # the folder may have gone: made again at the next write
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


def _interrupted(text: str) -> list[Interrupted]:
    """The strokes a file names as playing whose planned end came after its last write (the
    file is a ``PACE_FORMAT`` one); entries that are not such a note are left out."""
    document = json.loads(text)
    alive_at_ms = document.get("alive_at_ms")
    notes = document.get("playing")
    if not _finite(alive_at_ms) or not isinstance(notes, list):
        return []
    found = []
    for item in notes[:MAX_NOTED]:
        note = _note(item)
        if note is not None and note.ends_at_ms > alive_at_ms:
            found.append(Interrupted(note, float(alive_at_ms)))
    return found


def _note(item: object) -> Playing | None:
    if not isinstance(item, dict):
        return None
    times: list[Any] = [item.get(n) for n in ("received_at_ms", "started_at_ms", "ends_at_ms")]
    topic, drawing, seq = item.get("topic"), item.get("drawing"), item.get("seq")
    sent_at_ms = item.get("sent_at_ms")
    if not all(_finite(value) for value in times):
        return None
    if sent_at_ms is not None and not _finite(sent_at_ms):
        return None
    if not all(value is None or isinstance(value, str) for value in (topic, drawing)):
        return None
    if seq is not None and (not isinstance(seq, int) or isinstance(seq, bool) or seq < 0):
        return None
    received_at_ms, started_at_ms, ends_at_ms = (float(value) for value in times)
    return Playing(topic, drawing, seq, sent_at_ms, received_at_ms, started_at_ms, ends_at_ms)
