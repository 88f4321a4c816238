"""`pathbench history SUBCOMMAND`: record, rebuild, changes, report, backfill, instructions.

Exit status (docs/history.md): 0 fine; 1 only for "a regression found" (changes
--fail-on-regression); 2 bad input or a bad database, as ONE line on stderr, nothing stored and
nothing left behind; 3 an internal error (a bug: one line too, PATHBENCH_DEBUG=1 shows the
traceback); 128+N when stopped by signal N (SIGINT, SIGTERM, SIGHUP), again with nothing left behind.
"""
from __future__ import annotations

import argparse
import json
import os
import signal
import sqlite3
import sys

from .text import term

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# The project's text export: in a source tree results/history/runs; `cmake --install` and
# `pip install .` lay it down beside the tools (share/pathbench/results/history/runs).
DEFAULT_RUNS = os.path.join(ROOT, "results", "history", "runs")
# The database: in a source tree (a checkout has .git) results/history/history.sqlite (git-ignored);
# an installed pathbench has no writable tree, so the per-user data folder, as `pathbench suite`.
IN_SOURCE_TREE = os.path.exists(os.path.join(ROOT, ".git"))
DEFAULT_DB = (os.path.join(ROOT, "results", "history", "history.sqlite") if IN_SOURCE_TREE else
              os.path.join(os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local", "share"),
                           "pathbench", "history.sqlite"))
PROG = "pathbench history"


class UsageError(Exception):
    pass


class Stopped(BaseException):
    """A signal asked us to stop: raised where Python is, so every finally (temporary files,
    ROLLBACK) runs before the exit."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def _err(msg: str) -> int:
    print(f"{PROG}: error: {term(msg)}", file=sys.stderr)
    return 2


def _out(msg: str) -> None:
    print(term(msg))


def cmd_record(a) -> int:
    from . import importer, store
    # Every file parsed first: one bad file among many stores none of them.
    runs = [importer.parse(p, a.commit, a.date, a.machine) for p in a.files]
    seen: dict[str, str] = {}
    for p, r in zip(a.files, runs):
        if r["run_key"] in seen:
            return _err(f"{p}: the same run as {seen[r['run_key']]}")
        seen[r["run_key"]] = p
    db = store.connect(a.db)
    try:
        stored = importer.insert_all(db, runs, a.export, skip_recorded=a.skip_recorded)
    finally:
        db.close()
    keys = {r["run_key"] for r in stored}
    for run in runs:
        if run["run_key"] not in keys:
            _out(f"already recorded {run['source']}: skipped")
            continue
        _out(f"recorded {run['source']}: {len(run['results'])} rows, commit {run['commit'][:12]}, "
             f"machine {run['machine_name']} ({run['machine_id']})")
    return 0


def cmd_rebuild(a) -> int:
    from . import export
    if not os.path.isdir(a.runs):
        return _err(f"{a.runs}: no such folder of run files (--runs)")
    n = export.rebuild(a.runs, a.db)
    _out(f"rebuilt {a.db} from {n} run files in {a.runs}")
    return 0


def _open(path: str):
    from . import store
    if path == DEFAULT_DB and not os.path.exists(path) and os.path.isdir(DEFAULT_RUNS):
        # First use of the default database: build it from the project's export, so that
        # `changes` and `report` work at once (an installed pathbench included).
        from . import export
        os.makedirs(os.path.dirname(path), exist_ok=True)
        n = export.rebuild(DEFAULT_RUNS, path)
        print(f"{PROG}: built {term(path)} from the {n} run files in {term(DEFAULT_RUNS)}", file=sys.stderr)
    return store.connect(path, create=False, readonly=True)


def _regex(pattern):
    import re
    if pattern is None:
        return None
    try:
        re.compile(pattern)
    except (re.error, RecursionError, OverflowError) as e:
        raise UsageError(f"--benchmark: not a regular expression: {e}") from None
    return pattern


def cmd_changes(a) -> int:
    from . import changes
    db = _open(a.db)
    try:
        found = changes.find(db, _regex(a.benchmark), a.machine, a.max_pvalue, a.min_change, exact=not a.otava_only)
    finally:
        db.close()
    fmt = "json" if a.json else a.format
    if fmt == "json":
        print(json.dumps(changes.as_json(found), indent=1))  # ensure_ascii: no raw control character
    elif fmt == "markdown":
        print(changes.format_markdown(found))
    else:
        print(changes.format_table(found))
    if a.fail_on_regression:
        bad = changes.newest_after_regression(found)
        for c in bad:
            p = "exact" if c.p_value is None else f"p={c.p_value:.1e}"
            print(term(f"regression: {c.benchmark} on {c.machine}: {c.change * 100:+.2f}% since {c.commit[:12]} ({p})"),
                  file=sys.stderr)
        return 1 if bad else 0
    return 0


def cmd_report(a) -> int:
    from . import report
    url = report.check_commit_url(a.commit_url)
    db = _open(a.db)
    try:
        n = report.write_site(db, a.out, commit_url=url, png=not a.no_png, repo=a.repo,
                              benchmark=_regex(a.benchmark))
    finally:
        db.close()
    _out(f"wrote {a.out}/index.html: {n} series")
    return 0


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (exit 2), like every other error here."""

    def error(self, message):
        raise UsageError(f"{message} (see `{self.prog} --help`)")


