"""Emulating an AVX2-only host on an AVX-512 one (issue 14), for tools/mitsuba_speed.py
--emulate-isa avx2: every component of both renderers that would use AVX-512 is capped
at AVX2, and each cap is read back rather than assumed.

- pathbench's batched path step: `pathbench render --isa avx2` (the report's `isa`).
- Embree 3, in pathbench and pathbench-bench (Debian's libembree3) and in Mitsuba (the
  libembree3 its wheel bundles): the LD_PRELOAD shim scripts/isa_cap/embree_isa_cap.c
  appends `max_isa=avx2` to rtcNewDevice's config. Read back: the native packet widths
  Embree answers (16 only with AVX-512): pathbench's report and pathbench-bench's context
  (fingerprint.embree), and the shim's own record of Mitsuba's device.
- Dr.Jit's LLVM backend (Mitsuba's JIT): jit_llvm_set_target(cpu, features, width),
  read back with jit_llvm_target_cpu/features and jit_llvm_vector_width, and a probe
  kernel's disassembly counted for zmm (512-bit) registers.
- glibc's own dispatch (memcpy and the like): GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX512...,
  set for the tool and its children (not read back).

The shim and the tunables must be in place when a process starts, so the tool re-executes
itself with them (ensure_preloaded). It is an emulation: the caches, clocks, cores and
memory are the AVX-512 host's.
"""
from __future__ import annotations

import ctypes
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SHIM_SOURCE = ROOT / "scripts" / "isa_cap" / "embree_isa_cap.c"
SHIM_BUILD = ROOT / "scripts" / "isa_cap" / "build.sh"
SHIM_DEFAULT = ROOT / "build" / "isa_cap" / "libembree_isa_cap.so"
SHIM_ENV = "PATHBENCH_EMBREE_MAX_ISA"
REEXEC_ENV = "PATHBENCH_ISA_EMULATION_REEXEC"  # set on the re-executed tool: no second re-exec

# Per emulated ISA: Dr.Jit's LLVM target (cpu, features, vector width) and the glibc
# hwcaps masked. The features are x86-64-v3's (Haswell's), AVX-512 switched off
# explicitly; Dr.Jit writes them into each kernel's "target-features" attribute, which
# replaces the host's features (LLVM's per-function subtarget), and picks its AVX
# intrinsics by finding "+avx" in them.
TARGETS = {
    "avx2": {
        "drjit": ("haswell", "+avx,+avx2,+fma,+f16c,+bmi,+bmi2,+lzcnt,+popcnt,+sse4.2,+movbe,-avx512f", 8),
        "glibc_hwcaps": "-AVX512F,-AVX512CD,-AVX512DQ,-AVX512BW,-AVX512VL,-AVX512_IFMA,-AVX512_VBMI",
    },
}

STATEMENT = ("This is an AVX-512 host with every component capped at {ISA}, NOT a real {ISA}-only host: the cores, "
             "caches, clocks and memory are this CPU's, and only the instructions used are those of an {ISA} host.")


def host_has_avx512(cpu_flags: list[str]) -> bool:
    return "avx512f" in cpu_flags


def glibc_tunables(isa: str, existing: str | None) -> str:
    cap = f"glibc.cpu.hwcaps={TARGETS[isa]['glibc_hwcaps']}"
    return f"{existing}:{cap}" if existing else cap


def build_shim(out: Path) -> Path:
    """Builds the shim (scripts/isa_cap/build.sh) unless `out` is newer than its source."""
    out = Path(out).resolve()
    if not out.is_file() or out.stat().st_mtime < SHIM_SOURCE.stat().st_mtime:
        subprocess.run(["bash", str(SHIM_BUILD), str(out)], check=True, stdout=subprocess.DEVNULL)
    return out


def shim_report() -> dict | None:
    """The shim's record (devices created through it, the last one's config and native packet
    widths), or None when this process was started without the shim preloaded."""
    try:
        f = ctypes.CDLL(None).pathbench_embree_isa_cap_report
    except AttributeError:
        return None
    f.restype = ctypes.c_char_p
    return json.loads(f().decode())


def ensure_preloaded(isa: str, shim: Path, argv: list[str] | None) -> None:
    """Returns when the shim is preloaded in this process with the cap asked; otherwise
    re-executes the tool with LD_PRELOAD, the cap and the glibc tunables set (they only
    act from a process's start), or exits with the command to run where it cannot."""
    rep = shim_report()
    if rep is not None and os.environ.get(SHIM_ENV) == isa:
        return
    if os.environ.get(REEXEC_ENV) or argv is not None:
        sys.exit(f"--emulate-isa {isa}: the Embree shim is not preloaded in this process (or {SHIM_ENV} is not "
                 f"{isa}); run: LD_PRELOAD={shim} {SHIM_ENV}={isa} GLIBC_TUNABLES={glibc_tunables(isa, None)} "
                 f"python3 {' '.join(sys.argv)}")
    if any(c in str(shim) for c in ": "):
        sys.exit(f"{shim}: LD_PRELOAD cannot take a path with ':' or spaces; pass --embree-shim elsewhere")
    env = dict(os.environ)
    env["LD_PRELOAD"] = f"{shim}:{env['LD_PRELOAD']}" if env.get("LD_PRELOAD") else str(shim)
    env[SHIM_ENV] = isa
    env["GLIBC_TUNABLES"] = glibc_tunables(isa, env.get("GLIBC_TUNABLES"))
    env[REEXEC_ENV] = "1"
    print(f"--emulate-isa {isa}: re-executing with LD_PRELOAD={shim} {SHIM_ENV}={isa} "
          f"GLIBC_TUNABLES={env['GLIBC_TUNABLES']}", flush=True)
    args = getattr(sys, "orig_argv", None) or [sys.executable, *sys.argv]
    os.execve(sys.executable, [sys.executable, *args[1:]], env)


