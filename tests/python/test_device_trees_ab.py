"""scripts/device/gpu_trees_ab.sh refuses what it cannot read before it copies or builds
anything: a missing variants, cases or patch file, or no tree at all, is one line on stderr
and exit 2, and the output folder is not made. gpu_bench_scaling.sh refuses a part NAME that is not
a plain file name, before it makes anything. (Their builds and runs need the GPU host.)"""
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "device" / "gpu_trees_ab.sh"


def run(tmp_path, *args):
    return subprocess.run(["bash", str(SCRIPT), str(tmp_path / "out"), *args], capture_output=True, text=True,
                          timeout=60)


def test_refuses_unreadable_inputs_before_building(tmp_path):
    variants, cases = tmp_path / "variants.txt", tmp_path / "cases.txt"
    variants.write_text("base | /tmp/pb/base\n")
    cases.write_text("c | 1 | * | --scene paper-cornell\n")
    for args, named in [((str(tmp_path / "missing"), str(cases), "new"), "missing"),
                        ((str(variants), str(tmp_path / "gone"), "new"), "gone"),
                        ((str(variants), str(cases), "base:" + str(tmp_path / "no such.patch"), "new"), "no such.patch"),
                        ((str(variants), str(cases)), "no tree named")]:
        r = run(tmp_path, *args)
        assert r.returncode == 2, (args, r.stdout, r.stderr)
        assert named in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
        assert r.stdout == ""
        assert not (tmp_path / "out").exists()


SCALING = ROOT / "scripts" / "device" / "gpu_bench_scaling.sh"


def test_bench_scaling_refuses_a_name_it_would_write_as_a_path(tmp_path):
    # NAME becomes part of file names under OUT_DIR: a slash or a space could write elsewhere.
    for args in [["../x", "gpu/pixel/"], ["a b", "gpu/pixel/"], ["x/y", "gpu/pixel/"], ["", "gpu/pixel/"], ["x", ""],
                 ["x"]]:
        r = subprocess.run(["bash", str(SCALING), str(tmp_path / "out"), *args], capture_output=True,
                           text=True, timeout=60)
        assert r.returncode == 2, (args, r.stdout, r.stderr)
        assert len(r.stderr.strip().splitlines()) == 1, r.stderr
        assert not (tmp_path / "out").exists()
