"""The one gate for what the history reads from files (bench JSON, render reports, run files of
the export): JSON as the history takes it (depth, duplicate keys, non-finite numbers, lone
surrogates), bounded files, and every field of a run checked for the type and range its column
takes. A value outside them is a RecordError naming the file and the field (exit 2).
Shared by importer.py (record) and runfile.py (rebuild's reader), so neither imports the other.
"""
from __future__ import annotations

import datetime as dt
import json
import math
import os
import re
import stat

from . import store


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
