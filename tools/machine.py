"""The machine's name for results/<machine>/, the same slug as pb::machine_slug
(common/src/report.cpp): the lowercase CPU model from /proc/cpuinfo, every run of
non-alphanumerics turned into one '-', then a trailing '-processor' and a trailing '-cpu' removed."""
from __future__ import annotations

import re


def cpu_model(cpuinfo: str = "/proc/cpuinfo") -> str:
    try:
        with open(cpuinfo) as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


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
    m = cpu_model() if model is None else model
    out = re.sub(r"[^a-z0-9]+", "-", m.lower()).strip("-")
    for noise in ("-processor", "-cpu"):
        if out.endswith(noise):
            out = out[: -len(noise)]
    return out or "unknown-machine"
