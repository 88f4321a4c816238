"""`pathbench suite`'s options: the argument parser and the checks of what it was given
(the repetitions, the crosscheck's frame, the binaries, --out, --db). Bad input is an
InputError: one line on stderr, exit 2 (cli.main)."""
from __future__ import annotations

import argparse
import os
import re
import subprocess

from . import crosscheck

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# cli.py's docstring's first paragraph: --help's description.
DESCRIPTION = ("`pathbench suite`: every workload of the manifest on every device present, with enough\n"
               "repetitions for compare's U test; a progress bar and a table; bench JSON; records into the\n"
               "history database; one page (HTML + Markdown).")
REPETITIONS = 9  # `pathbench compare` refuses fewer (its U test)


class InputError(ValueError):
    pass


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2 (the project's contract)
        raise InputError(message)


def _data_home() -> str:
    return os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local", "share")


def default_db() -> str:
    return os.path.join(_data_home(), "pathbench", "history.sqlite")


def parse_args(argv):
    ap = _Parser(prog="pathbench suite", description=DESCRIPTION)
    ap.add_argument("--quick", action="store_true", help="small frames (minutes on 2 cores): CI and smoke tests")
    ap.add_argument("--workloads", metavar="REGEX", help="only the workloads whose name matches")
    ap.add_argument("--devices", metavar="LIST", help="cpu, gpu or cpu,gpu (default: every device present)")
    ap.add_argument("--isa", choices=["auto", "avx512", "avx2", "scalar"], help="pin the CPU tracer's instruction set "
                    "(default auto: the widest the CPU has)")
    ap.add_argument("--repetitions", type=int, default=REPETITIONS, help="per workload and device (default 9, the "
                    "fewest compare's U test takes)")
    ap.add_argument("--repetitions-for", action="append", default=[], metavar="REGEX=N",
                    help="N repetitions for the workloads whose name matches REGEX (repeatable; the first match "
                    "wins): fewer for slow full frames on a CPU; the page shows each row's count")
    ap.add_argument("--crosscheck", action="store_true", help="no measurement: each workload against Mitsuba 3 on "
                    "each device (pathbench crosscheck: per-pixel z-test), written as crosscheck.json and .md")
    ap.add_argument("--mitsuba-variant", default="scalar_rgb", help="--crosscheck: Mitsuba's variant (scalar_rgb; "
                    "cuda_ad_rgb or llvm_ad_rgb where installed)")
    ap.add_argument("--crosscheck-size", default="32x32", metavar="WxH", help="--crosscheck: the frame (default "
                    "32x32; a Mitsuba XML scene renders at its film's size)")
    ap.add_argument("--crosscheck-spp", type=int, default=64, help="--crosscheck: pathbench's samples per pixel "
                    "(Mitsuba renders 4x)")
    ap.add_argument("--min-time", type=float, help="seconds of frames per repetition (default: 1 on GPUs, for "
                    "NVML's energy windows; 0.1 quick / 0.5 full on CPUs)")
    ap.add_argument("--manifest", default=os.path.join(ROOT, "scenes", "suite", "manifest.json"))
    ap.add_argument("--db", default=None, help=f"history database (default {default_db()})")
    ap.add_argument("--no-record", action="store_true", help="do not record into the history database")
    ap.add_argument("--export", help="also write the history's text export here (results/history/runs for the "
                    "project's reference machines)")
    ap.add_argument("--machine", help="a name for this machine in the history and on pages")
    ap.add_argument("--references", default=os.path.join(ROOT, "results", "history", "runs"),
                    help="the reference machines' records (the history's text export)")
    ap.add_argument("--out", help="folder for the page and the JSON (default: "
                    "$XDG_DATA_HOME/pathbench/suite/<date>-<mode>)")
    ap.add_argument("--list", action="store_true", help="list the workloads and exit")
    ap.add_argument("--from-json", nargs="+", metavar="BENCH.json", help="no measurement: the page and the records "
                    "from the suite's bench JSON written earlier (a run cut short, another host); --quick if it was one")
    a = ap.parse_args(argv)
    if a.repetitions < 1:
        raise InputError("--repetitions: must be at least 1 (9 for compare's U test)")
    if a.min_time is not None and not (0 < a.min_time <= 3600):
        raise InputError("--min-time: must be in (0, 3600] seconds")
    a.repetitions_by = _repetitions_for(a.repetitions_for)
    try:
        a.crosscheck_frame = crosscheck.parse_size(a.crosscheck_size)
        crosscheck.check_variant(a.mitsuba_variant)
    except ValueError as e:
        raise InputError(str(e)) from None
    if not 1 <= a.crosscheck_spp <= 1 << 20:
        raise InputError(f"--crosscheck-spp {a.crosscheck_spp}: must be 1 to {1 << 20}")
    if a.crosscheck and (a.from_json or a.list):
        raise InputError("--crosscheck: measures nothing itself; not with --from-json or --list")
    return a


def _repetitions_for(specs: list[str]) -> list[tuple]:
    """--repetitions-for REGEX=N -> [(compiled REGEX, N)]; InputError naming the bad one."""
    out = []
    for spec in specs:
        rx, sep, n = spec.rpartition("=")
        if not sep or not rx or not n.isdigit() or not 1 <= int(n) <= 1000:
            raise InputError(f"--repetitions-for {spec!r}: expected REGEX=N with N from 1 to 1000")
        try:
            out.append((re.compile(rx), int(n)))
        except re.error as e:
            raise InputError(f"--repetitions-for {spec!r}: not a regular expression: {e}") from None
    return out


def repetitions_of(a, workload: str) -> int:
    """The workload's repetitions: the first --repetitions-for that matches, else --repetitions."""
    return next((n for rx, n in a.repetitions_by if rx.search(workload)), a.repetitions)


def _exe() -> str:
    exe = os.environ.get("PATHBENCH_EXE") or os.path.join(ROOT, "build", "bin", "pathbench")
    if not os.access(exe, os.X_OK):
        raise InputError(f"{exe}: no pathbench binary (build it, or run `pathbench suite` from the build)")
    bench = os.path.join(os.path.dirname(exe), "pathbench-bench")
    if not os.access(bench, os.X_OK):
        raise InputError(f"{bench}: not found (build the target pathbench-bench; it needs Google Benchmark)")
    return exe


def _check_out(out: str) -> None:
    if os.path.exists(out) and not os.path.isdir(out):
        raise InputError(f"--out {out}: exists and is not a folder")
    if os.path.isdir(out) and any(not n.startswith(".") for n in os.listdir(out)):
        if not os.path.exists(os.path.join(out, "suite.json")):
            raise InputError(f"--out {out}: a folder with other files in it (give an empty or new folder)")


def _check_db(db: str) -> None:
    if os.path.isdir(db):
        raise InputError(f"--db {db}: is a folder")
    real = os.path.realpath(db)
    if real.startswith(ROOT + os.sep) and os.path.exists(os.path.join(ROOT, ".git")):
        r = subprocess.run(["git", "-C", ROOT, "ls-files", "--error-unmatch", real], capture_output=True)
        if r.returncode == 0:
            raise InputError(f"--db {db}: a file tracked by git; the history database is never committed")
