"""`pathbench history backfill REV-RANGE`: build each commit of a range in a scratch clone and record
the instruction-count preset (tools/history/instructions.py, carried from *this* tree, since older
commits lack it) into the history.

Builds are incremental (one build folder reused commit after commit, oldest first, ccache, CUDA off,
only the `pathbench` target). A commit that does not build or measure is recorded as failed in the
log and the backfill goes on. When a commit leaves bin/pathbench byte-identical to the previous
commit's (results-only commits), callgrind would count the same instructions, so the previous
measurement is re-used for it and marked so in the run's context (`measured_at`).
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def _git(repo: str, *args: str) -> str:
    return subprocess.run(["git", "-C", repo, *args], check=True, capture_output=True, text=True).stdout.strip()


def _sha256(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _log(log, msg: str) -> None:
    print(msg, flush=True)
    if log:
        log.write(msg + "\n")
        log.flush()


def build(scratch: str, build_dir: str, log) -> bool:
    env = os.environ | {"CCACHE_BASEDIR": scratch, "CCACHE_DIR": os.environ.get("CCACHE_DIR", "/root/.ccache")}
    launcher = ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"] if shutil.which("ccache") else []
    # Configured once: configuring again would stamp the new revision into the binary and rebuild
    # and re-measure results-only commits; ninja still re-runs CMake itself when a CMakeLists changes.
    steps = [] if os.path.exists(os.path.join(build_dir, "build.ninja")) else [
        ["cmake", "-S", scratch, "-B", build_dir, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release", "-DPATHBENCH_CUDA=OFF",
         *launcher]]
    steps.append(["cmake", "--build", build_dir, "--target", "pathbench", "-j", str(os.environ.get("BACKFILL_JOBS", 2))])
    for cmd in steps:
        r = subprocess.run(["nice", "-n", "10", *cmd], capture_output=True, text=True, env=env)
        if r.returncode != 0:
            _log(log, f"  build failed: {' '.join(cmd[:3])}: {(r.stdout + r.stderr)[-800:]}")
            return False
    return True


def run(repo: str, rev_range: str, scratch: str, json_dir: str, db: str | None, wall: int,
        machine: str | None, log_path: str | None, export_dir: str | None = None) -> int:
    if not rev_range or rev_range.startswith("-") or any(c.isspace() or ord(c) < 32 for c in rev_range):
        print(f"pathbench history backfill: error: {rev_range[:80]!r}: not a revision range", file=sys.stderr)
        return 2
    try:
        revs = _git(repo, "rev-list", "--reverse", "--first-parent", "--end-of-options", rev_range).split()
    except subprocess.CalledProcessError as e:
        detail = " ".join(e.stderr.split())[:200]
        print(f"pathbench history backfill: error: {rev_range[:80]!r}: not a revision range in {repo}: {detail}",
              file=sys.stderr)
        return 2
    if not revs:
        print(f"pathbench history backfill: error: {rev_range[:80]!r}: no commits in this range", file=sys.stderr)
        return 2
    os.makedirs(json_dir, exist_ok=True)
    if not os.path.isdir(os.path.join(scratch, ".git")):
        subprocess.run(["git", "clone", "--quiet", "--shared", "--no-checkout", repo, scratch], check=True)
    # The measuring script comes from this tree, copied once, so every commit is measured alike.
    tool = os.path.join(scratch, ".backfill-instructions.py")
    shutil.copy(os.path.join(HERE, "instructions.py"), tool)
    build_dir = os.path.join(scratch, "build")
    log = open(log_path, "a") if log_path else None
    prev_hash, prev_json, failed = None, None, 0
    for i, rev in enumerate(revs, 1):
        short = rev[:12]
        out = os.path.join(json_dir, f"{i:03d}-{short}.json")
        subject = _git(repo, "log", "-1", "--format=%s", rev)[:70]
        if os.path.exists(out):
            _log(log, f"[{i}/{len(revs)}] {short} already measured")
            prev_json = out
            continue
        _log(log, f"[{i}/{len(revs)}] {short} {subject}")
        subprocess.run(["git", "-C", scratch, "fetch", "--quiet", repo, rev], check=False)
        subprocess.run(["git", "-C", scratch, "checkout", "--quiet", "--force", rev], check=True)
        if not build(scratch, build_dir, log):
            failed += 1
            with open(os.path.join(json_dir, f"{i:03d}-{short}.failed"), "w") as f:
                f.write("build failed\n")
            continue
        exe = os.path.join(build_dir, "bin", "pathbench")
        h = _sha256(exe)
        date = _git(repo, "log", "-1", "--format=%cI", rev)
        if h == prev_hash and prev_json:
            with open(prev_json) as f:
                data = json.load(f)
            data["context"]["measured_at"] = data["context"].get("measured_at") or data["context"]["git_revision"]
            _log(log, f"  binary unchanged: re-using the measurement of {data['context']['measured_at'][:12]}")
        else:
            r = subprocess.run([sys.executable, tool, "--build-dir", build_dir, "--out", out + ".raw",
                                "--wall", str(wall), "--revision", rev], capture_output=True, text=True)
            if r.returncode != 0:
                _log(log, f"  measuring failed: {r.stderr[-800:]}")
                failed += 1
                continue
            with open(out + ".raw") as f:
                data = json.load(f)
            os.remove(out + ".raw")
        data["context"].update({"git_revision": rev, "commit_date": date, "binary_sha256": h,
                                "commit_seq": int(_git(repo, "rev-list", "--count", rev)),
                                "backfill": True, "commit_subject": subject})
        with open(out, "w") as f:
            json.dump(data, f, indent=1, allow_nan=False)
        prev_hash, prev_json = h, out
        if db:
            from . import importer  # recorded as it goes, so a cut-short backfill still leaves a history
            try:
                importer.record_file(db, out, commit=rev, machine=machine, export_dir=export_dir)
            except importer.RecordError as e:
                _log(log, f"  not recorded: {e}")
        _log(log, f"  done: {out}")
    if log:
        log.close()
    print(f"backfill: {len(revs) - failed} of {len(revs)} commits measured, {failed} failed")
    return 0


def import_git(repo: str, paths: list[str], db: str, export_dir: str | None, machine: str | None) -> int:
    """Records every committed version of bench JSON files (results/ is overwritten run after run,
    but git kept each version): oldest first; a version already recorded is skipped."""
    import tempfile

    from . import importer
    n = 0
    with tempfile.TemporaryDirectory() as tmp:
        for path in paths:
            rel = os.path.relpath(os.path.abspath(path), repo)
            for sha in reversed(_git(repo, "log", "--format=%H", "--", rel).split()):
                body = subprocess.run(["git", "-C", repo, "show", f"{sha}:{rel}"], capture_output=True).stdout
                out = os.path.join(tmp, os.path.basename(rel))
                with open(out, "wb") as f:
                    f.write(body)
                try:
                    run = importer.record_file(db, out, machine=machine, export_dir=export_dir)
                except importer.RecordError as e:
                    print(f"{rel}@{sha[:12]}: skipped: {e}")
                    continue
                n += 1
                print(f"{rel}@{sha[:12]}: recorded (measured at {run['commit'][:12]}, {len(run['results'])} rows)")
    return n


def main(argv: list[str] | None = None) -> int:
    from .cli import _Parser  # usage errors as one line, exit 2
    ap = _Parser(prog="pathbench history backfill", description=__doc__.split("\n\n")[0])
    ap.add_argument("range", nargs="?", help="git revision range, e.g. HEAD~45..HEAD")
    ap.add_argument("--git-results", nargs="+", metavar="JSON",
                    help="instead of building: record every committed version of these bench JSON files (needs --db)")
    ap.add_argument("--repo", default=".", help="git repository to take the commits from")
    ap.add_argument("--scratch", default="/tmp/pathbench-backfill", help="scratch clone (kept for incremental builds)")
    ap.add_argument("--json-dir", default="/tmp/pathbench-backfill-json", help="where each commit's JSON goes")
    ap.add_argument("--db", help="history database to record into (default: none, JSON only)")
    ap.add_argument("--machine", help="machine name to record under")
    ap.add_argument("--wall", type=int, default=3, help="native timed renders per series (0: none)")
    ap.add_argument("--export", help="text export folder for recorded runs (with --db)")
    ap.add_argument("--log", help="append progress here too")
    a = ap.parse_args(argv)
    if a.git_results:
        if not a.db:
            print("pathbench history backfill: error: --git-results needs --db", file=sys.stderr)
            return 2
        try:
            import_git(os.path.abspath(a.repo), a.git_results, a.db, a.export, a.machine)
        except subprocess.CalledProcessError as e:  # not a repository, a path outside it
            from .store import UserError
            detail = " ".join((e.stderr or "").split())[:200] if isinstance(e.stderr, str) else ""
            raise UserError(f"{a.repo}: git {' '.join(e.cmd[3:5])} failed: {detail}") from None
        return 0
    if not a.range:
        print("pathbench history backfill: error: give a revision range (or --git-results)", file=sys.stderr)
        return 2
    return run(os.path.abspath(a.repo), a.range, os.path.abspath(a.scratch), os.path.abspath(a.json_dir),
               a.db, a.wall, a.machine, a.log, a.export)


if __name__ == "__main__":
    sys.exit(main())
