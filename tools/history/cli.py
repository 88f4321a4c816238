"""`pathbench history SUBCOMMAND`: record, rebuild, changes, report, backfill, instructions.
Exit status: 0 fine, 1 a regression found (changes --fail-on-regression) or a run failed,
2 bad input (message on stderr, nothing stored)."""
from __future__ import annotations

import argparse
import json
import os
import sqlite3
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_DB = os.path.join(ROOT, "results", "history", "history.sqlite")


def _err(msg: str) -> int:
    print(f"pathbench history: error: {msg}", file=sys.stderr)
    return 2


def cmd_record(a) -> int:
    from . import importer, store
    # Every file parsed first: one bad file among many stores none of them.
    try:
        runs = [importer.parse(p, a.commit, a.date, a.machine) for p in a.files]
    except importer.RecordError as e:
        return _err(str(e))
    seen: dict[str, str] = {}
    for p, r in zip(a.files, runs):
        if r["run_key"] in seen:
            return _err(f"{p}: the same run as {seen[r['run_key']]}")
        seen[r["run_key"]] = p
    try:
        db = store.connect(a.db)
    except (store.SchemaError, sqlite3.Error) as e:
        return _err(f"{a.db}: {e}")
    from . import export
    status = 0
    try:
        for run in runs:
            pending = export.write_run(a.export, run, pending=True) if a.export else None
            try:
                importer.insert(db, run)
            except importer.RecordError as e:
                if pending:
                    os.remove(pending)
                print(f"pathbench history: refused: {e}", file=sys.stderr)
                status = 2
                continue
            if pending:
                os.replace(pending, pending[: -len(".pending")])
            print(f"recorded {run['source']}: {len(run['results'])} rows, commit {run['commit'][:12]}, "
                  f"machine {run['machine_name']} ({run['machine_id']})")
    finally:
        db.close()
    return status


def cmd_rebuild(a) -> int:
    from . import export
    if not a.export or not os.path.isdir(a.export):
        return _err(f"{a.export}: no such folder")
    try:
        n = export.rebuild(a.export, a.db)
    except (ValueError, KeyError, json.JSONDecodeError) as e:
        return _err(str(e))
    print(f"rebuilt {a.db} from {n} run files in {a.export}")
    return 0


def _open(path: str):
    from . import store
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: no history database (record runs or run `history rebuild`)")
    return store.connect(path, create=False)


def cmd_changes(a) -> int:
    from . import changes
    import re

    from . import store
    try:
        db = _open(a.db)
        found = changes.find(db, a.benchmark, a.machine, a.max_pvalue, a.min_change, exact=not a.otava_only)
    except (FileNotFoundError, store.SchemaError) as e:
        return _err(str(e))
    except re.error as e:
        return _err(f"--benchmark: not a regular expression: {e}")
    print(json.dumps(changes.as_json(found), indent=1) if a.json else changes.format_table(found))
    if a.fail_on_regression:
        bad = changes.newest_after_regression(found)
        for c in bad:
            p = "exact" if c.p_value is None else f"p={c.p_value:.1e}"
            print(f"regression: {c.benchmark} on {c.machine}: {c.change * 100:+.2f}% since {c.commit[:12]} ({p})",
                  file=sys.stderr)
        return 1 if bad else 0
    return 0


def cmd_report(a) -> int:
    from . import report
    from . import store
    try:
        db = _open(a.db)
    except (FileNotFoundError, store.SchemaError) as e:
        return _err(str(e))
    import re
    try:
        n = report.write_site(db, a.out, commit_url=a.commit_url, png=not a.no_png, repo=a.repo, benchmark=a.benchmark)
    except re.error as e:
        return _err(f"--benchmark: not a regular expression: {e}")
    print(f"wrote {a.out}/index.html: {n} series")
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="pathbench history", description="performance history of pathbench runs")
    sub = ap.add_subparsers(dest="cmd", required=True)

    def with_db(p):
        p.add_argument("--db", default=DEFAULT_DB, help="SQLite database (default: results/history/history.sqlite)")
        return p

    p = with_db(sub.add_parser("record", help="store bench JSON / render reports"))
    p.add_argument("files", nargs="+", metavar="RUN.json")
    p.add_argument("--commit", help="git commit (default: the JSON's git_revision)")
    p.add_argument("--date", help="ISO-8601 date of the run (default: the JSON's)")
    p.add_argument("--machine", help="a name for the machine (its identity stays the fingerprint hash)")
    p.add_argument("--export", help="folder for the text export (default: runs/ beside the database; '' for none)")
    p.set_defaults(fn=cmd_record)

    p = with_db(sub.add_parser("rebuild", help="make the database again from the text export"))
    p.add_argument("--export", help="folder of run files (default: runs/ beside the database)")
    p.set_defaults(fn=cmd_rebuild)

    from .changes import DEFAULT_MAX_PVALUE, DEFAULT_MIN_CHANGE
    p = with_db(sub.add_parser("changes", help="change points per (benchmark, machine) series (Apache Otava)"))
    p.add_argument("--benchmark", help="regular expression on benchmark names")
    p.add_argument("--machine", help="machine name or id prefix")
    p.add_argument("--json", action="store_true", help="a JSON list instead of a table")
    p.add_argument("--fail-on-regression", action="store_true", help="exit 1 when a newest run sits after a regression")
    p.add_argument("--max-pvalue", type=float, default=DEFAULT_MAX_PVALUE)
    p.add_argument("--min-change", type=float, default=DEFAULT_MIN_CHANGE, help="relative; smaller steps are merged away")
    p.add_argument("--otava-only", action="store_true",
                   help="Otava for instruction-count series too (default: their exact steps)")
    p.set_defaults(fn=cmd_changes)

    p = with_db(sub.add_parser("report", help="write the static HTML dashboard"))
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--commit-url", default="", help="link template for commits, e.g. https://host/repo/commit/{}")
    p.add_argument("--repo", default=ROOT, help="git repository for commit subjects")
    p.add_argument("--no-png", action="store_true", help="skip the matplotlib PNG copies")
    p.add_argument("--benchmark", help="regular expression: only these benchmarks")
    p.set_defaults(fn=cmd_report)

    p = sub.add_parser("backfill", help="build and measure each commit of a range", add_help=False)
    p.set_defaults(fn=None)
    p = sub.add_parser("instructions", help="the callgrind instruction-count preset as bench JSON", add_help=False)
    p.set_defaults(fn=None)

    args, rest = ap.parse_known_args(argv)
    if args.cmd == "backfill":
        from . import backfill
        return backfill.main(rest)
    if args.cmd == "instructions":
        from . import instructions
        return instructions.main(rest)
    if rest:
        return _err(f"unrecognised arguments: {' '.join(rest)}")
    if hasattr(args, "export"):
        # The text export lives beside its database: results/history/{history.sqlite,runs/} by default.
        if args.export is None:
            args.export = os.path.join(os.path.dirname(os.path.abspath(args.db)), "runs")
        elif args.export == "":
            args.export = None
    return args.fn(args)
