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
import sqlite3

SCHEMA_VERSION = 1

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


class SchemaError(Exception):
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


def connect(path: str, create: bool = True) -> sqlite3.Connection:
    if create and os.path.dirname(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
    db = sqlite3.connect(path, isolation_level=None)  # transactions explicit (BEGIN/COMMIT)
    db.execute("PRAGMA foreign_keys = ON")
    has_meta = db.execute("SELECT 1 FROM sqlite_master WHERE type='table' AND name='meta'").fetchone()
    if not has_meta:
        if not create:
            raise SchemaError(f"{path}: not a pathbench history database")
        db.executescript("BEGIN;" + SCHEMA + f"INSERT INTO meta VALUES ('schema_version', '{SCHEMA_VERSION}');COMMIT;")
    version = db.execute("SELECT value FROM meta WHERE key='schema_version'").fetchone()
    if version is None or int(version[0]) != SCHEMA_VERSION:
        raise SchemaError(f"{path}: schema version {version and version[0]}, this pathbench reads {SCHEMA_VERSION}")
    return db
