"""`pathbench history record RUN.json...`: store bench JSON (Google Benchmark, every repetition of
every benchmark with its counters) and `pathbench render` reports (one row) in the history.

Each file is one transaction: a malformed or truncated file stores nothing. The same run twice is
refused (run_key: a hash of the file's canonical JSON). Commit and date default to the JSON's own
(context.git_revision / context.date; a render report's git_revision). Every recorded run is also
written as a text file under the export folder (export.py), from which `history rebuild` remakes
the database.
"""
from __future__ import annotations

import datetime as dt
import hashlib
import json
import math
import os
import re
import subprocess

from . import export, store


class RecordError(Exception):
    """Bad input (exit 2) or a refused duplicate."""


# Fields of a Google Benchmark row that are not counters.
_ROW_FIELDS = {"name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
               "repetition_index", "threads", "iterations", "real_time", "cpu_time", "time_unit",
               "aggregate_name", "aggregate_unit", "label", "error_occurred", "error_message"}


def _load(path: str):
    # Duplicate keys (older bench JSON has two `threads`) keep the last; NaN/Infinity become None.
    def pairs(items):
        return {k: v for k, v in items}
    try:
        with open(path, "rb") as f:
            raw = f.read()
        return json.loads(raw, object_pairs_hook=pairs, parse_constant=lambda c: None), raw
    except OSError as e:
        raise RecordError(f"{path}: cannot read: {e.strerror}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise RecordError(f"{path}: not valid JSON ({e})") from None


def _num(v):
    return None if v is None or (isinstance(v, float) and not math.isfinite(v)) else v


def _iso(value: str, what: str) -> str:
    try:
        d = dt.datetime.fromisoformat(value.replace("Z", "+00:00"))
    except (ValueError, AttributeError):
        raise RecordError(f"{what}: {value!r} is not an ISO-8601 date") from None
    if d.tzinfo is None:
        d = d.replace(tzinfo=dt.timezone.utc)
    return d.astimezone(dt.timezone.utc).isoformat(timespec="seconds")


def _commit_date(commit: str, repo: str | None) -> str | None:
    try:
        r = subprocess.run(["git", "-C", repo or ".", "show", "-s", "--format=%cI", commit + "^{commit}"],
                           capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return _iso(r.stdout.strip(), "commit date") if r.returncode == 0 and r.stdout.strip() else None


def _commit_seq(commit: str, repo: str | None) -> int | None:
    """How many commits lead to this one: orders commits that share a committer date (a rebase)."""
    try:
        r = subprocess.run(["git", "-C", repo or ".", "rev-list", "--count", commit + "^{commit}"],
                           capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return int(r.stdout) if r.returncode == 0 and r.stdout.strip().isdigit() else None


def _full_sha(commit: str, repo: str | None) -> str:
    """A short or symbolic revision made the full hash where git knows it; kept as given otherwise."""
    try:
        r = subprocess.run(["git", "-C", repo or ".", "rev-parse", "--verify", "--quiet", commit + "^{commit}"],
                           capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return commit
    return r.stdout.strip() if r.returncode == 0 and r.stdout.strip() else commit


def _slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", str(text).lower()).strip("-") or "machine"


def _bench_results(path: str, rows) -> list[dict]:
    if not isinstance(rows, list):
        raise RecordError(f"{path}: 'benchmarks' is not a list")
    out = []
    for i, row in enumerate(rows):
        if not isinstance(row, dict) or "name" not in row:
            raise RecordError(f"{path}: benchmarks[{i}] has no name")
        if row.get("run_type", "iteration") != "iteration":
            continue  # aggregates (mean, cv, ...) are recomputed from the repetitions
        if row.get("error_occurred"):
            continue
        if not isinstance(row.get("real_time"), (int, float)) or "time_unit" not in row:
            raise RecordError(f"{path}: benchmarks[{i}] ({row['name']}) has no real_time/time_unit")
        counters = {k: _num(v) for k, v in row.items()
                    if k not in _ROW_FIELDS and isinstance(v, (int, float)) and k != "rays_per_second"}
        if isinstance(row.get("threads"), (int, float)):
            counters["threads"] = row["threads"]
        out.append({"benchmark": row.get("run_name", row["name"]), "repetition": int(row.get("repetition_index", 0)),
                    "value": _num(row["real_time"]), "unit": row["time_unit"], "cpu_time": _num(row.get("cpu_time")),
                    "iterations": row.get("iterations"), "rays_per_second": _num(row.get("rays_per_second")),
                    "counters": counters})
    if not out:
        raise RecordError(f"{path}: no repetitions to record (only aggregates or errors); run with "
                          "--benchmark_report_aggregates_only=false")
    keys = [(r["benchmark"], r["repetition"]) for r in out]
    if len(set(keys)) != len(keys):
        raise RecordError(f"{path}: a benchmark repeats a repetition_index")
    return out


def _render_result(path: str, rep: dict) -> dict:
    try:
        name = (f"render/{rep['device']}/{rep['strategy']}/{rep['scene']}/{rep['width']}x{rep['height']}"
                f"/spp:{rep['spp']}/bounces:{rep['bounces']}/{rep['sampling']}")
        seconds = float(rep["seconds"])
    except (KeyError, TypeError, ValueError) as e:
        raise RecordError(f"{path}: render report lacks {e}") from None
    counters = {k: _num(v) for k, v in rep.items() if isinstance(v, (int, float)) and not isinstance(v, bool)
                and k not in ("seconds", "rays_per_second", "width", "height", "spp", "bounces", "seed")}
    if isinstance(rep.get("rays"), dict):
        counters.update({f"rays_{k}": v for k, v in rep["rays"].items() if isinstance(v, (int, float))})
    return {"benchmark": name, "repetition": 0, "value": seconds * 1e3, "unit": "ms", "cpu_time": None,
            "iterations": 1, "rays_per_second": _num(rep.get("rays_per_second")), "counters": counters}


def parse(path: str, commit: str | None = None, date: str | None = None, machine: str | None = None,
          repo: str | None = None) -> dict:
    """The run a file describes, as export.py writes it (a header and its results)."""
    data, raw = _load(path)
    if not isinstance(data, dict):
        raise RecordError(f"{path}: expected a JSON object")
    if "benchmarks" in data:
        kind, context = "bench", data.get("context")
        if not isinstance(context, dict):
            raise RecordError(f"{path}: bench JSON without a context object")
        results = _bench_results(path, data["benchmarks"])
        film_hash = context.get("film_hash")
    elif "strategy" in data and "seconds" in data:
        kind = "render"
        context = {k: v for k, v in data.items() if not isinstance(v, (int, float)) or isinstance(v, bool)}
        results = [_render_result(path, data)]
        film_hash = data.get("film_hash")
    else:
        raise RecordError(f"{path}: neither a bench JSON (context + benchmarks) nor a render report")
    commit = commit or context.get("git_revision")
    if not commit or not isinstance(commit, str) or not commit.split():
        raise RecordError(f"{path}: no git revision in the JSON; pass --commit")
    commit = commit.split()[0]  # some runs annotate it ("638947392d8c (PATHBENCH_SOURCE_COMMIT; ...)")
    run_date = date or context.get("date") or context.get("date_utc")
    if not run_date and kind == "render":  # render reports carry no date yet: the file's own time
        run_date = dt.datetime.fromtimestamp(os.path.getmtime(path), dt.timezone.utc).isoformat()
    if not run_date:
        raise RecordError(f"{path}: no date in the JSON; pass --date")
    run_date = _iso(run_date, f"{path}: date" if not date else "--date")
    commit = _full_sha(commit, repo)
    commit_date = context.get("commit_date") or _commit_date(commit, repo)
    commit_seq = context.get("commit_seq") or _commit_seq(commit, repo)
    try:
        desc = store.machine_description(context)
    except ValueError as e:
        raise RecordError(f"{path}: {e}") from None
    mid = store.machine_id(context)
    m = context.get("machine")
    cpu = context.get("cpu_model") or (m.get("cpu") if isinstance(m, dict) else None)
    name = machine or (context["machine"] if isinstance(context.get("machine"), str) else _slug(cpu or "machine"))
    return {
        "run_key": hashlib.sha256(store.canonical(data).encode()).hexdigest(),
        "kind": kind, "commit": commit, "commit_date": commit_date and _iso(commit_date, "commit date"),
        "commit_seq": commit_seq,
        "run_date": run_date, "machine_id": mid, "machine_name": name, "machine_description": desc,
        "preset": context.get("pathbench_preset"), "film_hash": film_hash,
        "source": os.path.basename(path), "context": context, "results": results,
    }


def insert(db, run: dict) -> int:
    """Store one parsed run in one transaction; refuses a run already there."""
    if db.execute("SELECT 1 FROM runs WHERE run_key=?", (run["run_key"],)).fetchone():
        raise RecordError(f"{run['source']}: this run is already recorded (commit {run['commit'][:12]}, "
                          f"{run['run_date']})")
    db.execute("BEGIN")
    try:
        db.execute("INSERT OR IGNORE INTO machines VALUES (?, ?, ?)",
                   (run["machine_id"], run["machine_name"], store.canonical(run["machine_description"])))
        cur = db.execute(
            "INSERT INTO runs (run_key, kind, commit_sha, commit_date, commit_seq, run_date, machine_id, preset, "
            "film_hash, source, context) VALUES (?,?,?,?,?,?,?,?,?,?,?)",
            (run["run_key"], run["kind"], run["commit"], run["commit_date"], run.get("commit_seq"), run["run_date"],
             run["machine_id"],
             run["preset"], run["film_hash"], run["source"], store.canonical(run["context"])))
        rid = cur.lastrowid
        db.executemany(
            "INSERT INTO results VALUES (?,?,?,?,?,?,?,?,?)",
            [(rid, r["benchmark"], r["repetition"], r["value"], r["unit"], r["cpu_time"], r["iterations"],
              r["rays_per_second"], store.canonical(r["counters"])) for r in run["results"]])
        db.execute("COMMIT")
    except BaseException:
        db.execute("ROLLBACK")
        raise
    return rid


def record_file(db_path: str, path: str, commit=None, date=None, machine=None, export_dir=None) -> dict:
    run = parse(path, commit, date, machine)
    db = store.connect(db_path)
    try:
        # The text file is written aside first and put in place only once the database took the run.
        pending = export.write_run(export_dir, run, pending=True) if export_dir else None
        try:
            insert(db, run)
        except BaseException:
            if pending:
                os.remove(pending)
            raise
        if pending:
            os.replace(pending, pending[: -len(".pending")])
    finally:
        db.close()
    return run
