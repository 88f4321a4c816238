"""Out-of-range input through the Python module: ValueError, never an Embree abort
(issue 12; the ranges are in common/include/pathbench/common/limits.h); empty scenes,
failed conversions and impossible sizes raise, never crash (issue 34)."""
import copy
import os
import pickle
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

try:
    import pathbench
except ImportError as e:
    if os.environ.get("CI"):
        raise
    pytest.skip(f"{e} (scripts/build.sh)", allow_module_level=True)


@pytest.fixture(scope="module")
def box():
    return pathbench.load_scene("paper-cornell")


@pytest.mark.parametrize("backend", ["embree", "bvh"])
@pytest.mark.parametrize("origin, direction, message", [
    ((3e38, 0, 0), (0, 0, 1), "origins[0] = (3e+38, 0, 0) is outside the supported coordinate range"),
    ((1e20, 0, 0), (0, 0, 1), "origins[0]"),
    ((0, 0, 0), (0, 3e38, 1), "directions[0] = (0, 3e+38, 1) is outside the supported range"),
    ((0, -2e15, 0), (1, 0, 0), "origins[0]"),
])
def test_huge_rays_are_value_errors(box, backend, origin, direction, message):
    o = np.array([[0, 0, 0], origin], dtype=np.float32)[1:]
    d = np.array([direction], dtype=np.float32)
    for call in (box.intersect, box.occluded):
        with pytest.raises(ValueError, match=re.escape(message)):
            call(o, d, backend=backend)


def test_rays_at_the_limit_are_traced(box):
    r = box.intersect(np.array([[1e15, 0, 0]], np.float32), np.array([[1, 0, 0]], np.float32))
    assert not r["hit"][0]


@pytest.mark.parametrize("scale, offset", [(1e20, (0, 0, 0)), (1.0, (3e38, 0, 0)), (2.0**63, (0, 0, 0))])
def test_scene_moved_out_of_range(scale, offset):
    with pytest.raises(ValueError, match="outside the supported coordinate range"):
        pathbench.load_scene("paper-cornell", scale=scale, offset=offset)


def test_huge_emission_is_refused():
    with pytest.raises(ValueError, match="above the supported maximum 1e\\+20"):
        pathbench.load_scene("furnace:0.5,3e38")


# ---- Issue 34: the module's handles, conversions and sizes ------------------------------

