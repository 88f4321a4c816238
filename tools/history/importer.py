"""`pathbench history record RUN.json...`: store bench JSON (Google Benchmark, every repetition of
every benchmark with its counters) and `pathbench render` reports (one row) in the history.

Each file is one transaction: a malformed or truncated file stores nothing. The same run twice is
refused (run_key: a hash of the file's canonical JSON). Commit and date default to the JSON's own
(context.git_revision / context.date; a render report's git_revision). Every recorded run is also
written as a text file under the export folder (runfile.py), from which `history rebuild` remakes
the database.
"""
from __future__ import annotations

import datetime as dt
import hashlib
import os
import re
import subprocess

from . import runfile, store
from .fields import (MAX_TEXT, RecordError, _iso, _kind, _non_negative, integer, read_bytes, loads, real, revision,
                     text, validate_run)

# Fields of a Google Benchmark row that are not counters.
_ROW_FIELDS = {"name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
               "repetition_index", "threads", "iterations", "real_time", "cpu_time", "time_unit",
               "aggregate_name", "aggregate_unit", "label", "error_occurred", "error_message"}


def _load(path: str):
    raw = read_bytes(path)
    return loads(raw, path), raw


def _git(repo: str | None, *args: str, rev: str, timeout: int = 30) -> str | None:
    """git's output for one revision, or None. The revision comes after --end-of-options (and is
    validated by revision() before), so no revision can be read as an option."""
    try:
        r = subprocess.run(["git", "-C", repo or ".", *args, "--end-of-options", rev + "^{commit}"],
                           capture_output=True, text=True, timeout=timeout)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return r.stdout.strip() if r.returncode == 0 and r.stdout.strip() else None


def _commit_date(commit: str, repo: str | None) -> str | None:
    out = _git(repo, "show", "-s", "--format=%cI", rev=commit, timeout=10)
    return _iso(out, "commit date") if out else None


def _commit_seq(commit: str, repo: str | None) -> int | None:
    """How many commits lead to this one: orders commits that share a committer date (a rebase)."""
    out = _git(repo, "rev-list", "--count", rev=commit)
    return int(out) if out and out.isdigit() else None


def _full_sha(commit: str, repo: str | None) -> str:
    """A short or symbolic revision made the full hash where git knows it; kept as given otherwise."""
    return _git(repo, "rev-parse", "--verify", "--quiet", rev=commit, timeout=10) or commit


