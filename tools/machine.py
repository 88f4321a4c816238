"""The machine, as the C++ side sees it (common/src/fingerprint_host.cpp, report.cpp):

- host_fingerprint(root): the host half of the fingerprint pathbench writes into every
  JSON (CPU, ISA flags, caches, clock, memory) with its `machine_id`, read from the same
  files in the same way, so that both languages give the same id on the same machine;
- slugify(text, fallback): the project's one slug rule; machine_slug() names
  results/<machine>/ folders (the lowercase CPU model, '-processor' / '-cpu' dropped).

  python3 tools/machine.py [--root DIR]      prints the host fingerprint as JSON
"""
from __future__ import annotations

import json
import os
import re
import sys

# Same order as kIsaFlags in common/src/fingerprint_host.cpp.
ISA_FLAGS = ["sse2", "sse4_1", "sse4_2", "avx", "avx2", "fma", "f16c", "bmi2", "avx512f", "avx512dq", "avx512cd",
             "avx512bw", "avx512vl", "avx512ifma", "avx512vbmi", "avx512_vnni", "avx512_bf16", "amx_tile"]


def _first_line(path: str) -> str:
    try:
        with open(path, errors="replace") as f:
            return f.readline().strip()
    except OSError:
        return ""


def _to_int(s: str, fallback: int) -> int:
    return int(s) if re.fullmatch(r"[+-]?\d+", s) else fallback


def _size_bytes(s: str) -> int:
    if not s:
        return -1
    mult = {"K": 1024, "M": 1024 ** 2, "G": 1024 ** 3}.get(s[-1], 1)
    v = _to_int(s[:-1] if s[-1] in "KMG" else s, -1)
    return -1 if v < 0 else v * mult


def _read_cpuinfo(path: str):
    first, logical, cores, sockets, physical = {}, 0, set(), set(), ""
    try:
        with open(path, errors="replace") as f:
            for line in f:
                if ":" not in line:
                    continue
                key, value = (p.strip() for p in line.split(":", 1))
                if key == "processor":
                    logical += 1
                if logical <= 1 and key not in first:
                    first[key] = value
                if key == "physical id":
                    physical = value
                    sockets.add(value)
                if key == "core id":
                    cores.add((physical, value))
    except OSError:
        pass
    return first, logical, cores, sockets


def host_fingerprint(root: str = "/") -> dict:
    root = os.path.join(root, "")
    first, logical, cores, sockets = _read_cpuinfo(root + "proc/cpuinfo")
    flags = set(first.get("flags", "").split())
    cpu0 = root + "sys/devices/system/cpu/cpu0/"
    caches = {}
    for i in range(10):
        d = f"{cpu0}cache/index{i}/"
        level, ctype = _first_line(d + "level"), _first_line(d + "type")
        size = _size_bytes(_first_line(d + "size"))
        if not level or size < 0:
            continue
        caches["L" + level + {"Data": "d", "Instruction": "i"}.get(ctype, "")] = size
    cpu = {
        "vendor": first.get("vendor_id") or "unknown",
        "model_name": first.get("model name") or "unknown CPU",
        "family": _to_int(first.get("cpu family", ""), -1),
        "model": _to_int(first.get("model", ""), -1),
        "stepping": _to_int(first.get("stepping", ""), -1),
        "logical_cpus": logical,
        "physical_cores": len(cores) if cores else logical,
        "sockets": len(sockets) if sockets else 1,
        "isa": [f for f in ISA_FLAGS if f in flags],
        "hypervisor": "hypervisor" in flags,
        "max_mhz": _to_int(_first_line(cpu0 + "cpufreq/cpuinfo_max_freq"), 0) // 1000,
        "caches": dict(sorted(caches.items())),
    }
    mem_kb = 0
    try:
        with open(root + "proc/meminfo") as f:
            for line in f:
                if line.startswith("MemTotal:"):
                    mem_kb = int(line.split()[1])
                    break
    except (OSError, ValueError, IndexError):
        pass
    j = {"cpu": cpu, "memory_bytes": mem_kb * 1024, "memory_gib": (mem_kb + 524288) // 1048576}
    j["machine_id"] = fnv1a64_hex(machine_identity_text(j))
    return j


def machine_identity_text(host: dict) -> str:
    """The canonical text machine_id hashes (pb::machine_identity_text)."""
    c = host["cpu"]
    caches = ",".join(f"{k}:{v}" for k, v in sorted(c["caches"].items()))
    return (f"vendor={c['vendor']}\nmodel_name={c['model_name']}\nfamily={c['family']}\nmodel={c['model']}\n"
            f"stepping={c['stepping']}\nlogical_cpus={c['logical_cpus']}\nphysical_cores={c['physical_cores']}\n"
            f"sockets={c['sockets']}\nisa={','.join(c['isa'])}\nhypervisor={1 if c['hypervisor'] else 0}\n"
            f"max_mhz={c['max_mhz']}\ncaches={caches}\nmemory_gib={host['memory_gib']}\n")


def fnv1a64_hex(text: str) -> str:
    h = 1469598103934665603
    for b in text.encode("utf-8"):
        h = ((h ^ b) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


def machine_id(root: str = "/") -> str:
    return host_fingerprint(root)["machine_id"]


def cpu_model(cpuinfo: str = "/proc/cpuinfo") -> str:
    return _read_cpuinfo(cpuinfo)[0].get("model name") or "unknown CPU"


def slugify(text: str, fallback: str) -> str:
    """pb::slugify: lowercase ASCII letters and digits kept, every other run one '-'."""
    ascii_lower = "".join(c.lower() if c.isascii() else "-" for c in text)  # C++ works on bytes
    out = re.sub(r"[^a-z0-9]+", "-", ascii_lower).strip("-")
    return out or fallback


# The x86 flags that say which vector code a host can run (pathbench's --isa, Embree's
# kernels, Mitsuba's LLVM back end).
VECTOR_FLAGS = ("sse4_2", "avx", "avx2", "fma", "avx512f", "avx512bw", "avx512dq", "avx512vl", "avx512cd")


def cpu_vector_flags(cpuinfo: str = "/proc/cpuinfo") -> list[str]:
    """The VECTOR_FLAGS this CPU lists in /proc/cpuinfo, in that order ([] if unreadable)."""
    try:
        with open(cpuinfo) as f:
            for line in f:
                if line.startswith("flags"):
                    have = set(line.split(":", 1)[1].split())
                    return [x for x in VECTOR_FLAGS if x in have]
    except OSError:
        pass
    return []


def machine_slug(model: str | None = None) -> str:
    out = slugify(cpu_model() if model is None else model, "unknown-machine")
    for noise in ("-processor", "-cpu"):
        if out.endswith(noise) and len(out) > len(noise):
            out = out[: -len(noise)]
    return out


if __name__ == "__main__":
    root = sys.argv[sys.argv.index("--root") + 1] if "--root" in sys.argv else "/"
    print(json.dumps(host_fingerprint(root), indent=2))
