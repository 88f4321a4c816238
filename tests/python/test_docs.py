"""The front door stays true: README and docs/ code blocks run (long ones with small sizes, or
checked against the binary's --help), the generated CLI reference and results table are
current, `pathbench reproduce` leaves a clean checkout clean, and an installed pathbench runs
its Python subcommands without the source tree."""
from __future__ import annotations

import functools
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = ROOT / "build" / "bin"
PATHBENCH = BIN / "pathbench"
PAGES = ["README.md", "docs/user-guide.md", "docs/reference.md", "docs/design.md", "docs/python.md"]
needs_binary = pytest.mark.skipif(not PATHBENCH.exists(), reason="build/bin/pathbench not built")
# Subcommands built by other work that a binary of this branch may not have yet.
MAYBE_ABSENT = {"suite"}
# Run in full (they take seconds here); every other command is checked against --help.
RUN = {"render", "compare", "history", "accuracy", "crosscheck"}
# What each prints, as the README's one line says.
PRINTS = {"render": r"M rays/s", "compare": r"verdict", "history record": r"recorded .* rows",
          "accuracy": r"rows written", "crosscheck": r"crosscheck: .* against Mitsuba 3"}


def blocks(page: str) -> list[tuple[str, str]]:
    text = (ROOT / page).read_text()
    return [(m.group(1), m.group(2)) for m in re.finditer(r"^```(\w*)\n(.*?)^```", text, flags=re.M | re.S)]


def shell_commands() -> list[tuple[str, str]]:
    out = []
    for page in PAGES:
        for lang, body in blocks(page):
            if lang not in ("sh", "bash"):
                continue
            for line in body.replace("\\\n", " ").splitlines():
                line = re.sub(r"\s+#.*$", "", line).strip()
                if line and not line.startswith("#"):
                    out.append((page, line))
    return out


@functools.lru_cache(maxsize=None)
def _helptext(args: tuple[str, ...]) -> str | None:
    p = subprocess.run([str(PATHBENCH), *args, "--help"], capture_output=True, text=True, timeout=60)
    return p.stdout if p.returncode == 0 else None


def helptext(args: list[str]) -> str | None:
    return _helptext(tuple(args))


def pathbench_words(line: str) -> list[str] | None:
    """The pathbench command in a line (after mpirun's own options), or None."""
    words = shlex.split(line.split("&&")[0])
    for i, w in enumerate(words):
        if w.endswith("bin/pathbench") or w == "pathbench":
            return words[i + 1:]
    return None


def test_readme_is_a_front_door():
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= 250
    assert "pathbench compare base.json new.json" in text
    for page in ("docs/user-guide.md", "docs/reference.md", "docs/design.md", "docs/python.md"):
        assert page in text and (ROOT / page).exists()


