"""The `pathbench` package: its type stubs match the built module, and (slow, once in CI)
`pip install .` builds it from the repository and it imports in a fresh venv."""
import ast
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

try:
    import pathbench
except ImportError as e:
    if os.environ.get("CI"):
        raise
    pytest.skip(f"{e} (scripts/build.sh)", allow_module_level=True)

ROOT = Path(__file__).resolve().parents[2]
STUB = ROOT / "python" / "pathbench" / "__init__.pyi"


def _params(fn: ast.FunctionDef) -> list[tuple[str, str, object]]:
    """(name, 'pos' | 'kw', default) per parameter; default is None when there is none, ... when elided."""
    a = fn.args
    pos = a.posonlyargs + a.args
    defaults = [None] * (len(pos) - len(a.defaults)) + list(a.defaults)
    out = [(p.arg, "pos", d) for p, d in zip(pos, defaults)]
    out += [(p.arg, "kw", d) for p, d in zip(a.kwonlyargs, a.kw_defaults)]

    def value(d):
        if d is None:
            return None
        if isinstance(d, ast.Constant) and d.value is Ellipsis:
            return ...
        src = ast.unparse(d)
        return float(src) if src == "inf" else ast.literal_eval(src)
    return [(n, k, value(d)) for n, k, d in out]


def _runtime_signature(obj) -> ast.FunctionDef:
    # pybind11 writes each function's signature as the first line of its docstring.
    return ast.parse("def " + obj.__doc__.splitlines()[0] + ": pass").body[0]


def _stub():
    tree = ast.parse(STUB.read_text())
    funcs = {}  # name -> the last definition (overloads share their parameters here)
    classes = {}
    names = set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            funcs.setdefault(node.name, []).append(node)
        elif isinstance(node, ast.ClassDef):
            classes[node.name] = {n.name: n for n in node.body if isinstance(n, ast.FunctionDef)}
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
    return funcs, classes, names


def _same(stub_fn: ast.FunctionDef, runtime, skip_self=False):
    want = _params(_runtime_signature(runtime))
    got = _params(stub_fn)
    if skip_self:
        want, got = want[1:], got[1:]
    assert [(n, k) for n, k, _ in got] == [(n, k) for n, k, _ in want], stub_fn.name
    for (n, _, g), (_, _, w) in zip(got, want):
        if isinstance(g, (list, tuple)) and isinstance(w, (list, tuple)):
            g, w = tuple(g), tuple(w)  # a stub writes a sequence default as a tuple
        if g is not ...:
            # overloads of render differ only in variance's Literal default; its value is checked on one
            assert g == w or (n == "variance" and g is None), f"{stub_fn.name}({n}=): stub {g!r}, module {w!r}"


def test_stub_names_every_public_function_argument_and_default():
    funcs, classes, names = _stub()
    public = {n for n in dir(pathbench) if not n.startswith("_")}
    assert public == set(funcs) | set(classes) | {n for n in names if not n.startswith("_")}
    assert "__version__" in names and pathbench.__version__
    for name, defs in funcs.items():
        for d in defs:
            _same(d, getattr(pathbench, name))
    render_variances = [d.args.kw_defaults[[a.arg for a in d.args.kwonlyargs].index("variance")] for d in
                        funcs["render"]]
    assert [ast.unparse(v) if v is not None else None for v in render_variances] == ["False", None]
    scene = classes["Scene"]
    runtime = {n for n in dir(pathbench.Scene) if not n.startswith("_")}
    assert runtime == set(scene), "Scene members differ from the stub"
    for name, d in scene.items():
        member = pathbench.Scene.__dict__[name]
        if isinstance(member, property):
            assert any(isinstance(x, ast.Name) and x.id == "property" for x in d.decorator_list), name
        else:
            _same(d, member, skip_self=True)


def test_package_carries_its_stubs():
    here = Path(pathbench.__file__).parent
    assert (here / "py.typed").is_file() and (here / "__init__.pyi").read_text() == STUB.read_text()


PYTHONS = os.environ.get("PATHBENCH_WHEEL_PYTHONS", "").split() or [getattr(sys, "_base_executable", sys.executable)]


@pytest.mark.slow
@pytest.mark.parametrize("python", PYTHONS)
def test_pip_install_in_a_fresh_venv(tmp_path, python):
    """The README's `python3 -m venv v && v/bin/pip install . && v/bin/python -c "import pathbench"`,
    with build isolation (scikit-build-core and pybind11 from PyPI): a full C++ build, minutes.
    Run by scripts/test.sh with PATHBENCH_SLOW=1; PATHBENCH_WHEEL_PYTHONS="python3.11 python3.13" picks
    the interpreters (default: the one running the tests)."""
    if os.environ.get("PATHBENCH_SLOW") != "1":
        pytest.skip("a full build through pip (minutes): PATHBENCH_SLOW=1")
    exe = shutil.which(python) or python
    venv = tmp_path / "v"
    subprocess.run([exe, "-m", "venv", str(venv)], check=True)
    pip = [str(venv / "bin" / "python"), "-m", "pip"]
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    start = time.monotonic()
    r = subprocess.run(pip + ["install", "-q", str(ROOT)], env=env, capture_output=True, text=True, timeout=3600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    print(f"pip install . with {exe}: {time.monotonic() - start:.0f} s")
    check = ("import pathbench, pathlib, numpy as np; s = pathbench.load_scene('paper-cornell');"
             "img, rep = pathbench.render(s, 4, 4, 1); assert img.shape == (4, 4, 3) and rep['spp'] == 1;"
             "d = pathlib.Path(pathbench.__file__).parent; assert (d / 'py.typed').is_file() and "
             "(d / '__init__.pyi').is_file(); print(pathbench.__file__)")
    r = subprocess.run([str(venv / "bin" / "python"), "-c", check], env=env, cwd=tmp_path, capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    assert str(venv) in r.stdout  # the installed copy, not the build folder
    # The command line beside the module (pyproject.toml, cmake/install.cmake): run from / with the
    # tools of the venv, the source tree's tools/ not needed.
    assert (venv / "bin" / "pathbench").is_file() and (venv / "bin" / "pathbench-bench").is_file()
    assert (venv / "share" / "pathbench" / "tools" / "history" / "__main__.py").is_file()
    r = subprocess.run([str(venv / "bin" / "pathbench"), "history", "rebuild", "--db", str(tmp_path / "h.sqlite"),
                        "--export", str(ROOT / "results" / "history" / "runs")], env=env, cwd="/",
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
