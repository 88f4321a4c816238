"""The Embree ISA-cap shim (scripts/isa_cap/embree_isa_cap.c) that tools/mitsuba_speed.py
--emulate-isa avx2 preloads: it builds, caps an Embree device at AVX2 (as Embree itself
answers: no native 16-wide packets), also when Embree is reached through a library loaded
with RTLD_LOCAL (as Python loads Mitsuba's), and refuses an ISA name Embree would silently
take as SSE2. Skipped without a C compiler or Embree's headers."""
import importlib.util
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import isa_emulation
from machine import cpu_vector_flags

ROOT = Path(__file__).resolve().parents[2]

PROGRAM = r"""
#include <embree3/rtcore.h>
#include <dlfcn.h>
#include <stdio.h>
int main(int argc, char** argv) {
  RTCDevice d = rtcNewDevice(argc > 1 ? argv[1] : NULL);
  fflush(stdout);
  if (!d) { printf("device NULL\n"); return 3; }
  printf("ray8=%d ray16=%d\n", (int)rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED),
         (int)rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED));
  const char* (*report)(void) = (const char* (*)(void))dlsym(RTLD_DEFAULT, "pathbench_embree_isa_cap_report");
  printf("report %s\n", report ? report() : "none");
  rtcReleaseDevice(d);
  return 0;
}
"""

# A library that uses Embree, loaded by the program below with RTLD_LOCAL: Embree is then
# outside the scope dlsym(RTLD_NEXT) searches, as Mitsuba's is when Python imports it.
USER_LIB = r"""
#include <embree3/rtcore.h>
int user_ray16(void) {
  RTCDevice d = rtcNewDevice("threads=1");
  if (!d) return -1;
  int r = (int)rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED);
  rtcReleaseDevice(d);
  return r;
}
"""
LOADER = r"""
#include <dlfcn.h>
#include <stdio.h>
int main(int argc, char** argv) {
  void* h = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
  if (!h) { printf("dlopen: %s\n", dlerror()); return 3; }
  int (*f)(void) = (int (*)(void))dlsym(h, "user_ray16");
  printf("ray16=%d\n", f());
  return 0;
}
"""


def _cc():
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not cc:
        pytest.skip("no C compiler")
    return cc


def _compile(tmp_path, name, source, *flags):
    src = tmp_path / f"{name}.c"
    src.write_text(source)
    out = tmp_path / name
    r = subprocess.run([_cc(), "-O1", "-o", str(out), str(src), *flags], capture_output=True, text=True)
    if r.returncode and "embree3/rtcore.h" in r.stderr:
        pytest.skip("Embree 3 headers not found")
    assert r.returncode == 0, r.stderr
    return out


@pytest.fixture(scope="module")
def shim(tmp_path_factory):
    _cc()
    out = tmp_path_factory.mktemp("shim") / "libembree_isa_cap.so"
    subprocess.run(["bash", str(ROOT / "scripts" / "isa_cap" / "build.sh"), str(out)], check=True,
                   capture_output=True)
    return out


def _env(shim, **kw):
    env = {k: v for k, v in os.environ.items() if not k.startswith("PATHBENCH_EMBREE_")}
    return env | {"LD_PRELOAD": str(shim)} | kw


def test_shim_caps_embree_at_avx2(tmp_path, shim):
    exe = _compile(tmp_path, "newdevice", PROGRAM, "-lembree3", "-ldl")
    native = subprocess.run([str(exe), "threads=1"], capture_output=True, text=True, check=True).stdout
    assert "report none" in native  # without the shim
    if "avx512f" in cpu_vector_flags():
        assert "ray16=1" in native  # so that the capped run below shows a difference
    r = subprocess.run([str(exe), "threads=1"], capture_output=True, text=True, check=True,
                       env=_env(shim, PATHBENCH_EMBREE_MAX_ISA="avx2", PATHBENCH_EMBREE_VERBOSE="1",
                                PATHBENCH_EMBREE_CAP_LOG="1"))
    assert 'embree_isa_cap: embree("threads=1,max_isa=avx2,verbose=1")' in r.stderr
    assert "ray8=1 ray16=0" in r.stdout
    supported = [ln for ln in r.stdout.splitlines() if "(supported)" in ln]  # Embree's verbose output
    assert supported and all("AVX2" in ln and "AVX512" not in ln for ln in supported), r.stdout
    report = json.loads(r.stdout.split("report ", 1)[1].splitlines()[0])
    assert report == {"devices": 1, "library": "embree", "max_isa": "avx2",
                      "config": "threads=1,max_isa=avx2,verbose=1", "created": True, "native_packet_widths": [4, 8]}
    # NULL config: the cap alone.
    r = subprocess.run([str(exe)], capture_output=True, text=True, check=True,
                       env=_env(shim, PATHBENCH_EMBREE_MAX_ISA="avx2", PATHBENCH_EMBREE_CAP_LOG="1"))
    assert 'embree("max_isa=avx2")' in r.stderr and "ray16=0" in r.stdout


