"""The history as text, for git: one JSON-lines file per recorded run (a header line, then one line
per benchmark repetition, sorted), and `history rebuild`, which makes a database from those files.

File name: <run date>_<commit 12>_<run key 8>.jsonl, so a folder listing is in time order and
the same run never collides with another.
"""
from __future__ import annotations

import glob
import os
import re
import tempfile

from . import store

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
    from . import importer
    raw = importer.read_bytes(path)
    try:
        body = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise importer.RecordError(f"{path}: not UTF-8 text (byte {e.start})") from None
    lines = [(n, line) for n, line in enumerate(body.split("\n"), 1) if line.strip()]
    docs = [importer.loads(line, f"{path}:{n}") for n, line in lines]
    if not docs or not isinstance(docs[0], dict) or not isinstance(docs[0].get("run"), dict):
        raise importer.RecordError(f"{path}: not a history run file (no header line)")
    run = dict(docs[0]["run"])
    run["results"] = docs[1:]
    run["source"] = run.get("source") or os.path.basename(path)
    return importer.validate_run(run, path)


def rebuild(folder: str, db_path: str) -> int:
    """A fresh database at db_path from every run file in folder; returns the number of runs.
    Made under a temporary name beside db_path and renamed over it only when complete: on any
    failure the old database is untouched and the temporary one removed."""
    from . import importer
    if os.path.isdir(db_path):
        raise store.UserError(f"{db_path}: is a folder, not a history database")
    if os.path.exists(db_path):  # replaced only if it is one: never a file that holds something else
        store.connect(db_path, create=False, readonly=True).close()
    files = sorted(glob.glob(os.path.join(glob.escape(folder), "*.jsonl")))
    runs, seen = [], {}
    for path in files:
        run = read_run(path)
        if run["run_key"] in seen:
            raise importer.RecordError(f"{path}: the same run as {seen[run['run_key']]} (run_key "
                                       f"{run['run_key'][:12]}); remove one of them")
        seen[run["run_key"]] = os.path.basename(path)
        runs.append(run)
    folder_of_db = os.path.dirname(os.path.abspath(db_path))
    os.makedirs(folder_of_db, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(db_path) + ".", suffix=".rebuild", dir=folder_of_db)
    os.close(fd)
    store.TEMPORARY.add(tmp)
    try:
        os.remove(tmp)  # sqlite makes the file itself; the name stays ours
        db = store.connect(tmp)
        try:
            importer.insert_all(db, runs)
        finally:
            db.close()
        os.replace(tmp, db_path)  # the old database stays until the new one is complete
    finally:
        store.remove_temporary_one(tmp)
    return len(files)
