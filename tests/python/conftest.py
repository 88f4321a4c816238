# Lets the tests import the Python tools (tools/*.py) as modules, and the project's
# own Python module (`pathbench`, built into build/python/ by scripts/build.sh;
# PATHBENCH_PYTHON_DIR points elsewhere).
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, os.environ.get("PATHBENCH_PYTHON_DIR", str(ROOT / "build" / "python")))


def pytest_configure(config):
    config.addinivalue_line("markers", "oracle_large: the intersection oracle's larger sweep "
                                       "(PATHBENCH_ORACLE_LARGE=1)")
    config.addinivalue_line("markers", "slow: minutes, e.g. `pip install .` with a full build (PATHBENCH_SLOW=1)")