def test_shim_refuses_an_isa_embree_does_not_know(tmp_path, shim):
    exe = _compile(tmp_path, "newdevice", PROGRAM, "-lembree3", "-ldl")
    r = subprocess.run([str(exe)], capture_output=True, text=True, env=_env(shim, PATHBENCH_EMBREE_MAX_ISA="avx2x"))
    assert r.returncode == 3 and "device NULL" in r.stdout
    assert "PATHBENCH_EMBREE_MAX_ISA=avx2x is not one of" in r.stderr


def test_shim_reaches_an_embree_loaded_with_rtld_local(tmp_path, shim):
    src = tmp_path / "user.c"
    src.write_text(USER_LIB)
    lib = tmp_path / "libuser.so"
    r = subprocess.run([_cc(), "-shared", "-fPIC", "-o", str(lib), str(src), "-lembree3"], capture_output=True,
                       text=True)
    if r.returncode and "embree3/rtcore.h" in r.stderr:
        pytest.skip("Embree 3 headers not found")
    assert r.returncode == 0, r.stderr
    exe = _compile(tmp_path, "loader", LOADER, "-ldl")
    r = subprocess.run([str(exe), str(lib)], capture_output=True, text=True, check=True,
                       env=_env(shim, PATHBENCH_EMBREE_MAX_ISA="avx2", PATHBENCH_EMBREE_CAP_LOG="1"))
    assert 'embree("threads=1,max_isa=avx2")' in r.stderr
    assert "ray16=0" in r.stdout


def test_pathbench_under_the_shim_reports_avx2_embree(tmp_path, shim):
    exe = ROOT / "build" / "bin" / "pathbench"
    if not exe.exists():
        pytest.skip("build/bin/pathbench not built")
    report = tmp_path / "r.json"
    subprocess.run([str(exe), "render", "--scene", "paper-cornell", "--width", "8", "--height", "8", "--spp", "1",
                    "--isa", "avx2", "--quiet", "--report", str(report)], check=True,
                   env=_env(shim, PATHBENCH_EMBREE_MAX_ISA="avx2"))
    r = json.loads(report.read_text())
    assert r["fingerprint"]["embree"]["native_packet_widths"] == [4, 8]
    isa_emulation.check_pathbench_report(r, "pathbench", "avx2")


def test_mitsuba_under_the_shim(tmp_path, shim):
    """Mitsuba's bundled Embree (API in namespace mitsuba, loaded by Python with RTLD_LOCAL)
    and Dr.Jit's LLVM target, capped as mitsuba_speed.py --emulate-isa avx2 caps them."""
    if importlib.util.find_spec("mitsuba") is None:
        pytest.skip("mitsuba is not installed")
    import mitsuba_scene as ms
    if "DRJIT_LIBLLVM_PATH" not in os.environ and not os.path.exists(ms.LLVM_DEFAULT):
        pytest.skip("no libLLVM for Dr.Jit's LLVM backend")
    script = tmp_path / "probe.py"
    script.write_text(f"""
import json, sys
sys.path.insert(0, {str(ROOT / "tools")!r})
import isa_emulation, mitsuba_scene as ms
mi = ms.import_mitsuba("llvm_ad_rgb")
import drjit as dr
d = isa_emulation.drjit_set_target(dr, "avx2")
d["probe"] = isa_emulation.drjit_codegen_probe(dr)
scene = ms.load_scene(mi, width=16, height=16, spp=1)
img = ms.render(mi, scene, 1, seed=0)
print("RESULT " + json.dumps({{"drjit": d, "embree": isa_emulation.shim_report(), "mean": float(img.mean())}}))
""")
    r = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=600,
                       env=_env(shim, PATHBENCH_EMBREE_MAX_ISA="avx2"))
    assert r.returncode == 0, r.stderr[-3000:]
    res = json.loads(r.stdout.split("RESULT ", 1)[1].splitlines()[0])
    assert res["embree"]["library"] == "mitsuba-embree" and res["embree"]["native_packet_widths"] == [4, 8]
    assert "max_isa=avx2" in res["embree"]["config"]
    assert res["drjit"]["read_back"]["cpu"] == "haswell" and res["drjit"]["read_back"]["vector_width"] == 8
    isa_emulation.check_drjit(res["drjit"], "avx2")
    assert res["drjit"]["probe"]["ymm_instructions"] > 0 or not res["drjit"]["probe"]["disassembly_lines"]
    assert res["mean"] > 0