def _drjit_core(dr):
    return ctypes.CDLL(str(Path(dr.__file__).parent / "libdrjit-core.so"), mode=getattr(os, "RTLD_NOLOAD", 4))


def drjit_target(dr) -> dict:
    """The LLVM backend's target as Dr.Jit reports it (jit.h's C++ functions, by their
    mangled names: libdrjit-core exports them without C linkage)."""
    core = _drjit_core(dr)
    cpu, feat, width = (core._Z19jit_llvm_target_cpuv, core._Z24jit_llvm_target_featuresv,
                        core._Z21jit_llvm_vector_widthv)
    cpu.restype = feat.restype = ctypes.c_char_p
    width.restype = ctypes.c_uint32
    return {"cpu": (cpu() or b"").decode(), "features": (feat() or b"").decode(), "vector_width": int(width())}


def drjit_set_target(dr, isa: str) -> dict:
    """Sets Dr.Jit's LLVM target for `isa` (after the LLVM backend is initialised, i.e. after
    mi.set_variant of an llvm variant, and before any kernel of the render is compiled) and
    returns {native, asked, read_back}; raises if the read-back differs from what was asked."""
    native = drjit_target(dr)
    cpu, features, width = TARGETS[isa]["drjit"]
    if not native["cpu"]:
        raise RuntimeError("Dr.Jit's LLVM backend is not initialised (no target cpu): set an llvm variant first")
    f = _drjit_core(dr)._Z19jit_llvm_set_targetPKcS0_j
    f.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_uint32]
    f.restype = None
    f(cpu.encode(), features.encode(), width)
    back = drjit_target(dr)
    asked = {"cpu": cpu, "features": features, "vector_width": width}
    if back != asked:
        raise RuntimeError(f"Dr.Jit's LLVM target read back as {back}, not {asked}")
    return {"native": native, "asked": asked, "read_back": back}


def drjit_codegen_probe(dr) -> dict:
    """Compiles a small kernel (fma, sqrt, rsqrt, a gather) with Dr.Jit's Trace log on, which
    prints the kernel's disassembly, and counts the instructions naming zmm (512-bit) and ymm
    (256-bit) registers. The render's own kernels are not disassembled (that would slow the
    timed warm-up); this shows the target Dr.Jit compiles for. A literal unique to this run
    keeps the kernel out of Dr.Jit's on-disk kernel cache (a cached kernel is not disassembled)."""
    nonce = float(time.time_ns() % 1_000_003) + 0.25
    with tempfile.TemporaryFile(mode="w+b") as log:
        saved = []
        for fd, stream in ((1, sys.stdout), (2, sys.stderr)):  # Dr.Jit logs on stdout (Python's callback)
            stream.flush()
            saved.append(os.dup(fd))
            os.dup2(log.fileno(), fd)
        try:
            level = dr.log_level()
            dr.set_log_level(dr.LogLevel.Trace)
            try:
                x = dr.arange(dr.llvm.Float, 4099)
                i = dr.arange(dr.llvm.UInt32, 4099)
                y = dr.fma(dr.sqrt(x), x, nonce) + dr.gather(dr.llvm.Float, x, (i * 7) % 4099) + dr.rsqrt(x + 1)
                dr.eval(y)
            finally:
                dr.set_log_level(level)
        finally:
            for fd, stream in ((1, sys.stdout), (2, sys.stderr)):
                stream.flush()
                os.dup2(saved[fd - 1], fd)
                os.close(saved[fd - 1])
        log.seek(0)
        lines = [ln for ln in log.read().decode(errors="replace").splitlines() if "jit_llvm_disasm" in ln]
    return {"disassembly_lines": len(lines), "zmm_instructions": sum("zmm" in ln for ln in lines),
            "ymm_instructions": sum("ymm" in ln for ln in lines)}


def check_drjit(record: dict, isa: str) -> None:
    if "+avx512" in record["read_back"]["features"]:
        raise RuntimeError(f"Dr.Jit's features still enable AVX-512: {record['read_back']['features']}")
    probe = record.get("probe") or {}
    if probe.get("zmm_instructions"):
        raise RuntimeError(f"Dr.Jit capped at {isa} still compiled {probe['zmm_instructions']} zmm instructions")