def probability(text: str) -> float:
    v = float(text)
    if not 0 < v <= 1:
        raise ValueError(text)
    return v


def fraction(text: str) -> float:
    v = float(text)
    if not 0 <= v < 1e6:
        raise ValueError(text)
    return v


def _parser() -> argparse.ArgumentParser:
    ap = _Parser(prog=PROG, description="performance history of pathbench runs",
                 epilog="exit status: 0 fine, 1 a regression found (changes --fail-on-regression), 2 bad input "
                        "or database (one line on stderr, nothing stored), 3 internal error (docs/history.md)")
    sub = ap.add_subparsers(dest="cmd", required=True, parser_class=_Parser)

    def with_db(p):
        p.add_argument("--db", default=DEFAULT_DB, help="SQLite database (default: results/history/history.sqlite in a source tree, else $XDG_DATA_HOME/pathbench/history.sqlite; changes and report build it from the project's export when missing)")
        return p

    p = with_db(sub.add_parser("record", help="store bench JSON / render reports (all or none, one transaction)"))
    p.add_argument("files", nargs="+", metavar="RUN.json")
    p.add_argument("--commit", help="git commit (default: the JSON's git_revision)")
    p.add_argument("--date", help="ISO-8601 date of the run (default: the JSON's)")
    p.add_argument("--machine", help="a name for the machine (its identity stays the fingerprint hash)")
    p.add_argument("--export", help="folder for the text export (default: runs/ beside the database; '' for none)")
    p.add_argument("--skip-recorded", action="store_true",
                   help="skip files already recorded instead of refusing them all (exit 2)")
    p.set_defaults(fn=cmd_record)

    p = with_db(sub.add_parser("rebuild", help="make the database again from the text export"))
    p.add_argument("--runs", "--export", dest="runs", default=DEFAULT_RUNS,
                   help="folder of run files (default: the project's export, results/history/runs)")
    p.set_defaults(fn=cmd_rebuild)

    from .changes import DEFAULT_MAX_PVALUE, DEFAULT_MIN_CHANGE
    p = with_db(sub.add_parser("changes", help="change points per (benchmark, machine) series (Apache Otava)"))
    p.add_argument("--benchmark", help="regular expression on benchmark names")
    p.add_argument("--machine", help="machine name or id prefix")
    p.add_argument("--format", choices=("table", "json", "markdown"), default="table")
    p.add_argument("--json", action="store_true", help="the same as --format json")
    p.add_argument("--fail-on-regression", action="store_true", help="exit 1 when a newest run sits after a regression")
    p.add_argument("--max-pvalue", type=probability, default=DEFAULT_MAX_PVALUE, help="in (0, 1]")
    p.add_argument("--min-change", type=fraction, default=DEFAULT_MIN_CHANGE,
                   help="relative, >= 0; smaller steps are merged away")
    p.add_argument("--otava-only", action="store_true",
                   help="Otava for instruction-count series too (default: their exact steps)")
    p.set_defaults(fn=cmd_changes)

    p = with_db(sub.add_parser("report", help="write the static HTML dashboard"))
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--commit-url", default="", help="http(s) link template for commits, e.g. https://host/repo/commit/{}")
    p.add_argument("--repo", default=ROOT, help="git repository for commit subjects")
    p.add_argument("--no-png", action="store_true", help="skip the matplotlib PNG copies")
    p.add_argument("--benchmark", help="regular expression: only these benchmarks")
    p.set_defaults(fn=cmd_report)

    p = sub.add_parser("backfill", help="build and measure each commit of a range", add_help=False)
    p.set_defaults(fn=None)
    p = sub.add_parser("instructions", help="the callgrind instruction-count preset as bench JSON", add_help=False)
    p.set_defaults(fn=None)
    return ap


def _dispatch(argv) -> int:
    args, rest = _parser().parse_known_args(argv)
    if args.cmd == "backfill":
        from . import backfill
        return backfill.main(rest)
    if args.cmd == "instructions":
        from . import instructions
        return instructions.main(rest)
    if rest:
        raise UsageError(f"unrecognised arguments: {' '.join(rest)}")
    for opt in ("db", "out", "runs"):  # '' would be the current folder, or for sqlite a throw-away database
        if getattr(args, opt, None) in ("", ":memory:"):
            raise UsageError(f"--{opt}: give a path")
    if args.cmd == "record":
        # The text export lives beside its database: results/history/{history.sqlite,runs/} by default.
        if args.export is None:
            args.export = os.path.join(os.path.dirname(os.path.abspath(args.db)), "runs")
        elif args.export == "":
            args.export = None
    return args.fn(args)