def _run(code: str) -> subprocess.CompletedProcess:
    """`code` in a fresh interpreter with this module on its path: a segfault there is a
    failed test here, not a crashed test run."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(pathbench.__file__).parents[1]),
                                                       os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, env=env,
                          timeout=300)


EMPTY_SCENE_USES = {
    "render": "pathbench.render(e, 8, 8, 1)",
    "name": "e.name", "positions": "e.positions", "triangles": "e.triangles", "material_ids": "e.material_ids",
    "bounds": "e.bounds", "extent": "e.extent", "num_triangles": "e.num_triangles",
    "dropped_triangles": "e.dropped_triangles",
    "intersect": "e.intersect(np.zeros((1, 3)), np.ones((1, 3)))",
    "occluded": "e.occluded(np.zeros((1, 3)), np.ones((1, 3)), backend='bvh')",
}


def test_an_empty_scene_raises_everywhere():
    """Scene.__new__(Scene) makes a Scene without a scene: every method, property and
    render() raises ValueError (it segfaulted)."""
    code = ["import numpy as np, pathbench", "e = pathbench.Scene.__new__(pathbench.Scene)", "print(repr(e))"]
    for name, use in EMPTY_SCENE_USES.items():
        code += ["try:", f"    {use}", f"    print('{name}: no error')", "except ValueError as x:",
                 f"    print('{name}: ValueError', 'load_scene' in str(x))"]
    r = _run("\n".join(code))
    assert r.returncode == 0, r.stderr[-2000:]
    out = r.stdout.splitlines()
    assert "empty" in out[0]
    assert out[1:] == [f"{name}: ValueError True" for name in EMPTY_SCENE_USES]


def test_a_scene_copies_as_itself_and_does_not_pickle(box):
    # copy.copy went through Scene.__new__: an empty scene.
    assert copy.copy(box) is box and copy.deepcopy(box) is box
    with pytest.raises(TypeError, match="cannot be pickled"):
        pickle.dumps(box)


def test_render_wants_a_scene():
    with pytest.raises(TypeError, match="scene must be a pathbench.Scene, got int"):
        pathbench.render(5, 8, 8, 1)


def test_failed_array_conversion_raises():
    """Under a memory limit the float32 copy of the rays fails: MemoryError, never the
    failed (null) array used as if it had been made (it segfaulted)."""
    r = _run("""
        import resource
        import numpy as np
        import pathbench
        s = pathbench.load_scene("paper-cornell")
        s.intersect(np.zeros((1, 3)), np.ones((1, 3)))  # threads and Embree's scene made first
        n = 8_000_000
        o, d = np.zeros((n, 3)), np.ones((n, 3))  # float64: each float32 copy needs 96 MB
        vm = int(next(l for l in open("/proc/self/status") if l.startswith("VmSize")).split()[1]) * 1024
        resource.setrlimit(resource.RLIMIT_AS, (vm + (32 << 20), resource.RLIM_INFINITY))
        for call in (s.intersect, s.occluded):
            try:
                call(o, d)
                print("no error")
            except MemoryError:
                print("MemoryError")
        """)
    assert r.returncode == 0, f"exit {r.returncode}: {r.stderr[-2000:]}"
    assert r.stdout.split() == ["MemoryError", "MemoryError"]


class _BadIndex:
    def __index__(self):
        raise RuntimeError("no index here")


def test_an_index_that_raises_is_raised(box):
    # Its exception went unnoticed: a null int was read ("width = <NULL> is out of range").
    for kw in ({"seed": _BadIndex()}, {"threads": _BadIndex()}):
        with pytest.raises(RuntimeError, match="no index here"):
            pathbench.render(box, 8, 8, 1, **kw)
    with pytest.raises(RuntimeError, match="no index here"):
        pathbench.render(box, _BadIndex(), 8, 1)


@pytest.mark.parametrize("size, kw, message", [
    ((2**31, 1, 1), {}, "width/height: 2147483648x1 is 2147483648 pixels, more than the supported 268435456"),
    ((65536, 65536, 1), {}, "more than the supported 268435456"),
    ((2**32 - 1, 2**32 - 1, 1), {}, "more than the supported 268435456"),
    ((4096, 4096, 2**32 - 1), {}, "spp: 4096x4096 pixels at 4294967295 spp"),
    ((8, 8, 1), {"paths_in_flight": 2**64 - 1, "strategy": "wavefront"},
     "paths_in_flight: 18446744073709551615 is more than the supported 4294967295"),
])
def test_impossible_sizes_are_value_errors(box, size, kw, message):
    # 2^31 x 1 passed the old check and died in the film's allocation: MemoryError.
    with pytest.raises(ValueError, match=re.escape(message)):
        pathbench.render(box, *size, **kw)


def test_scene_names_that_are_not_utf8(tmp_path):
    """A scene file whose name is not UTF-8: its name (and the report's) keeps the bytes
    as surrogate escapes instead of raising UnicodeDecodeError."""
    src = Path(__file__).resolve().parents[2] / "scenes" / "paper-cornell.json"
    odd = tmp_path / os.fsdecode(b"odd-\xff\x1b[31m.json")
    odd.write_bytes(src.read_bytes())
    s = pathbench.load_scene(str(odd))
    assert "\udcff" in s.name and "\\x1b" in repr(s)
    _, report = pathbench.render(s, 4, 4, 1)
    assert report["scene"] == s.name
