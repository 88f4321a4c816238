"""The history as text, for git: one JSON-lines file per recorded run (a header line, then one line
per benchmark repetition, sorted), and `history rebuild`, which makes a database from those files.

File name: <run date>_<commit 12>_<run key 8>.jsonl, so a folder listing is in time order and
the same run never collides with another.
"""
from __future__ import annotations

import glob
import json
import os

from . import store

HEADER_KEYS = ("run_key", "kind", "commit", "commit_date", "commit_seq", "run_date", "machine_id", "machine_name",
               "machine_description", "preset", "film_hash", "source", "context")


def file_name(run: dict) -> str:
    date = run["run_date"].replace(":", "").replace("-", "")[:15]
    return f"{date}_{run['commit'][:12]}_{run['run_key'][:8]}.jsonl"


def write_run(folder: str, run: dict, pending: bool = False) -> str:
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, file_name(run)) + (".pending" if pending else "")
    lines = [store.canonical({"run": {k: run.get(k) for k in HEADER_KEYS}})]
    for r in sorted(run["results"], key=lambda r: (r["benchmark"], r["repetition"])):
        lines.append(store.canonical(r))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path


def read_run(path: str) -> dict:
    with open(path) as f:
        lines = [json.loads(line) for line in f if line.strip()]
    if not lines or "run" not in lines[0]:
        raise ValueError(f"{path}: not a history run file (no header line)")
    run = dict(lines[0]["run"])
    run["results"] = lines[1:]
    return run


def rebuild(folder: str, db_path: str) -> int:
    """A fresh database at db_path from every run file in folder; returns the number of runs."""
    from . import importer
    files = sorted(glob.glob(os.path.join(folder, "*.jsonl")))
    tmp = db_path + ".rebuild"
    if os.path.exists(tmp):
        os.remove(tmp)
    db = store.connect(tmp)
    try:
        for path in files:
            run = read_run(path)
            run["source"] = run.get("source") or os.path.basename(path)
            importer.insert(db, run)
    finally:
        db.close()
    os.replace(tmp, db_path)  # the old database stays until the new one is complete
    return len(files)