def test_results_glance_is_current():
    p = subprocess.run([sys.executable, str(ROOT / "scripts/results_glance.py"), "--check", str(ROOT / "README.md")],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr


@needs_binary
def test_cli_reference_is_current():
    p = subprocess.run([sys.executable, str(ROOT / "scripts/gen_cli_reference.py"), "--check",
                        str(ROOT / "docs/reference.md")], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr


def test_referenced_scripts_and_tools_exist():
    for page, line in shell_commands():
        for w in shlex.split(line.replace("&&", " ")):
            if re.match(r"^(scripts|tools|gpu)/[\w./-]+\.(sh|py)$", w):
                assert (ROOT / w).exists(), f"{page}: {line}: {w} does not exist"


@needs_binary
def test_commands_match_the_binary():
    """Every pathbench command shown names a subcommand and options the binary has."""
    top = helptext([])
    for page, line in shell_commands():
        words = pathbench_words(line)
        if not words or words[0].startswith("-"):
            continue
        sub = words[0]
        if not re.search(rf"^\s+{re.escape(sub)}\s", top, flags=re.M):
            assert sub in MAYBE_ABSENT, f"{page}: {line}: no subcommand {sub}"
            continue
        args = [sub] + ([words[1]] if sub == "history" and len(words) > 1 and not words[1].startswith("-") else [])
        text = helptext(args)
        assert text is not None, f"{page}: {line}: `pathbench {' '.join(args)} --help` failed"
        for w in words:
            opt = w.split("=")[0]
            if re.match(r"^--[a-z][a-z0-9-]*$", opt):
                assert opt in text, f"{page}: {line}: {opt} is not an option of pathbench {' '.join(args)}"


def run_line(words: list[str], cwd: Path, tmp: Path) -> subprocess.CompletedProcess:
    sub = words[0]
    if sub == "compare":  # base.json / new.json come from `bench` lines: use the fixtures
        fixtures = {"base.json": "tests/data/bench/base.json", "new.json": "tests/data/bench/identical.json"}
        words = [str(ROOT / fixtures[w]) if w in fixtures else w for w in words]
    if sub == "history":
        db = str(tmp / "history.sqlite")
        if not (tmp / "history.sqlite").exists():
            subprocess.run([str(PATHBENCH), "history", "rebuild", "--db", db, "--export",
                            str(ROOT / "results/history/runs")], check=True, capture_output=True)
        if words[1] == "record":
            words = words[:2] + [str(ROOT / "tests/data/bench/base.json"), "--commit", "0" * 40,
                                 "--date", "2026-01-01T00:00:00+00:00", "--export", ""]
        words = words + ["--db", db] + (["--export", str(ROOT / "results/history/runs")] if words[1] == "rebuild" else [])
    return subprocess.run([str(PATHBENCH), *words], cwd=cwd, capture_output=True, text=True, timeout=240)


@needs_binary
def test_commands_run(tmp_path):
    """The fast commands shown run as written (from a scratch folder); what they print is checked."""
    (tmp_path / "scenes").symlink_to(ROOT / "scenes")
    ran = 0
    for page, line in shell_commands():
        words = pathbench_words(line)
        if not words or words[0] not in RUN or line.startswith("mpirun") or re.search(r"[\[|]|\.\.\.|[A-Z]{3,}", line):
            continue  # a synopsis (brackets, alternatives, placeholders) or MPI: checked against --help only
        if words[0] == "accuracy" and "--quick" not in words:
            continue  # a full sweep takes minutes
        if words[0] == "history" and words[1] not in ("record", "rebuild", "changes", "report"):
            continue  # instructions and backfill build and measure: minutes
        if words[0] == "crosscheck":
            try:
                import mitsuba  # noqa: F401
            except ImportError:
                continue
        p = run_line(words, tmp_path, tmp_path)
        allowed = {0, 1} if words[0] in ("compare", "crosscheck") else {0}
        assert p.returncode in allowed, f"{page}: {line}: exit {p.returncode}\n{p.stderr[-2000:]}"
        expect = PRINTS.get(words[0] if words[0] != "history" else f"history {words[1]}")
        if expect:
            assert re.search(expect, p.stdout + p.stderr), f"{page}: {line}: printed no {expect!r}:\n{p.stdout[-1000:]}"
        ran += 1
    assert ran >= 8


@needs_binary
def test_python_blocks_run(tmp_path):
    build_python = ROOT / "build" / "python"
    if not list(build_python.glob("pathbench/_core*.so")):
        pytest.skip("the Python module is not built")
    env = dict(os.environ, PYTHONPATH=str(build_python))
    for page in ("README.md", "docs/python.md"):
        for lang, body in blocks(page):
            if lang != "python":
                continue
            p = subprocess.run([sys.executable, "-c", body], cwd=tmp_path, env=env, capture_output=True, text=True,
                               timeout=240)
            assert p.returncode == 0, f"{page}: python block failed:\n{p.stderr[-2000:]}"


def git(*args, cwd):
    return subprocess.run(["git", *args], cwd=cwd, capture_output=True, text=True, check=True).stdout


@needs_binary
def test_reproduce_leaves_a_clean_checkout_clean(tmp_path):
    clone = tmp_path / "clone"
    git("clone", "--quiet", "--no-hardlinks", str(ROOT), str(clone), cwd=tmp_path)
    assert git("status", "--porcelain", cwd=clone) == ""
    p = subprocess.run([str(PATHBENCH), "reproduce", "--device", "cpu", "--spp", "16", "--budget", "0", "--quiet"],
                       cwd=clone, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    written = list((clone / "pathbench-out").rglob("paper-cornell.md"))
    assert written, "reproduce wrote no table under pathbench-out/"
    assert git("status", "--porcelain", cwd=clone) == ""


@needs_binary
def test_installed_pathbench_stands_alone(tmp_path):
    """cmake --install, then the install copied elsewhere and run from /: history, accuracy and
    crosscheck find their Python tools beside the executable, not in the source tree."""
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", str(ROOT / "build"), "--prefix", str(prefix)], check=True,
                   capture_output=True)
    moved = tmp_path / "elsewhere"
    shutil.copytree(prefix, moved, symlinks=True)
    shutil.rmtree(prefix)
    exe = moved / "bin" / "pathbench"
    assert (moved / "share/pathbench/tools/history/__main__.py").exists()
    assert (moved / "bin/pathbench-bench").exists()
    if list((ROOT / "build" / "python").glob("pathbench/_core*.so")):  # a build with the module
        assert list((moved / "lib").rglob("pathbench/_core*.so"))
        assert (moved / "lib" / "pathbench" / "python" / "pathbench" / "__init__.py").exists()
    # The interpreter with the tools' dependencies; the tools themselves from the install only.
    env = dict(os.environ, PATHBENCH_PYTHON=sys.executable, PATHBENCH_TOOLS_DIR="")
    env.pop("PYTHONPATH", None)

    # The source tree's tools/ hidden (a private mount namespace, where the system allows one), so
    # that a launcher falling back to the source tree would fail here.
    hide = ["unshare", "-m", "--propagation", "private", "sh", "-c",
            f"mount -t tmpfs none {shlex.quote(str(ROOT / 'tools'))} && exec \"$@\"", "-"]
    if not shutil.which("unshare") or subprocess.run(hide + ["true"], capture_output=True).returncode != 0:
        hide = []

    def run(*args):
        return subprocess.run([*hide, str(exe), *args], cwd="/", env=env, capture_output=True, text=True, timeout=300)

    db = tmp_path / "h.sqlite"
    p = run("history", "rebuild", "--db", str(db), "--export", str(ROOT / "results/history/runs"))
    assert p.returncode == 0, p.stderr
    p = run("history", "report", "--db", str(db), "--out", str(tmp_path / "d"))
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "d" / "index.html").exists()
    # No --db at all: the per-user database, built on first use from the installed export.
    env["XDG_DATA_HOME"] = str(tmp_path / "xdg")
    p = run("history", "report", "--out", str(tmp_path / "d2"))
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "d2" / "index.html").exists() and (tmp_path / "xdg/pathbench/history.sqlite").exists()
    assert "share/pathbench/results/history/runs" in p.stderr
    p = run("accuracy", "--quick", "--out-dir", str(tmp_path / "acc"))
    assert p.returncode == 0, p.stderr
    # A Python without Mitsuba (or none at all): one clear line, exit 2.
    env["PATHBENCH_PYTHON"] = shutil.which("python3") if not _has_mitsuba("python3") else "/nonexistent/python3"
    p = run("crosscheck", "cornell-box", "--spp", "1", "--width", "8", "--height", "8", "--out-dir", str(tmp_path / "cc"))
    assert p.returncode == 2, p.stderr
    assert re.search(r"pathbench: error: crosscheck: .*(lacks .*mitsuba|cannot run Python)", p.stderr), p.stderr
    assert "Traceback" not in p.stderr


