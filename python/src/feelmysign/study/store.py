"""One study in one SQLite file: the design, participants, trials, answers, sleeve events.

Opened with write-ahead logging and ``synchronous=FULL``, in autocommit mode:
every answer is on disk when the call that records it returns, so a crash,
a ``kill -9`` or Ctrl-C loses nothing already given, and the participant's
session resumes at the first trial without an answer. Safe to share between
the web server's threads (one connection behind a lock).
"""

from __future__ import annotations

import json
import os
import secrets
import sqlite3
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from feelmysign.errors import StudyError
from feelmysign.events import EventError, event_from_json
from feelmysign.input_files import UnusableFile, check_kind
from feelmysign.plural import plural
from feelmysign.study.design import Design
from feelmysign.study.design_file import parse_design
from feelmysign.study.order import participant_order
from feelmysign.study.schema import MIGRATIONS, SCHEMA, SCHEMA_VERSION

# Participant codes: 5 characters without look-alikes (0/O, 1/I/L): 28^5 = 17 million.
CODE_ALPHABET = "23456789ABCDEFGHJKMNPQRSTUVWXYZ"
CODE_LENGTH = 5


RUNNER_STARTS = "runner_starts_json"  # meta: when each runner started (note_runner_start)
DISCARDED = "discarded"  # a threshold run's stop_reason when the researcher discarded it


def now_ms() -> int:
    return round(time.time() * 1000)


