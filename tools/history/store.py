"""The history database: one SQLite schema, versioned (SCHEMA_VERSION, kept in meta), and the
machine identity. SCHEMA.md beside this file documents the tables; change both together.

Machines are keyed by a hash of what describes the hardware, not by a slug of the CPU name: the
`fingerprint` object when the JSON has one (volatile keys such as load and the date left out), else
the fields today's bench context already carries (host_name, cpu_model, num_cpus, mhz_per_cpu,
caches) or a render report's `machine` object.
"""
from __future__ import annotations

import hashlib
import json
import os
import pathlib
import sqlite3
import stat

SCHEMA_VERSION = 1
# How long a writer waits for another one to finish (sqlite's busy timeout, seconds). The largest
# run a file may hold (32 MiB, ~165,000 rows) holds the lock ~4 s on the loaded 2-core VM; a
# 4,000-row run well under one. 120 s lets ten writers of the largest runs queue with room to
# spare, and still ends (exit 2, "database is locked") where a writer hangs holding the lock.
def _busy_timeout(default: float = 120.0) -> float:
    try:
        v = float(os.environ.get("PATHBENCH_HISTORY_BUSY_TIMEOUT", default))
    except ValueError:
        return default
    return v if 0 <= v <= 86400 else default


BUSY_TIMEOUT_S = _busy_timeout()

SCHEMA = """
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE machines (
  id TEXT PRIMARY KEY,             -- machine_id(): 16 hex digits
  name TEXT NOT NULL,              -- for people: --machine, the JSON's slug, or the CPU model
  description TEXT NOT NULL        -- canonical JSON of what was hashed
);
CREATE TABLE runs (
  id INTEGER PRIMARY KEY,
  run_key TEXT NOT NULL UNIQUE,    -- sha256 of the run's canonical JSON: the same run twice is refused
  kind TEXT NOT NULL,              -- 'bench' (Google Benchmark JSON) or 'render' (pathbench render report)
  commit_sha TEXT NOT NULL,
  commit_date TEXT,                -- ISO-8601 committer date; orders the series ...
  commit_seq INTEGER,              -- ... then this: commits reachable from it (rebased commits share a date)
  run_date TEXT NOT NULL,          -- ISO-8601, when it ran
  machine_id TEXT NOT NULL REFERENCES machines(id),
  preset TEXT,                     -- context.pathbench_preset where given
  film_hash TEXT,                  -- image checksum where the JSON has one, else NULL
  source TEXT,                     -- file name it was recorded from
  context TEXT NOT NULL            -- the run's context / environment, canonical JSON
);
CREATE TABLE results (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  benchmark TEXT NOT NULL,         -- Google Benchmark run_name
  repetition INTEGER NOT NULL,
  value REAL,                      -- the series' metric, lower is better: real_time (or seconds) ...
  unit TEXT NOT NULL,              -- ... in this unit ('ms', 'ns', 's', 'instructions' per sample)
  cpu_time REAL,
  iterations INTEGER,
  rays_per_second REAL,
  counters TEXT NOT NULL,          -- every other numeric field, canonical JSON (NaN stored as null)
  PRIMARY KEY (run_id, benchmark, repetition)
);
CREATE INDEX results_benchmark ON results(benchmark);
CREATE INDEX runs_machine ON runs(machine_id, commit_date);
"""

# Keys that change from run to run on one machine: never part of its identity.
VOLATILE = {"load", "load_avg", "load_average", "load_average_at_start", "date", "date_utc", "time",
            "uptime", "frequency_now", "mhz_now", "cur_freq", "scaling_cur_freq", "temperature",
            "free_memory", "memory_available", "executable", "git_revision", "git_dirty", "pid"}
FALLBACK_KEYS = ("host_name", "cpu_model", "num_cpus", "mhz_per_cpu", "caches")


# Temporary files and folders this process made and has not yet renamed or removed (staged run
# files, a database being rebuilt, a site being written). The CLI's signal watcher removes them
# where a signal arrives while the main thread is stuck in C (a sqlite busy wait) and cannot
# unwind through its finally blocks in time.
TEMPORARY: set[str] = set()


def remove_temporary_one(path: str) -> None:
    """path (a file, a folder, or a database with its journal) removed and forgotten."""
    import shutil
    for p in (path, path + "-journal", path + "-wal", path + "-shm"):
        try:
            if os.path.isdir(p) and not os.path.islink(p):
                shutil.rmtree(p, ignore_errors=True)
            else:
                os.remove(p)
        except OSError:
            pass
    TEMPORARY.discard(path)