def _slug(name: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", str(name).lower()).strip("-")[:80] or "machine"


def _bench_results(path: str, rows) -> list[dict]:
    if not isinstance(rows, list):
        raise RecordError(f"{path}: 'benchmarks' is not a list")
    out = []
    for i, row in enumerate(rows):
        where = f"{path}: benchmarks[{i}]"
        if not isinstance(row, dict) or "name" not in row:
            raise RecordError(f"{where} has no name")
        name = text(row["name"], f"{where}.name")
        if row.get("run_type", "iteration") != "iteration":
            continue  # aggregates (mean, cv, ...) are recomputed from the repetitions
        if row.get("error_occurred"):
            continue
        if not isinstance(row.get("real_time"), (int, float)) or isinstance(row.get("real_time"), bool) \
                or "time_unit" not in row:
            raise RecordError(f"{where} ({name[:80]}) has no real_time/time_unit")
        counters = {k: real(v, f"{where}.{k}") for k, v in row.items()
                    if k not in _ROW_FIELDS and isinstance(v, (int, float)) and not isinstance(v, bool)
                    and k != "rays_per_second"}
        if isinstance(row.get("threads"), (int, float)) and not isinstance(row["threads"], bool):
            counters["threads"] = real(row["threads"], f"{where}.threads")
        out.append({"benchmark": text(row.get("run_name", name), f"{where}.run_name"),
                    "repetition": integer(row.get("repetition_index", 0), f"{where}.repetition_index", hi=2**31 - 1),
                    "value": _non_negative(real(row["real_time"], f"{where}.real_time", optional=False),
                                           f"{where}.real_time"),
                    "unit": text(row["time_unit"], f"{where}.time_unit", limit=64),
                    "cpu_time": real(row.get("cpu_time"), f"{where}.cpu_time"),
                    "iterations": integer(row.get("iterations"), f"{where}.iterations", optional=True),
                    "rays_per_second": real(row.get("rays_per_second"), f"{where}.rays_per_second"),
                    "counters": counters})
    if not out:
        raise RecordError(f"{path}: no repetitions to record (only aggregates or errors); run with "
                          "--benchmark_report_aggregates_only=false")
    keys = [(r["benchmark"], r["repetition"]) for r in out]
    if len(set(keys)) != len(keys):
        raise RecordError(f"{path}: a benchmark repeats a repetition_index")
    return out


def _render_result(path: str, rep: dict) -> dict:
    for k in ("device", "strategy", "scene", "width", "height", "spp", "bounces", "sampling", "seconds"):
        if k not in rep:
            raise RecordError(f"{path}: render report lacks '{k}'")
    s = {k: text(rep[k], f"{path}: {k}", limit=256) for k in ("device", "strategy", "scene", "sampling")}
    n = {k: integer(rep[k], f"{path}: {k}") for k in ("width", "height", "spp", "bounces")}
    seconds = _non_negative(real(rep["seconds"], f"{path}: seconds", optional=False), f"{path}: seconds")
    name = (f"render/{s['device']}/{s['strategy']}/{s['scene']}/{n['width']}x{n['height']}"
            f"/spp:{n['spp']}/bounces:{n['bounces']}/{s['sampling']}")
    counters = {k: real(v, f"{path}: {k}") for k, v in rep.items()
                if isinstance(v, (int, float)) and not isinstance(v, bool)
                and k not in ("seconds", "rays_per_second", "width", "height", "spp", "bounces", "seed")}
    if isinstance(rep.get("rays"), dict):
        counters.update({f"rays_{k}": real(v, f"{path}: rays.{k}") for k, v in rep["rays"].items()
                         if isinstance(v, (int, float)) and not isinstance(v, bool)})
    return {"benchmark": name, "repetition": 0, "value": real(seconds * 1e3, f"{path}: seconds", optional=False),
            "unit": "ms", "cpu_time": None, "iterations": 1,
            "rays_per_second": real(rep.get("rays_per_second"), f"{path}: rays_per_second"), "counters": counters}


def parse(path: str, commit: str | None = None, date: str | None = None, machine: str | None = None,
          repo: str | None = None) -> dict:
    """The run a file describes, as runfile.py writes it (a header and its results); every field
    checked (validate_run), so what parse returns can be stored and exported."""
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
    if commit is not None:
        commit = revision(commit, "--commit")
    else:
        given = context.get("git_revision")
        if given is not None and not isinstance(given, str):
            raise RecordError(f"{path}: git_revision: expected a string, got {_kind(given)}")
        if not given or not given.split():
            raise RecordError(f"{path}: no git revision in the JSON; pass --commit")
        # some runs annotate it ("638947392d8c (PATHBENCH_SOURCE_COMMIT; ...)")
        commit = revision(given.split()[0], f"{path}: git_revision")
    run_date = date or context.get("date") or context.get("date_utc")
    if not run_date and kind == "render":  # render reports carry no date yet: the file's own time
        try:
            run_date = dt.datetime.fromtimestamp(os.path.getmtime(path), dt.timezone.utc).isoformat()
        except (OSError, OverflowError, ValueError):
            run_date = None
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
    if machine is not None:
        name = text(machine, "--machine", limit=200)
    else:
        name = context["machine"][:200] if isinstance(context.get("machine"), str) else _slug(cpu or "machine")
    run = {
        "run_key": hashlib.sha256(store.canonical(data).encode()).hexdigest(),
        "kind": kind, "commit": commit, "commit_date": commit_date and _iso(commit_date, f"{path}: commit_date"),
        "commit_seq": commit_seq,
        "run_date": run_date, "machine_id": mid, "machine_name": name, "machine_description": desc,
        "preset": context.get("pathbench_preset"), "film_hash": film_hash,
        "source": os.path.basename(path)[:MAX_TEXT], "context": context, "results": results,
    }
    # The same gate as a run file read back, rows included: what record takes, rebuild takes.
    return validate_run(run, path)


def _insert_rows(db, run: dict) -> int:
    """The rows of one run, inside the caller's transaction."""
    if db.execute("SELECT 1 FROM runs WHERE run_key=?", (run["run_key"],)).fetchone():
        raise RecordError(f"{run['source']}: this run is already recorded (commit {run['commit'][:12]}, "
                          f"{run['run_date']})")
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
    return rid


def recorded(db, run_key: str) -> bool:
    return db.execute("SELECT 1 FROM runs WHERE run_key=?", (run_key,)).fetchone() is not None


def insert_all(db, runs: list[dict], export_dir: str | None = None, skip_recorded: bool = False) -> list[dict]:
    """Stores runs in ONE transaction (BEGIN IMMEDIATE: a concurrent writer waits up to the busy
    timeout, then this one goes; nothing is lost) and, with export_dir, their run files: written
    to temporary names first (before the lock is taken, so it is held only for the inserts), put in
    place just before the commit, removed again if it fails. All or nothing: a refused run (already
    recorded) stores none. Returns the runs stored."""
    staged: dict[str, tuple[str, str]] = {}  # run_key -> (temporary file, final name)
    placed: list[str] = []
    stored = []
    try:
        if export_dir:
            for run in runs:
                staged[run["run_key"]] = runfile.stage_run(export_dir, run)
        db.execute("BEGIN IMMEDIATE")
        try:
            for run in runs:
                if skip_recorded and recorded(db, run["run_key"]):
                    continue
                _insert_rows(db, run)
                stored.append(run)
            for run in stored:
                if run["run_key"] in staged:
                    tmp, final = staged.pop(run["run_key"])
                    existed = os.path.exists(final)
                    os.replace(tmp, final)
                    store.TEMPORARY.discard(tmp)
                    if not existed:
                        placed.append(final)
            db.execute("COMMIT")
        except BaseException as e:
            if not db.in_transaction:  # a signal came after the COMMIT: stored, run files and all
                e.stored = True
                raise
            db.execute("ROLLBACK")
            for final in placed:
                _remove(final)
            raise
    finally:
        for tmp, _ in staged.values():  # runs skipped, or everything after a failure
            store.remove_temporary_one(tmp)
    return stored


def _remove(path: str) -> None:
    try:
        os.remove(path)
    except FileNotFoundError:
        pass


def insert(db, run: dict) -> int:
    """Store one parsed run in one transaction; refuses a run already there."""
    insert_all(db, [run])
    return db.execute("SELECT id FROM runs WHERE run_key=?", (run["run_key"],)).fetchone()[0]


def record_file(db_path: str, path: str, commit=None, date=None, machine=None, export_dir=None) -> dict:
    run = parse(path, commit, date, machine)
    db = store.connect(db_path)
    try:
        insert_all(db, [run], export_dir)
    finally:
        db.close()
    return run
