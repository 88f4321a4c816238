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
import stat
import subprocess

from . import export, store


class RecordError(store.UserError):
    """Bad input (exit 2) or a refused duplicate."""


# Limits on what a run file may hold; beyond them the file is refused with the limit named.
MAX_FILE_BYTES = 32 << 20   # real bench JSON are < 1 MB; 32 MiB (300k rows) records in ~15 s
MAX_DEPTH = 64              # nesting of objects/arrays (a fingerprint is 3 deep)
MAX_TEXT = 4096             # characters of a name, unit, preset...
INT64 = (1 << 63) - 1       # SQLite INTEGER
_SURROGATE = re.compile("[\ud800-\udfff]")
_SURROGATE_ESCAPE = re.compile(r"\\u[dD][89a-fA-F]")
_SURROGATE_ESCAPE_BYTES = re.compile(rb"\\u[dD][89a-fA-F]")
_REVISION = re.compile(r"[A-Za-z0-9][A-Za-z0-9._/~^@{}+-]{0,199}")

# Fields of a Google Benchmark row that are not counters.
_ROW_FIELDS = {"name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
               "repetition_index", "threads", "iterations", "real_time", "cpu_time", "time_unit",
               "aggregate_name", "aggregate_unit", "label", "error_occurred", "error_message"}


def _kind(v) -> str:
    return {dict: "an object", list: "a list", str: "a string", bool: "a boolean", type(None): "null",
            int: "an integer", float: "a number"}.get(type(v), type(v).__name__)


def _finite(text: str):
    v = float(text)
    return v if math.isfinite(v) else None  # 1e999: an extreme is no measurement


def loads(text, where: str):
    """JSON as the history reads it: duplicate keys keep the last (older bench JSON has two
    `threads`); NaN, Infinity and overflowing numbers become null; then checked for depth and
    for strings that are not Unicode (lone surrogates), which no database or terminal takes."""
    try:
        data = json.loads(text, object_pairs_hook=dict, parse_constant=lambda c: None, parse_float=_finite)
    except RecursionError:
        raise RecordError(f"{where}: JSON nested too deeply (limit {MAX_DEPTH})") from None
    except UnicodeDecodeError:
        raise RecordError(f"{where}: not UTF-8 text") from None
    except json.JSONDecodeError as e:
        raise RecordError(f"{where}: not valid JSON ({e})") from None
    except ValueError as e:  # an integer of more than 4300 digits
        raise RecordError(f"{where}: not valid JSON ({e})") from None
    # Strict UTF-8 cannot carry a surrogate: only a \\uD800-\\uDFFF escape can make one.
    pattern = _SURROGATE_ESCAPE if isinstance(text, str) else _SURROGATE_ESCAPE_BYTES
    strings = pattern.search(text) is not None
    stack = [(data, 1)] if isinstance(data, (dict, list)) else []
    if isinstance(data, str) and strings and _SURROGATE.search(data):
        raise RecordError(f"{where}: a string is not valid Unicode (a lone surrogate)")
    while stack:
        v, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise RecordError(f"{where}: JSON nested too deeply (limit {MAX_DEPTH})")
        values = v.values() if isinstance(v, dict) else v
        if strings and (any(_SURROGATE.search(k) for k in v) if isinstance(v, dict) else False):
            raise RecordError(f"{where}: a key is not valid Unicode (a lone surrogate)")
        for x in values:
            if type(x) is dict or type(x) is list:
                stack.append((x, depth + 1))
            elif strings and type(x) is str and _SURROGATE.search(x):
                raise RecordError(f"{where}: a string is not valid Unicode (a lone surrogate)")
    return data


def read_bytes(path: str, limit: int = MAX_FILE_BYTES) -> bytes:
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):  # a FIFO would block, a device never end
            raise RecordError(f"{path}: not a regular file")
        with open(path, "rb") as f:
            raw = f.read(limit + 1)
    except OSError as e:
        raise RecordError(f"{path}: cannot read: {e.strerror or e}") from None
    if len(raw) > limit:
        raise RecordError(f"{path}: larger than {limit >> 20} MiB, the limit for a run file")
    return raw


def _load(path: str):
    raw = read_bytes(path)
    return loads(raw, path), raw


def text(v, what: str, optional: bool = False, limit: int = MAX_TEXT) -> str | None:
    if v is None and optional:
        return None
    if not isinstance(v, str):
        raise RecordError(f"{what}: expected a string, got {_kind(v)}")
    if len(v) > limit:
        raise RecordError(f"{what}: longer than {limit} characters")
    return v


def integer(v, what: str, optional: bool = False, lo: int = 0, hi: int = INT64) -> int | None:
    if v is None and optional:
        return None
    if isinstance(v, float) and v.is_integer():
        v = int(v)
    if not isinstance(v, int) or isinstance(v, bool):
        raise RecordError(f"{what}: expected an integer, got {_kind(v)}")
    if not lo <= v <= hi:
        raise RecordError(f"{what}: {v if abs(v) < 10**30 else 'a huge integer'} is outside [{lo}, {hi}]")
    return v


def real(v, what: str, optional: bool = True) -> float | int | None:
    """A finite number (an int within 64 bits stays one), or None (null, NaN, an overflow) where optional."""
    if v is None and optional:
        return None
    if not isinstance(v, (int, float)) or isinstance(v, bool):
        raise RecordError(f"{what}: expected a number, got {_kind(v)}")
    if isinstance(v, int) and -INT64 <= v <= INT64:
        return v  # kept exact (byte counts); a larger one becomes a float, as SQLite would
    try:
        f = float(v)
    except OverflowError:
        f = math.inf
    if not math.isfinite(f):
        if optional:
            return None
        raise RecordError(f"{what}: {v if isinstance(v, float) else 'a huge integer'} is not a finite number")
    return f