def _oserror(e: OSError) -> str:
    where = e.filename if e.filename is not None else "file"
    what = e.strerror or str(e)
    if e.filename2 is not None:
        where = f"{where} -> {e.filename2}"
    return f"{where}: {what}"


def _on_signal(signum, frame):
    raise Stopped(signum)


SIGNALS = (signal.SIGTERM, signal.SIGHUP, signal.SIGINT)
GRACE_S = 5.0  # how long a signalled run may take to unwind before it is ended anyway


def _watch(done) -> None:
    """Receives SIGTERM/SIGHUP/SIGINT for the main thread (which blocks them): asks the main
    thread to stop (Stopped at its next bytecode, so every finally runs), and where it does not
    finish within GRACE_S (stuck in C: a sqlite busy wait can last the whole busy timeout), removes
    what this process made (store.TEMPORARY) and ends it. A database write in progress is safe:
    sqlite's journal rolls it back."""
    import _thread
    from . import store
    while not done.is_set():
        info = signal.sigtimedwait(SIGNALS, 0.25)
        # CPython 3.11 returns a zeroed siginfo (si_signo 0), not None, when another signal
        # interrupted the wait and the timeout ran out meanwhile: no signal of ours.
        if info is not None and info.si_signo in SIGNALS:
            break
    else:
        return  # the run finished: this watcher ends with it
    signum = info.si_signo
    _thread.interrupt_main(signum)
    if not done.wait(GRACE_S):
        store.remove_temporary()
        print(f"{PROG}: stopped by signal {signum}; nothing stored", file=sys.stderr, flush=True)
        os._exit(128 + signum)


def _arm_signals():
    """Signal handling for the subcommands that write (not backfill/instructions, whose child
    processes keep the default). Returns a function that disarms it."""
    import threading
    previous = {}
    try:
        for sig in SIGNALS:
            previous[sig] = signal.signal(sig, _on_signal)
        signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
    except (ValueError, OSError, AttributeError):  # not the main thread, or no pthread_sigmask
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        return lambda: None
    done = threading.Event()
    threading.Thread(target=_watch, args=(done,), daemon=True).start()

    def disarm():
        done.set()
        for sig, handler in previous.items():  # then a signal still pending gets the default action
            signal.signal(sig, handler)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, SIGNALS)
    return disarm


def main(argv: list[str] | None = None) -> int:
    """Runs one subcommand and maps every way it can end to the exit status contract (module doc)."""
    import warnings
    from . import store
    # numpy/Otava/matplotlib RuntimeWarnings on degenerate series (a division by zero whose result
    # is filtered out) are no message for the user: stderr holds our one line or nothing.
    warnings.simplefilter("ignore", RuntimeWarning)
    for stream in (sys.stdout, sys.stderr):
        try:  # a name in a foreign script on an ASCII terminal: escaped, not UnicodeEncodeError
            stream.reconfigure(errors="backslashreplace")
        except (AttributeError, ValueError):
            pass
    db = None
    argv = sys.argv[1:] if argv is None else argv
    disarm = _arm_signals() if next((a for a in argv if not a.startswith("-")), None) in \
        ("record", "rebuild", "changes", "report") else (lambda: None)
    try:
        for i, a in enumerate(argv):  # the --db given, to name it in a database error
            if a == "--db" and i + 1 < len(argv):
                db = argv[i + 1]
            elif a.startswith("--db="):
                db = a[5:]
        return _dispatch(argv)
    except (UsageError, store.UserError) as e:
        return _err(str(e))
    except sqlite3.Error as e:
        return _err(f"{db or DEFAULT_DB}: {str(e) or type(e).__name__} (sqlite)")
    except OSError as e:
        if isinstance(e, BrokenPipeError):  # `... | head`: the reader left; nothing more to say
            try:
                os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            except OSError:
                pass
            return 0
        return _err(_oserror(e))
    except ModuleNotFoundError as e:  # otava, matplotlib: an environment without the tools' packages
        return _err(f"needs the Python package providing '{e.name}' ({sys.executable}): "
                    "pip install -r tools/requirements.txt")
    except Stopped as e:
        done = "the runs were stored before it came" if getattr(e, "stored", False) else "nothing stored"
        print(f"{PROG}: stopped by signal {e.signum}; {done}", file=sys.stderr)
        return 128 + e.signum
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted; nothing stored", file=sys.stderr)
        return 128 + signal.SIGINT
    except SystemExit:
        raise
    except BaseException as e:  # a bug: one line, status 3; the traceback on request
        if os.environ.get("PATHBENCH_DEBUG"):
            import traceback
            traceback.print_exc()
        print(f"{PROG}: internal error: {term(type(e).__name__)}: {term(str(e))[:500]}", file=sys.stderr)
        return 3
    finally:
        disarm()
