"""Threads making their first calls into `pathbench` at once must not deadlock.

Built with Debian's pybind11 2.10.3 the module hung in about half of all fresh
interpreters where 8 threads called in at once (one thread held the GIL waiting on the
static guard of numpy's C API table while the thread initialising it, inside
`import numpy.core.multiarray`, waited for the GIL). Only a fresh interpreter shows it,
so each run is a subprocess with a timeout (threads_first_calls.py)."""
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

pathbench = pytest.importorskip("pathbench") if not os.environ.get("CI") else __import__("pathbench")

SCRIPT = Path(__file__).with_name("threads_first_calls.py")
RUNS = 12        # fresh interpreters; before the fix about half of them hung
AT_ONCE = 3      # interpreters running at the same time (more at once on 2 cores hides the race)
TIMEOUT_S = 60   # one run takes ~1-2 s on a loaded 2-core machine


def test_first_calls_from_many_threads_do_not_deadlock():
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(Path(pathbench.__file__).parents[1])] + os.environ.get("PYTHONPATH", "").split(os.pathsep)))
    hung, failed = 0, []
    pending = list(range(RUNS))
    while pending:
        batch, pending = pending[:AT_ONCE], pending[AT_ONCE:]
        procs = [(k, subprocess.Popen([sys.executable, str(SCRIPT), str(8 + 8 * (k % 2))], env=env,
                                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))
                 for k in batch]
        deadline = time.monotonic() + TIMEOUT_S
        for k, p in procs:
            try:
                out, err = p.communicate(timeout=max(1.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                p.kill()
                p.communicate()
                hung += 1
                continue
            if p.returncode != 0 or out.strip() != "ok":
                failed.append(f"run {k}: exit {p.returncode}: {err.strip()[-500:]}")
    assert hung == 0, f"{hung} of {RUNS} fresh interpreters hung (deadlock) with 8-16 threads calling in at once"
    assert not failed, "\n".join(failed)
