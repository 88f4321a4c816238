"""Runs the suite's cases of one device through pathbench-bench (--preset suite), drawing a
progress bar from its console output, and reads its bench JSON back."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time

from . import manifest

AGGREGATES = ("_mean", "_median", "_stddev", "_cv")


def strategy_of(settings: dict) -> str:
    return settings.get("strategy", "pixel")


def case_name(workload: dict, label: str, settings: dict) -> str:
    return f"suite/{workload['name']}/{label}/{strategy_of(settings)}"


def cases_for(workloads: list[dict], device: dict, quick: bool, isa: str | None, data: str) -> list[dict]:
    cases = []
    for w in workloads:
        s = dict(manifest.run_settings(w, quick))
        if device["device"] == "cpu" and isa:
            s["isa"] = isa
        if device["device"] == "gpu":
            s.pop("isa", None)
        c = {"workload": w["name"], "name": case_name(w, device["label"], s),
             "scene": manifest.scene_of(w, quick), "device": device["device"], "settings": s}
        cases.append(c)
    return cases


class Progress:
    """A bar on stderr when it is a terminal, else one line per finished benchmark."""

    def __init__(self, total: int, stream=sys.stderr):
        self.total, self.done, self.stream = max(total, 1), 0, stream
        self.tty = stream.isatty()
        self.start = time.monotonic()
        self.current = ""

    def step(self, name: str, error: str | None = None):
        self.done += 1
        self.current = name
        if self.tty:
            width = 30
            filled = int(width * min(self.done, self.total) / self.total)
            elapsed = int(time.monotonic() - self.start)
            self.stream.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total} "
                              f"{elapsed // 60}:{elapsed % 60:02d} {name[:60]:<60}")
            self.stream.flush()
        if error:
            self.stream.write(("\n" if self.tty else "") + f"  {name}: {error}\n")

    def finish_case(self, name: str):
        if not self.tty:
            elapsed = int(time.monotonic() - self.start)
            self.stream.write(f"[{self.done}/{self.total}] {elapsed // 60}:{elapsed % 60:02d} {name}\n")
            self.stream.flush()

    def close(self):
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()


def _row_name(line: str) -> str | None:
    parts = line.split()
    if not parts or not parts[0].startswith("suite/"):
        return None
    return parts[0].replace("/manual_time", "")


def run_device(bench: str, cases_doc: dict, workdir: str, label: str, repetitions: int, min_time: float,
               env: dict, progress: Progress, log) -> tuple[int, str]:
    """Runs pathbench-bench for one device; returns (exit status, path of its bench JSON)."""
    cases_path = os.path.join(workdir, f"cases-{label}.json")
    out_path = os.path.join(workdir, f"bench-{label}.json")
    with open(cases_path, "w") as f:
        json.dump(cases_doc, f, indent=1, allow_nan=False)
    cmd = [bench, "--preset", "suite", "--suite-cases", cases_path, f"--benchmark_repetitions={repetitions}",
           "--benchmark_report_aggregates_only=false", f"--benchmark_out={out_path}",
           "--benchmark_out_format=json", f"--benchmark_min_time={min_time:g}", "--benchmark_color=false"]
    log.write("$ " + " ".join(cmd) + "\n")
    child_env = dict(os.environ)
    child_env.update(env)
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=child_env,
                            errors="replace")
    last = None
    try:
        for line in proc.stdout:
            log.write(line)
            name = _row_name(line)
            if name is None:
                continue
            if name.endswith(AGGREGATES):
                if name.endswith("_cv") and last:
                    progress.finish_case(last)
                continue
            err = None
            if "ERROR OCCURRED" in line:
                err = line.split("ERROR OCCURRED:", 1)[1].strip().strip("'")
            progress.step(name, err if name != last else None)
            last = name
        rc = proc.wait()
    except BaseException:
        proc.kill()
        proc.wait()
        raise
    return rc, out_path


def read_bench_json(path: str, strict: bool = True) -> dict:
    """The bench JSON; strict: NaN/Infinity refused (pathbench-bench writes none)."""
    def refuse(c):
        raise ValueError(f"{path}: {c} in the bench JSON (not strict JSON)")
    with open(path) as f:
        return json.load(f, parse_constant=refuse) if strict else json.load(f)