def revision(v, what: str) -> str:
    """A git revision as given (a hash, a short hash, HEAD~2, v1.0-dirty): never one that git
    could read as an option, nor one with spaces or control characters."""
    v = text(v, what, limit=200)
    if not _REVISION.fullmatch(v):
        raise RecordError(f"{what}: {v[:60]!r} is not a git revision (letters, digits and ._/~^@{{}}+- only, "
                          "not starting with '-')")
    return v


def _num(v):
    return real(v, "value")


def _iso(value, what: str) -> str:
    try:
        d = dt.datetime.fromisoformat(value.replace("Z", "+00:00"))
        if d.tzinfo is None:
            d = d.replace(tzinfo=dt.timezone.utc)
        return d.astimezone(dt.timezone.utc).isoformat(timespec="seconds")
    except (ValueError, AttributeError, TypeError, OverflowError):
        shown = repr(value)[:60] if isinstance(value, str) else _kind(value)
        raise RecordError(f"{what}: {shown} is not an ISO-8601 date (years 0001-9999, UTC)") from None


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
    """The run a file describes, as export.py writes it (a header and its results); every field
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


_HEX = re.compile(r"[0-9a-f]+")


def validate_run(run, where: str, check_results: bool = True) -> dict:
    """A run as stored (parse's result, or a run file of the export read back): every field of the
    type and range its column takes, or RecordError naming the file and the field."""
    if not isinstance(run, dict):
        raise RecordError(f"{where}: the run header is not an object")
    for k in ("run_key", "kind", "commit", "run_date", "machine_id", "machine_name", "machine_description",
              "context", "results"):
        if k not in run:
            raise RecordError(f"{where}: the run lacks '{k}'")
    key = text(run["run_key"], f"{where}: run_key", limit=64)
    if len(key) != 64 or not _HEX.fullmatch(key):
        raise RecordError(f"{where}: run_key is not a sha256 (64 hex digits)")
    mid = text(run["machine_id"], f"{where}: machine_id", limit=16)
    if len(mid) != 16 or not _HEX.fullmatch(mid):
        raise RecordError(f"{where}: machine_id is not 16 hex digits")
    if run["kind"] not in ("bench", "render"):
        raise RecordError(f"{where}: kind must be 'bench' or 'render'")
    out = dict(run)
    out["commit"] = revision(run["commit"], f"{where}: commit")
    out["run_date"] = _iso(run["run_date"], f"{where}: run_date")
    out["commit_date"] = None if run.get("commit_date") is None else _iso(run["commit_date"], f"{where}: commit_date")
    out["commit_seq"] = integer(run.get("commit_seq"), f"{where}: commit_seq", optional=True)
    out["machine_name"] = text(run["machine_name"], f"{where}: machine_name", limit=200)
    for k in ("preset", "film_hash", "source"):
        out[k] = text(run.get(k), f"{where}: {k}", optional=True)
    for k in ("machine_description", "context"):
        if not isinstance(run[k], dict):
            raise RecordError(f"{where}: {k}: expected an object, got {_kind(run[k])}")
    if not isinstance(run["results"], list) or not run["results"]:
        raise RecordError(f"{where}: results: expected a non-empty list")
    if not check_results:
        return out
    results, seen = [], set()
    for i, r in enumerate(run["results"]):
        w = f"{where}: results[{i}]"
        if not isinstance(r, dict):
            raise RecordError(f"{w}: expected an object, got {_kind(r)}")
        if not isinstance(r.get("counters", {}), dict):
            raise RecordError(f"{w}.counters: expected an object")
        res = {"benchmark": text(r.get("benchmark"), f"{w}.benchmark"),
               "repetition": integer(r.get("repetition"), f"{w}.repetition", hi=2**31 - 1),
               "value": _non_negative(real(r.get("value"), f"{w}.value"), f"{w}.value"),
               "unit": text(r.get("unit"), f"{w}.unit", limit=64),
               "cpu_time": real(r.get("cpu_time"), f"{w}.cpu_time"),
               "iterations": integer(r.get("iterations"), f"{w}.iterations", optional=True),
               "rays_per_second": real(r.get("rays_per_second"), f"{w}.rays_per_second"),
               "counters": {text(k, f"{w}.counters key"): real(v, f"{w}.counters.{k[:40]}")
                            for k, v in r.get("counters", {}).items()}}
        if (res["benchmark"], res["repetition"]) in seen:
            raise RecordError(f"{w}: {res['benchmark'][:80]!r} repetition {res['repetition']} appears twice")
        seen.add((res["benchmark"], res["repetition"]))
        results.append(res)
    out["results"] = results
    return out


def _non_negative(v, what: str):
    if v is not None and v < 0:
        raise RecordError(f"{what}: {v} is negative; a time or a count is not")
    return v


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
    from . import export
    staged: dict[str, tuple[str, str]] = {}  # run_key -> (temporary file, final name)
    placed: list[str] = []
    stored = []
    try:
        if export_dir:
            for run in runs:
                staged[run["run_key"]] = export.stage_run(export_dir, run)
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
        except BaseException:
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
