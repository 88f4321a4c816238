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


def machine_slug(model: str | None = None) -> str:
    m = cpu_model() if model is None else model
    out = re.sub(r"[^a-z0-9]+", "-", m.lower()).strip("-")
    for noise in ("-processor", "-cpu"):
        if out.endswith(noise):
            out = out[: -len(noise)]
    return out or "unknown-machine"