def _has_mitsuba(python: str) -> bool:
    exe = shutil.which(python)
    return exe is None or subprocess.run([exe, "-c", "import mitsuba"], capture_output=True).returncode == 0


# Pages other work adds (linked from here before they land).
OTHERS_PAGES = {"docs/suite.md", "docs/suite-workloads.md", "docs/mpi.md", "docs/history.md"}


def test_relative_links_resolve():
    pages = PAGES + ["results/README.md", "docs/notes/cpu-log.md", "docs/notes/gpu-log.md"]
    for page in pages:
        text = re.sub(r"^```.*?^```", "", (ROOT / page).read_text(), flags=re.M | re.S)
        for target in re.findall(r"\]\(([^)\s]+)\)", text):
            if re.match(r"^(https?:|mailto:|#)", target):
                continue
            path = (ROOT / page).parent / target.split("#")[0]
            rel = os.path.relpath(path.resolve(), ROOT)
            assert path.exists() or rel in OTHERS_PAGES, f"{page}: broken link {target}"


def test_a_stale_generated_block_is_caught(tmp_path):
    readme = tmp_path / "README.md"
    readme.write_text((ROOT / "README.md").read_text().replace(" ms |", " ms  |", 1))
    p = subprocess.run([sys.executable, str(ROOT / "scripts/results_glance.py"), "--check", str(readme)],
                       capture_output=True, text=True)
    assert p.returncode == 1 and "stale" in p.stderr
    p = subprocess.run([sys.executable, str(ROOT / "scripts/results_glance.py"), "--write", str(readme)])
    assert p.returncode == 0 and readme.read_text() == (ROOT / "README.md").read_text()
