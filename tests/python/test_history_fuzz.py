"""The history fuzz target (tests/fuzz/python/fuzz_history.py) replays its seeds and every input
it ever found (tests/fuzz/regressions/history), and its mutation loop runs briefly without a
finding; scripts/fuzz.sh history runs it under atheris."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TARGET = ROOT / "tests" / "fuzz" / "python" / "fuzz_history.py"


def test_fuzz_target_replays_seeds_and_regressions_without_a_finding():
    dirs = [d for d in (ROOT / "tests/fuzz/corpus/history", ROOT / "tests/fuzz/regressions/history")
            if d.is_dir() and any(d.iterdir())]
    r = subprocess.run([sys.executable, TARGET, "--replay", *dirs], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and "no finding" in r.stdout, r.stdout + r.stderr


def test_fuzz_mutation_loop_runs_without_a_finding():
    r = subprocess.run([sys.executable, TARGET, "--mutate", "5", ROOT / "tests/fuzz/corpus/history"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and "no finding" in r.stdout, r.stdout + r.stderr
    assert int(r.stdout.split("mutate: ")[1].split()[0]) > 100