def remove_temporary() -> None:
    for path in list(TEMPORARY):
        remove_temporary_one(path)


class UserError(Exception):
    """Bad input or a bad database: `pathbench history` prints it as one line and exits 2."""


class SchemaError(UserError):
    pass


def canonical(obj) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=False, default=str)


def _strip_volatile(obj):
    if isinstance(obj, dict):
        return {k: _strip_volatile(v) for k, v in obj.items() if k not in VOLATILE}
    if isinstance(obj, list):
        return [_strip_volatile(v) for v in obj]
    return obj


def machine_description(context: dict) -> dict:
    """What identifies the machine: the fingerprint object if present, else today's context keys."""
    fp = context.get("fingerprint")
    if isinstance(fp, dict) and fp:
        return {"fingerprint": _strip_volatile(fp)}
    desc = {k: context[k] for k in FALLBACK_KEYS if k in context}
    if not desc and isinstance(context.get("machine"), dict):  # render report: {"cpu", "hardware_threads"}
        desc = {k: v for k, v in context["machine"].items() if k != "threads"}
    if not desc:
        raise ValueError("no machine description (neither a fingerprint object nor host/CPU fields)")
    return desc


def machine_id(context: dict) -> str:
    return hashlib.sha256(canonical(machine_description(context)).encode()).hexdigest()[:16]


def _statements(script: str) -> list[str]:
    body = "\n".join(line.split("--")[0] for line in script.splitlines())
    return [st.strip() for st in body.split(";") if st.strip()]


def connect(path: str, create: bool = True, readonly: bool = False) -> sqlite3.Connection:
    """The database at path; a new one (schema and version) where none exists and create is set.
    readonly opens it without ever writing (changes, report): a read-only file or folder works.
    sqlite errors (not a database, truncated, locked past the busy timeout, read-only) propagate as
    sqlite3.Error: the CLI names the database and exits 2."""
    if os.path.isdir(path):
        raise UserError(f"{path}: is a folder, not a history database")
    if os.path.exists(path) and not stat.S_ISREG(os.stat(path).st_mode):  # sqlite would block on a FIFO
        raise UserError(f"{path}: not a regular file, so not a history database")
    if not create and not os.path.exists(path):
        raise UserError(f"{path}: no history database (record runs or run `history rebuild`)")
    if create and os.path.dirname(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
    if readonly:
        uri = pathlib.Path(os.path.abspath(path)).as_uri() + "?mode=ro"
        db = sqlite3.connect(uri, uri=True, isolation_level=None, timeout=BUSY_TIMEOUT_S)
    else:
        db = sqlite3.connect(path, isolation_level=None, timeout=BUSY_TIMEOUT_S)  # transactions explicit
    try:
        db.execute("PRAGMA foreign_keys = ON")
        has_meta = db.execute("SELECT 1 FROM sqlite_master WHERE type='table' AND name='meta'").fetchone()
        if not has_meta:
            if not create or readonly:
                raise SchemaError(f"{path}: not a pathbench history database")
            # Two writers may create one new database at once: the second waits, then finds it made.
            db.execute("BEGIN IMMEDIATE")
            try:
                if not db.execute("SELECT 1 FROM sqlite_master WHERE type='table' AND name='meta'").fetchone():
                    if db.execute("SELECT 1 FROM sqlite_master").fetchone():
                        raise SchemaError(f"{path}: not a pathbench history database (it holds other tables)")
                    for st in _statements(SCHEMA):
                        db.execute(st)
                    db.execute("INSERT INTO meta VALUES ('schema_version', ?)", (str(SCHEMA_VERSION),))
                db.execute("COMMIT")
            except BaseException:
                db.execute("ROLLBACK")
                raise
        try:
            version = db.execute("SELECT value FROM meta WHERE key='schema_version'").fetchone()
        except sqlite3.Error:
            version = None
        if version is None or str(version[0]) != str(SCHEMA_VERSION):
            shown = "none" if version is None else repr(version[0])[:40]
            raise SchemaError(f"{path}: schema version {shown}, this pathbench reads {SCHEMA_VERSION}")
    except BaseException:
        db.close()
        raise
    return db
