"""The history as text, for git: one JSON-lines file per recorded run (runfile.py: its format),
and `history rebuild`, which makes a database from those files.
"""
from __future__ import annotations

import glob
import os
import tempfile

from . import importer, runfile, store


def rebuild(folder: str, db_path: str) -> int:
    """A fresh database at db_path from every run file in folder; returns the number of runs.
    Made under a temporary name beside db_path and renamed over it only when complete: on any
    failure the old database is untouched and the temporary one removed."""
    if os.path.isdir(db_path):
        raise store.UserError(f"{db_path}: is a folder, not a history database")
    if os.path.exists(db_path):  # replaced only if it is one: never a file that holds something else
        store.connect(db_path, create=False, readonly=True).close()
    files = sorted(glob.glob(os.path.join(glob.escape(folder), "*.jsonl")))
    runs, seen = [], {}
    for path in files:
        run = runfile.read_run(path)
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
