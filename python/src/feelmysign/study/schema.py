"""The tables of a study file (SQLite). One file per study; see ``store.StudyStore``.

Rows are only ever added, or filled in once (a trial's answer): a decision on an
answer is a new ``codings`` row, so every decision is kept with its time.
"""

from __future__ import annotations

SCHEMA_VERSION = 3
# A file of an earlier version is migrated when opened, after a backup (``store.StudyStore``),
# one version at a time. Version 1 had no ``threshold_runs.simulated``; version 2 no
# ``trials.speed_cm_s`` (its designs had one speed: every trial is given that speed, but a
# recorded drawing, which played at its own timing, keeps NULL).
_DESIGN_JSON = "(SELECT value FROM meta WHERE key = 'design_json')"
MIGRATIONS = {
    1: ("ALTER TABLE threshold_runs ADD COLUMN simulated INTEGER NOT NULL DEFAULT 0",),
    2: (
        "ALTER TABLE trials ADD COLUMN speed_cm_s REAL",
        f"UPDATE trials SET speed_cm_s = json_extract({_DESIGN_JSON}, '$.stimulus.speed_cm_s') "
        "WHERE shape NOT IN (SELECT json_extract(shape.value, '$.name') "
        f"FROM json_each({_DESIGN_JSON}, '$.shapes') AS shape "
        "WHERE json_extract(shape.value, '$.recording') IS NOT NULL)",
    ),
}

SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (
    key TEXT PRIMARY KEY,
    value TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS participants (
    code TEXT PRIMARY KEY,                -- random, e.g. P-7K3QX; never a name
    number INTEGER NOT NULL UNIQUE,       -- order of adding: the Latin square row
    created_at_ms INTEGER NOT NULL,
    simulated INTEGER NOT NULL DEFAULT 0, -- 1: a simulated participant (dry run)
    consent INTEGER,                      -- NULL: not asked yet; 1 given; 0 refused
    consent_at_ms INTEGER,
    comfort_json TEXT,                    -- yes/no per comfort question, and adjusted
    comfort_at_ms INTEGER,
    paused INTEGER NOT NULL DEFAULT 0,
    withdrawn INTEGER NOT NULL DEFAULT 0,
    finished_at_ms INTEGER
);
CREATE TABLE IF NOT EXISTS trials (
    id INTEGER PRIMARY KEY,
    participant TEXT NOT NULL REFERENCES participants(code),
    position INTEGER NOT NULL,            -- 0.. in the participant's stored order
    block TEXT NOT NULL,                  -- practice | main
    repetition INTEGER NOT NULL,
    shape TEXT NOT NULL,
    level INTEGER,                        -- index of the resolution; NULL: library practice
    segments INTEGER NOT NULL,
    speed_cm_s REAL,                      -- drawn at; NULL: a recording at its own timing
    answer TEXT,
    felt_nothing INTEGER,
    confidence INTEGER,
    answered_at_ms INTEGER,
    UNIQUE (participant, position)
);
CREATE TABLE IF NOT EXISTS sends (
    id INTEGER PRIMARY KEY,
    trial INTEGER NOT NULL REFERENCES trials(id),
    drawing TEXT NOT NULL,
    sent_at_ms INTEGER NOT NULL,
    strokes_json TEXT NOT NULL,           -- exactly what was published
    error TEXT                            -- why sending failed, when it did
);
CREATE TABLE IF NOT EXISTS events (
    id INTEGER PRIMARY KEY,
    send INTEGER NOT NULL REFERENCES sends(id),
    type TEXT NOT NULL,                   -- played | adjusted | rejected | ...
    seq INTEGER,
    latency_ms REAL,
    duration_ms REAL,
    requested_duration_ms REAL,
    reason TEXT,
    json TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS codings (
    id INTEGER PRIMARY KEY,
    trial INTEGER NOT NULL REFERENCES trials(id),
    status TEXT NOT NULL,                 -- shape | none | unclear
    shape TEXT,
    rule TEXT NOT NULL,
    decided_by TEXT NOT NULL,             -- auto | researcher
    decided_at_ms INTEGER NOT NULL
);
CREATE TABLE IF NOT EXISTS pauses (
    id INTEGER PRIMARY KEY,
    participant TEXT NOT NULL REFERENCES participants(code),
    paused_at_ms INTEGER NOT NULL,
    resumed_at_ms INTEGER
);
CREATE TABLE IF NOT EXISTS questionnaire (
    participant TEXT NOT NULL REFERENCES participants(code),
    item INTEGER NOT NULL,
    value INTEGER NOT NULL,
    answered_at_ms INTEGER NOT NULL,
    PRIMARY KEY (participant, item)
);
CREATE TABLE IF NOT EXISTS threshold_runs (
    id INTEGER PRIMARY KEY,
    participant TEXT NOT NULL REFERENCES participants(code),
    dimension TEXT NOT NULL,              -- length | duration
    settings_json TEXT NOT NULL,
    started_at_ms INTEGER NOT NULL,
    finished_at_ms INTEGER,
    threshold REAL,
    low REAL,
    high REAL,
    stop_reason TEXT,
    simulated INTEGER NOT NULL DEFAULT 0  -- 1: a dry run (a simulated observer answered)
);
CREATE TABLE IF NOT EXISTS threshold_trials (
    id INTEGER PRIMARY KEY,
    run INTEGER NOT NULL REFERENCES threshold_runs(id),
    position INTEGER NOT NULL,
    value REAL NOT NULL,                  -- grid units (length) or ms (duration)
    direction TEXT NOT NULL,              -- up | down | left | right: what was sent
    response TEXT NOT NULL,               -- what the participant said
    correct INTEGER NOT NULL,
    events_json TEXT NOT NULL,
    answered_at_ms INTEGER NOT NULL,
    UNIQUE (run, position)
);
"""
