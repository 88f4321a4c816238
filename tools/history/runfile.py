"""A recorded run as a text file, for git: a header line, then one line per benchmark repetition,
sorted. File name: <run date>_<commit 12>_<run key 8>.jsonl, so a folder listing is in time order
and the same run never collides with another. Read back through the same gate as `record`
(fields.validate_run).
"""
from __future__ import annotations

import os
import re
import tempfile

from . import fields, store


HEADER_KEYS = ("run_key", "kind", "commit", "commit_date", "commit_seq", "run_date", "machine_id", "machine_name",
               "machine_description", "preset", "film_hash", "source", "context")


def file_name(run: dict) -> str:
    date = run["run_date"].replace(":", "").replace("-", "")[:15]
    commit = re.sub(r"[^A-Za-z0-9_-]", "_", run["commit"][:12])  # a revision may hold '/', '.', '~'
    return f"{date}_{commit}_{run['run_key'][:8]}.jsonl"


def _lines(run: dict) -> str:
    lines = [store.canonical({"run": {k: run.get(k) for k in HEADER_KEYS}})]
    for r in sorted(run["results"], key=lambda r: (r["benchmark"], r["repetition"])):
        lines.append(store.canonical(r))
    return "\n".join(lines) + "\n"


def stage_run(folder: str, run: dict) -> tuple[str, str]:
    """The run file written under a temporary name in folder: (temporary path, final path). The
    caller renames it into place (os.replace) or removes it; a crash leaves only a dot-file."""
    os.makedirs(folder, exist_ok=True)
    final = os.path.join(folder, file_name(run))
    fd, tmp = tempfile.mkstemp(prefix=".", suffix=".jsonl.tmp", dir=folder)
    store.TEMPORARY.add(tmp)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(_lines(run))
    except BaseException:
        os.remove(tmp)
        store.TEMPORARY.discard(tmp)
        raise
    return tmp, final


def write_run(folder: str, run: dict) -> str:
    tmp, final = stage_run(folder, run)
    os.replace(tmp, final)
    store.TEMPORARY.discard(tmp)
    return final


def read_run(path: str) -> dict:
    raw = fields.read_bytes(path)
    try:
        body = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise fields.RecordError(f"{path}: not UTF-8 text (byte {e.start})") from None
    lines = [(n, line) for n, line in enumerate(body.split("\n"), 1) if line.strip()]
    docs = [fields.loads(line, f"{path}:{n}") for n, line in lines]
    if not docs or not isinstance(docs[0], dict) or not isinstance(docs[0].get("run"), dict):
        raise fields.RecordError(f"{path}: not a history run file (no header line)")
    run = dict(docs[0]["run"])
    run["results"] = docs[1:]
    run["source"] = run.get("source") or os.path.basename(path)
    return fields.validate_run(run, path)
