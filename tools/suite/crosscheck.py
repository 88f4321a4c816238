"""`pathbench suite --crosscheck`: every chosen workload against Mitsuba 3 on every chosen
device, through `pathbench crosscheck` (its per-pixel z-test against Mitsuba's image with its
variance): one verdict per (workload, device) with the statistic, written as
crosscheck.json and crosscheck.md. Small frames: the workload's scene (its quick scene for
the two large ones), bounces and materials at --crosscheck-size and --crosscheck-spp; a
Mitsuba XML scene renders at its own film's size. Mitsuba renders 4x the samples with
--mitsuba-variant (scalar_rgb by default; cuda_ad_rgb or llvm_ad_rgb where installed)."""
from __future__ import annotations

import json
import os
import re
import subprocess
import time

from . import manifest

SIZE = re.compile(r"([1-9][0-9]{0,4})x([1-9][0-9]{0,4})")
VARIANT = re.compile(r"[a-z][a-z0-9_]{0,63}")


def parse_size(text: str) -> tuple[int, int]:
    """"WxH" -> (W, H); ValueError naming the option otherwise."""
    m = SIZE.fullmatch(text or "")
    if not m:
        raise ValueError(f"--crosscheck-size {text!r}: expected WIDTHxHEIGHT, e.g. 32x32 (1 to 99999 each)")
    return int(m.group(1)), int(m.group(2))


def check_variant(variant: str) -> str:
    if not VARIANT.fullmatch(variant or ""):
        raise ValueError(f"--mitsuba-variant {variant!r}: not a Mitsuba variant name (e.g. scalar_rgb, cuda_ad_rgb)")
    return variant


def command(exe: str, w: dict, device: str, size: tuple[int, int], spp: int, variant: str, out_dir: str) -> list[str]:
    """The `pathbench crosscheck` call for one workload on one device."""
    scene = manifest.scene_of(w, True)  # the large workloads' quick scenes: the same kind, fewer triangles
    s = manifest.run_settings(w, False)
    frame = [] if scene.endswith(".xml") else ["--width", str(size[0]), "--height", str(size[1])]
    return [exe, "crosscheck", scene, "--device", device, *frame, "--spp", str(spp), "--bounces",
            str(s.get("bounces", 2)), "--variant", variant, "--out-dir", out_dir]


def _verdict(out_dir: str, device: str) -> dict | None:
    try:
        with open(os.path.join(out_dir, "verdict.json")) as f:
            v = json.load(f)
        return {"verdict": v, "device": v["devices"][device]}
    except (OSError, ValueError, KeyError, TypeError):
        return None


def run(exe: str, workloads: list[dict], devices: list[dict], size: tuple[int, int], spp: int, variant: str,
        work: str, log) -> list[dict]:
    """One row per (workload, device): status pass / FAIL / error, with crosscheck's statistic."""
    rows = []
    for w in workloads:
        for d in devices:
            out_dir = os.path.join(work, "crosscheck", f"{w['name']}-{d['label']}")
            cmd = command(exe, w, d["device"], size, spp, variant, out_dir)
            log.write("$ " + " ".join(cmd) + "\n")
            env = dict(os.environ, **d.get("env", {}), PATHBENCH_DATA_DIR=manifest.data_dir())
            t0 = time.monotonic()
            r = subprocess.run(cmd, capture_output=True, text=True, env=env, errors="replace")
            log.write(r.stdout + r.stderr)
            row = {"workload": w["name"], "device": d["label"], "scene": os.path.basename(manifest.scene_of(w, True)),
                   "seconds": round(time.monotonic() - t0, 2), "exit_status": r.returncode}
            got = _verdict(out_dir, d["device"]) if r.returncode in (0, 1) else None
            if got:
                s, v = got["device"], got["verdict"]
                row.update(status="pass" if s["pass"] else "FAIL", share_passed=s["share_passed"], values=s["values"],
                           min_p=s["min_p"], alpha=s["alpha"], mean_ratio=s["mean_ratio"], variant=v.get("variant"),
                           mitsuba_spp=v.get("mitsuba_spp"), pathbench_spp=v.get("pathbench_spp"))
            else:
                lines = (r.stderr.strip() or r.stdout.strip() or f"exit status {r.returncode}").splitlines()
                row.update(status="error", reason=lines[-1][:300])
            print(f"crosscheck {w['name']} {d['label']}: {row['status']}"
                  + (f" ({100 * row['share_passed']:.2f} % of {row['values']} pass)" if "share_passed" in row else
                     f": {row.get('reason', '')}"), flush=True)
            rows.append(row)
    return rows


def markdown(rows: list[dict], size: tuple[int, int], spp: int, variant: str, facts: list) -> str:
    m = ["# pathbench suite: crosscheck against Mitsuba 3", "",
         " · ".join(f"**{k}** {v}" for k, v in facts), "",
         f"Each workload's scene (the quick scene of the large ones) at {size[0]}x{size[1]} (a Mitsuba XML scene at its "
         f"film's size), {spp} samples per pixel, its bounces, light sampling; Mitsuba `{variant}` with 4x the samples "
         "in 16 passes. Pass: at least 99 % of the pixel-channels pass the z-test (Sidak-corrected alpha 0.01 over "
         "all of them) and every channel's image mean is within 2 % of Mitsuba's.", "",
         "| workload | device | scene | verdict | pixel-channels passing | min p (alpha) | mean / Mitsuba's (R G B) | s |",
         "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "share_passed" in r:
            ratio = " ".join(f"{x:.4f}" for x in r["mean_ratio"])
            m.append(f"| {r['workload']} | {r['device']} | {r['scene']} | {r['status']} | {100 * r['share_passed']:.2f} % "
                     f"of {r['values']} | {r['min_p']:.2g} ({r['alpha']:.2g}) | {ratio} | {r['seconds']} |")
        else:
            m.append(f"| {r['workload']} | {r['device']} | {r['scene']} | error | {r.get('reason', '')} | | | "
                     f"{r['seconds']} |")
    return "\n".join(m) + "\n"