def check_embree(facts: dict | None, who: str, isa: str) -> None:
    """`facts`: an Embree record with native_packet_widths (pathbench's fingerprint.embree, or
    the shim's report). 16-wide packets are native only with AVX-512."""
    if facts is None:
        raise RuntimeError(f"{who}: no record of its Embree device, cannot tell whether the {isa} cap took")
    if 16 in facts.get("native_packet_widths", []) or facts.get("isa_derived") == "avx512":
        raise RuntimeError(f"{who}: Embree still runs AVX-512 kernels ({facts}): the shim did not cap it")


def check_pathbench_report(report: dict, who: str, isa: str) -> None:
    if report.get("isa") != isa:
        raise RuntimeError(f"{who}: the path step ran {report.get('isa')}, not {isa}")
    build = (report.get("fingerprint") or {}).get("build") or {}
    if any("avx512" in x for x in build.get("isa_compiled", [])) or "-march=native" in build.get("cxx_flags", ""):
        raise RuntimeError(f"{who}: built for the host's ISA ({build}): its compiled code outside the path step "
                           "may use AVX-512; rebuild without PATHBENCH_NATIVE")
    check_embree((report.get("fingerprint") or {}).get("embree"), who, isa)


def record(isa: str, shim: Path, drjit: dict, mitsuba_embree: dict | None, pathbench_embree: dict,
           bench_embree: dict | None, pathbench_isa: dict, build: dict | None) -> dict:
    """The results' `emulation` field."""
    return {
        "isa": isa,
        "statement": STATEMENT.format(isa=isa, ISA=isa.upper()),
        "covered": {
            "pathbench_path_step": {"flag": f"--isa {isa}", "isa_ran": pathbench_isa},
            "embree": {"how": f"LD_PRELOAD {shim.name} (scripts/isa_cap/embree_isa_cap.c): max_isa={isa} appended "
                              "to rtcNewDevice's config", "shim": str(shim),
                       "pathbench": pathbench_embree, "pathbench_bench": bench_embree, "mitsuba": mitsuba_embree},
            "drjit_llvm": drjit,
            "glibc": {"GLIBC_TUNABLES": os.environ.get("GLIBC_TUNABLES"), "read_back": False},
        },
        "pathbench_build": build,
        "not_covered": "numpy (image means after each render, untimed). Mitsuba's and Dr.Jit's own compiled "
                       "libraries (libmitsuba, libdrjit-core) hold no AVX-512 instructions (objdump: no zmm) and "
                       "pathbench's hold them only in its --isa avx512 path step, which is not run.",
    }


def markdown_lines(em: dict) -> list[str]:
    """The Markdown paragraph that says what was emulated and what each cap read back."""
    c = em["covered"]
    d = c["drjit_llvm"]
    nat, back, probe = d["native"], d["read_back"], d.get("probe") or {}
    e = c["embree"]

    def widths(x):
        return "not recorded" if not x else ("widths " + "/".join(str(w) for w in x.get("native_packet_widths", [])))

    pb_e = "; ".join(f"{s} {widths(x)}" for s, x in e["pathbench"].items())
    native_probe = d.get("native_probe") or {}
    probe_s = (f"a probe kernel's disassembly has {probe['zmm_instructions']} zmm and {probe['ymm_instructions']} "
               "ymm instructions" if probe.get("disassembly_lines") else "no probe disassembly (LLVM gave none)")
    if native_probe.get("disassembly_lines"):
        probe_s += (f" (the same kernel for the native target: {native_probe['zmm_instructions']} zmm, "
                    f"{native_probe['ymm_instructions']} ymm)")
    return [
        "",
        f"**Emulated {em['isa'].upper()}-only host.** {em['statement']} Capped, each read back:",
        f"pathbench's path step `{c['pathbench_path_step']['flag']}` (ran: "
        + ", ".join(f"{s}: {i}" for s, i in c["pathbench_path_step"]["isa_ran"].items()) + ");",
        f"Embree through the LD_PRELOAD shim scripts/isa_cap/embree_isa_cap.c (`max_isa={em['isa']}` appended to "
        f"rtcNewDevice's config; native packet widths as Embree answers them, 16 only with AVX-512): pathbench "
        f"{pb_e}; pathbench-bench (raw rates) {widths(e['pathbench_bench'])}; Mitsuba's bundled Embree "
        f"{widths(e['mitsuba'])} (config `{(e['mitsuba'] or {}).get('config', '?')}`);",
        f"Dr.Jit's LLVM backend set to cpu `{back['cpu']}`, vector width {back['vector_width']}, features "
        f"`{back['features']}` (native: `{nat['cpu']}`, width {nat['vector_width']}); {probe_s};",
        f"glibc's dispatch `GLIBC_TUNABLES={c['glibc']['GLIBC_TUNABLES']}` (not read back).",
        f"Not covered: {em['not_covered']}",
    ]