class StudyStore:
    """``StudyStore.create(path, design_path)`` once, then ``StudyStore(path)``."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self._check_path()
        self._lock = threading.RLock()
        # The time every row is stamped with: the wall clock, or a dry run's simulated one
        # (so that a dry run's response times, and so its export, follow from its seed).
        self.clock: Callable[[], int] = now_ms
        self.migrated_from: Path | None = None  # the backup, when this open migrated the file
        self._db = self._connect(self.path)
        version = self.meta("schema_version")
        if version is not None and version.isdigit() and int(version) in MIGRATIONS:
            self._migrate(int(version))
            version = self.meta("schema_version")
        if version != str(SCHEMA_VERSION):
            raise StudyError(
                f"{self.path} is not a study file of this version (schema {version!r}, "
                f"expected {SCHEMA_VERSION}); open it with the feelmysign that made it"
            )
        base_dir = Path(self.meta("base_dir") or ".")
        self.design: Design = parse_design(
            self.meta("design_toml") or "",
            source=self.meta("design_source") or "",
            base_dir=base_dir,
        )
        self.base_dir = base_dir

    def _migrate(self, version: int) -> None:
        """Bring a study file of an earlier version up to this one, after a backup of it
        beside it (``NAME.schema-V.bak``, every answer as it was), one step at a time."""
        backup = self.path.with_name(f"{self.path.name}.schema-{version}.bak")
        if not backup.exists():
            target = sqlite3.connect(backup)
            with target:
                self._db.backup(target)
            target.close()
        while version in MIGRATIONS:
            with self._transaction() as db:
                for statement in MIGRATIONS[version]:
                    db.execute(statement)
                version += 1
                db.execute(
                    "UPDATE meta SET value = ? WHERE key = 'schema_version'", (str(version),)
                )
        self.migrated_from = backup

    def _check_path(self) -> None:
        """A study file is there and is a regular file (``os.stat`` does not block on a fifo)."""
        try:
            info = os.stat(self.path)
        except FileNotFoundError:
            raise StudyError(
                f"no study file at {self.path}; create one with "
                "'feelmysign study new DESIGN.toml --out FILE.sqlite'"
            ) from None
        except OSError as error:
            raise StudyError(f"cannot read the study file {self.path}: {error.strerror}") from None
        try:
            check_kind(self.path, info)
        except UnusableFile as error:
            what = str(error.strerror).removeprefix("it ").split(":")[0]  # "is a fifo ..."
            raise StudyError(
                f"the study file {str(self.path)!r} {what}: give the path of the file that "
                "'feelmysign study new DESIGN.toml --out FILE.sqlite' made"
            ) from None

    @staticmethod
    def _connect(path: Path) -> sqlite3.Connection:
        try:
            db = sqlite3.connect(path, isolation_level=None, check_same_thread=False, timeout=10)
            db.execute("PRAGMA journal_mode=WAL")
            db.execute("PRAGMA synchronous=FULL")
            db.execute("PRAGMA foreign_keys=ON")
        except sqlite3.DatabaseError as error:
            if Path(path).suffix.lower() == ".toml":
                what = (
                    f"it looks like a design: make a study file from it with 'feelmysign study "
                    f"new {path} --out STUDY.sqlite', then give STUDY.sqlite here"
                )
            else:
                what = (
                    "give the path of the file that 'feelmysign study new DESIGN.toml --out "
                    "FILE.sqlite' made ('feelmysign study check DESIGN.toml' checks a design)"
                )
            raise StudyError(f"{path} is not a study file ({error}); {what}") from error
        db.row_factory = sqlite3.Row
        return db

    @classmethod
    def create(cls, path: str | Path, design_path: str | Path, design: Design) -> StudyStore:
        """A new study file for ``design`` (already checked); refuses to overwrite one."""
        target = Path(path)
        if target.exists():
            raise StudyError(f"{target} exists already; give another --out, or run the study in it")
        target.parent.mkdir(parents=True, exist_ok=True)
        source = Path(design_path)
        db = cls._connect(target)
        with db:
            db.executescript(SCHEMA)
            for key, value in {
                "schema_version": str(SCHEMA_VERSION),
                "design_toml": source.read_text(encoding="utf-8"),
                "design_source": str(source),
                "base_dir": str(source.resolve().parent),
                "design_json": json.dumps(design.to_json()),
                "created_at_ms": str(now_ms()),
            }.items():
                db.execute("INSERT INTO meta (key, value) VALUES (?, ?)", (key, value))
        db.close()
        return cls(target)

    def close(self) -> None:
        with self._lock:
            self._db.close()

    @contextmanager
    def _transaction(self) -> Iterator[sqlite3.Connection]:
        with self._lock:
            self._db.execute("BEGIN IMMEDIATE")
            try:
                yield self._db
            except BaseException:
                self._db.execute("ROLLBACK")
                raise
            self._db.execute("COMMIT")

    def query(self, sql: str, args: tuple[Any, ...] = ()) -> list[sqlite3.Row]:
        with self._lock:
            return list(self._db.execute(sql, args))

    def meta(self, key: str) -> str | None:
        rows = self.query("SELECT value FROM meta WHERE key = ?", (key,))
        return str(rows[0]["value"]) if rows else None

    def set_meta(self, key: str, value: str) -> None:
        with self._transaction() as db:
            db.execute("INSERT OR REPLACE INTO meta (key, value) VALUES (?, ?)", (key, value))

    def note_runner_start(self) -> None:
        """A runner (the page's server or the terminal, one that sends) starts on this file:
        its time is kept, so that an answer recorded after a restart, to a shape sent before
        it, is known to have waited through the time no runner ran."""
        with self._transaction() as db:
            row = db.execute("SELECT value FROM meta WHERE key = ?", (RUNNER_STARTS,)).fetchone()
            starts = [*json.loads(row[0]), self.clock()] if row else [self.clock()]
            db.execute(
                "INSERT OR REPLACE INTO meta (key, value) VALUES (?, ?)",
                (RUNNER_STARTS, json.dumps(starts)),
            )

    def runner_starts(self) -> list[int]:
        """When a runner started on this file, oldest first (none kept before this was)."""
        stored = self.meta(RUNNER_STARTS)
        return [int(at) for at in json.loads(stored)] if stored else []

    # ---- participants ------------------------------------------------------------------

    def add_participant(self, *, simulated: bool = False) -> str:
        """A new participant with a random code and their whole trial order, stored at once."""
        with self._transaction() as db:
            number = db.execute("SELECT COUNT(*) FROM participants").fetchone()[0]
            code = self._fresh_code(db)
            db.execute(
                "INSERT INTO participants (code, number, created_at_ms, simulated) "
                "VALUES (?,?,?,?)",
                (code, number, self.clock(), int(simulated)),
            )
            for position, trial in enumerate(participant_order(self.design, number)):
                db.execute(
                    "INSERT INTO trials (participant, position, block, repetition, shape, level, "
                    "segments, speed_cm_s) VALUES (?,?,?,?,?,?,?,?)",
                    (
                        code,
                        position,
                        trial.block,
                        trial.repetition,
                        trial.shape,
                        trial.level,
                        trial.segments,
                        trial.speed_cm_s,
                    ),
                )
        return code

    @staticmethod
    def _fresh_code(db: sqlite3.Connection) -> str:
        while True:
            code = "P-" + "".join(secrets.choice(CODE_ALPHABET) for _ in range(CODE_LENGTH))
            if not db.execute("SELECT 1 FROM participants WHERE code = ?", (code,)).fetchone():
                return code

    def participant(self, code: str) -> sqlite3.Row:
        rows = self.query("SELECT * FROM participants WHERE code = ?", (code.strip().upper(),))
        if not rows:
            raise StudyError(
                f"no participant {code!r} in {self.path}; 'feelmysign study status {self.path}' "
                "lists them"
            )
        return rows[0]

    def participants(self) -> list[sqlite3.Row]:
        return self.query("SELECT * FROM participants ORDER BY number")

    def set_consent(self, code: str, consent: bool) -> None:
        code = self.participant(code)["code"]
        with self._transaction() as db:
            db.execute(
                "UPDATE participants SET consent = ?, consent_at_ms = ? WHERE code = ?",
                (int(consent), self.clock(), code),
            )

    def record_comfort(self, code: str, answers: list[bool], adjusted: bool) -> None:
        row = self.participant(code)
        self._require_consent(row)
        if len(answers) != len(self.design.comfort):
            raise StudyError(
                f"the comfort check has {plural(len(self.design.comfort), 'question')}; got "
                f"{plural(len(answers), 'answer')}"
            )
        data = json.dumps({"answers": answers, "adjusted": adjusted})
        with self._transaction() as db:
            db.execute(
                "UPDATE participants SET comfort_json = ?, comfort_at_ms = ? WHERE code = ?",
                (data, self.clock(), row["code"]),
            )

    def _require_consent(self, row: sqlite3.Row) -> None:
        if row["consent"] != 1:
            raise StudyError(
                f"participant {row['code']} has not given consent; nothing is recorded"
            )
        if row["withdrawn"]:
            raise StudyError(f"participant {row['code']} has withdrawn; nothing more is recorded")

    def set_paused(self, code: str, paused: bool) -> None:
        row = self.participant(code)
        if bool(row["paused"]) == paused:
            return
        with self._transaction() as db:
            db.execute(
                "UPDATE participants SET paused = ? WHERE code = ?", (int(paused), row["code"])
            )
            if paused:
                db.execute(
                    "INSERT INTO pauses (participant, paused_at_ms) VALUES (?, ?)",
                    (row["code"], self.clock()),
                )
            else:
                db.execute(
                    "UPDATE pauses SET resumed_at_ms = ? WHERE participant = ? AND resumed_at_ms "
                    "IS NULL",
                    (self.clock(), row["code"]),
                )

    def withdraw(self, code: str) -> None:
        row = self.participant(code)
        with self._transaction() as db:
            db.execute("UPDATE participants SET withdrawn = 1 WHERE code = ?", (row["code"],))

    # ---- trials ------------------------------------------------------------------------

    def trials(self, code: str) -> list[sqlite3.Row]:
        return self.query(
            "SELECT * FROM trials WHERE participant = ? ORDER BY position", (code.upper(),)
        )

    def trial(self, trial_id: int) -> sqlite3.Row:
        rows = self.query("SELECT * FROM trials WHERE id = ?", (trial_id,))
        if not rows:
            raise StudyError(f"no trial {trial_id} in {self.path}")
        return rows[0]

    def current_trial(self, code: str) -> sqlite3.Row | None:
        """The first trial without an answer: where the session goes on after any stop."""
        rows = self.query(
            "SELECT * FROM trials WHERE participant = ? AND answered_at_ms IS NULL "
            "ORDER BY position LIMIT 1",
            (self.participant(code)["code"],),
        )
        return rows[0] if rows else None

    def record_send(self, trial_id: int, drawing: str, strokes: list[dict[str, Any]]) -> int:
        with self._transaction() as db:
            cursor = db.execute(
                "INSERT INTO sends (trial, drawing, sent_at_ms, strokes_json) VALUES (?,?,?,?)",
                (trial_id, drawing, self.clock(), json.dumps(strokes)),
            )
            return int(cursor.lastrowid or 0)

    def record_send_error(self, send_id: int, error: str) -> None:
        with self._transaction() as db:
            db.execute("UPDATE sends SET error = ? WHERE id = ?", (error, send_id))

    def record_events(self, send_id: int, events: list[dict[str, Any]]) -> None:
        with self._transaction() as db:
            for event in events:
                db.execute(
                    "INSERT INTO events (send, type, seq, latency_ms, duration_ms, "
                    "requested_duration_ms, reason, json) VALUES (?,?,?,?,?,?,?,?)",
                    (
                        send_id,
                        _event_type(event),
                        event.get("seq"),
                        event.get("latency_ms"),
                        event.get("duration_ms"),
                        event.get("requested_duration_ms"),
                        event.get("reason"),
                        json.dumps(event),
                    ),
                )

    def sends(self, trial_id: int) -> list[sqlite3.Row]:
        return self.query("SELECT * FROM sends WHERE trial = ? ORDER BY id", (trial_id,))

    def events(self, send_id: int) -> list[sqlite3.Row]:
        return self.query("SELECT * FROM events WHERE send = ? ORDER BY id", (send_id,))

    def record_answer(
        self,
        trial_id: int,
        *,
        answer: str,
        felt_nothing: bool,
        confidence: int | None,
        coding: tuple[str, str | None, str],
    ) -> None:
        """The answer, once (a second answer to a trial is refused), and its automatic coding."""
        trial = self.trial(trial_id)
        self._require_consent(self.participant(trial["participant"]))
        at_ms = self.clock()
        with self._transaction() as db:
            cursor = db.execute(
                "UPDATE trials SET answer = ?, felt_nothing = ?, confidence = ?, "
                "answered_at_ms = ? "
                "WHERE id = ? AND answered_at_ms IS NULL",
                (answer, int(felt_nothing), confidence, at_ms, trial_id),
            )
            if cursor.rowcount != 1:
                raise StudyError(
                    f"trial {trial['position'] + 1} of {trial['participant']} has an answer "
                    "already; answers are never overwritten"
                )
            status, shape, rule = coding
            db.execute(
                "INSERT INTO codings (trial, status, shape, rule, decided_by, decided_at_ms) "
                "VALUES (?,?,?,?,?,?)",
                (trial_id, status, shape, rule, "auto", at_ms),
            )
            left = db.execute(
                "SELECT COUNT(*) FROM trials WHERE participant = ? AND answered_at_ms IS NULL",
                (trial["participant"],),
            ).fetchone()[0]
            if left == 0 and self._questionnaire_done(db, trial["participant"]):
                self._finish(db, trial["participant"])

    # ---- coding decisions --------------------------------------------------------------

    def decide(self, trial_id: int, shape: str | None, rule: str) -> None:
        """The researcher's decision on an answer: a shape, or None for no shape."""
        trial = self.trial(trial_id)
        if trial["answered_at_ms"] is None:
            raise StudyError(f"trial {trial_id} has no answer yet to decide on")
        if trial["block"] != "main":
            raise StudyError(
                f"trial {trial_id} is a practice trial: its answer is not analysed, so there "
                "is nothing to decide; decide the measured answers (study review)"
            )
        if shape is not None and shape not in self.design.shape_names:
            raise StudyError(
                f"{shape!r} is not a shape of this study ({', '.join(self.design.shape_names)})"
            )
        with self._transaction() as db:
            db.execute(
                "INSERT INTO codings (trial, status, shape, rule, decided_by, decided_at_ms) "
                "VALUES (?,?,?,?,?,?)",
                (trial_id, "shape" if shape else "none", shape, rule, "researcher", self.clock()),
            )

    def latest_codings(self) -> dict[int, sqlite3.Row]:
        """The decision in force for each answered trial: the latest one."""
        rows = self.query(
            "SELECT * FROM codings WHERE id IN (SELECT MAX(id) FROM codings GROUP BY trial)"
        )
        return {int(row["trial"]): row for row in rows}

    def awaiting_review(self, code: str | None = None) -> list[int]:
        """Measured answers whose coding is unclear, in trial order (of one participant, or of
        all): the review queue. Practice answers are never in it: they are not analysed, and
        a practice shape need not be a shape of the study the researcher could choose."""
        rows = self.query(
            "SELECT t.id FROM trials t JOIN codings c ON c.trial = t.id "
            "WHERE t.block = 'main' AND t.answered_at_ms IS NOT NULL "
            "AND (? IS NULL OR t.participant = ?) AND c.status = 'unclear' "
            "AND c.id = (SELECT MAX(id) FROM codings WHERE trial = t.id) ORDER BY t.id",
            (code, code),
        )
        return [int(row["id"]) for row in rows]

    def codings(self, trial_id: int) -> list[sqlite3.Row]:
        return self.query("SELECT * FROM codings WHERE trial = ? ORDER BY id", (trial_id,))

    # ---- questionnaire -----------------------------------------------------------------

    def record_questionnaire(self, code: str, values: list[int]) -> None:
        row = self.participant(code)
        self._require_consent(row)
        items, points = self.design.questionnaire.items, self.design.questionnaire.points
        if len(values) != len(items) or not all(1 <= v <= points for v in values):
            raise StudyError(
                f"the questionnaire has {plural(len(items), 'item')}, each answered "
                f"1..{points}; got {values}"
            )
        at_ms = self.clock()
        with self._transaction() as db:
            for item, value in enumerate(values):
                db.execute(
                    "INSERT OR REPLACE INTO questionnaire VALUES (?,?,?,?)",
                    (row["code"], item, value, at_ms),
                )
            left = db.execute(
                "SELECT COUNT(*) FROM trials WHERE participant = ? AND answered_at_ms IS NULL",
                (row["code"],),
            ).fetchone()[0]
            if left == 0:
                self._finish(db, row["code"])

    def questionnaire(self, code: str) -> list[sqlite3.Row]:
        return self.query(
            "SELECT * FROM questionnaire WHERE participant = ? ORDER BY item", (code.upper(),)
        )

    @staticmethod
    def _questionnaire_done(db: sqlite3.Connection, code: str) -> bool:
        count = db.execute("SELECT COUNT(*) FROM questionnaire WHERE participant = ?", (code,))
        return bool(count.fetchone()[0])

    def _finish(self, db: sqlite3.Connection, code: str) -> None:
        db.execute(
            "UPDATE participants SET finished_at_ms = ? WHERE code = ? AND finished_at_ms IS NULL",
            (self.clock(), code),
        )

    # ---- threshold procedure -----------------------------------------------------------

    def start_threshold_run(
        self, code: str, dimension: str, settings: dict[str, Any], *, simulated: bool = False
    ) -> int:
        """A new run; ``simulated`` (or a simulated participant's) runs are dry runs, kept
        apart from measurements in the export and the analysis."""
        row = self.participant(code)
        self._require_consent(row)
        with self._transaction() as db:
            cursor = db.execute(
                "INSERT INTO threshold_runs (participant, dimension, settings_json, started_at_ms, "
                "simulated) VALUES (?,?,?,?,?)",
                (
                    row["code"],
                    dimension,
                    json.dumps(settings),
                    self.clock(),
                    int(simulated or bool(row["simulated"])),
                ),
            )
            return int(cursor.lastrowid or 0)

    def threshold_runs(self, code: str | None = None) -> list[sqlite3.Row]:
        if code is None:
            return self.query("SELECT * FROM threshold_runs ORDER BY id")
        return self.query(
            "SELECT * FROM threshold_runs WHERE participant = ? ORDER BY id", (code.upper(),)
        )

    def record_threshold_trial(
        self,
        run_id: int,
        *,
        value: float,
        direction: str,
        response: str,
        events: list[dict[str, Any]],
        position: int | None = None,
    ) -> int:
        """Store the run's next trial; ``position``, when given, must be that next one."""
        with self._transaction() as db:
            stored = db.execute(
                "SELECT COUNT(*) FROM threshold_trials WHERE run = ?", (run_id,)
            ).fetchone()[0]
            if position is not None and position != stored:
                raise StudyError(
                    f"trial {position + 1} of threshold run {run_id} is not the next one "
                    f"(that is trial {stored + 1}): the page is out of date; reload it"
                )
            position = stored
            db.execute(
                "INSERT INTO threshold_trials (run, position, value, direction, response, correct, "
                "events_json, answered_at_ms) VALUES (?,?,?,?,?,?,?,?)",
                (
                    run_id,
                    position,
                    value,
                    direction,
                    response,
                    int(direction == response),
                    json.dumps(events),
                    self.clock(),
                ),
            )
            return int(position)

    def threshold_trials(self, run_id: int) -> list[sqlite3.Row]:
        return self.query(
            "SELECT * FROM threshold_trials WHERE run = ? ORDER BY position", (run_id,)
        )

    def discard_threshold_run(self, run_id: int) -> None:
        """An unfinished run the researcher discards: kept in the file with its trials, marked
        ``DISCARDED`` (no threshold), left out of the results."""
        with self._transaction() as db:
            db.execute(
                "UPDATE threshold_runs SET finished_at_ms = ?, stop_reason = ? "
                "WHERE id = ? AND finished_at_ms IS NULL",
                (self.clock(), DISCARDED, run_id),
            )

    def finish_threshold_run(
        self, run_id: int, *, threshold: float, low: float, high: float, stop_reason: str
    ) -> None:
        with self._transaction() as db:
            db.execute(
                "UPDATE threshold_runs SET finished_at_ms = ?, threshold = ?, low = ?, high = ?, "
                "stop_reason = ? WHERE id = ?",
                (self.clock(), threshold, low, high, stop_reason, run_id),
            )


def _event_type(event: dict[str, Any]) -> str:
    """The events table's type column: the sleeve event's type, empty for anything else
    (only the sleeve's events reach the store: the sleeve link reads no other)."""
    try:
        return event_from_json(event).kind
    except EventError:
        return ""
