#!/usr/bin/env python3
"""Interleaved A/B of pathbench builds on the CPU (issue 35): every build renders
paper-cornell SIZE x SIZE x SPP (2 bounces, nee) once per round for each strategy and ISA,
the order of the builds alternating from round to round; the render seconds are the
report's own (`seconds`: the render, without start-up). Prints medians, min-max and a
two-sided Mann-Whitney U test of each build against the first, and whether each build's
images are one (and the first build's); writes all runs as JSON.

    scripts/device/cpu_ab.py --bin main=/tmp/b-main/bin/pathbench --bin new=build/bin/pathbench \
        --strategies pixel,wavefront --isa auto,avx2 --rounds 7 --out ab.json
"""
import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys
import tempfile


def render(exe, strategy, isa, size, spp, threads, tmp, extra):
    rep = os.path.join(tmp, "r.json")
    cmd = [exe, "render", "--scene", "paper-cornell", "--width", str(size), "--height", str(size), "--spp", str(spp),
           "--bounces", "2", "--sampling", "nee", "--strategy", strategy, "--isa", isa, "--quiet",
           "--out", os.path.join(tmp, "i.pfm"), "--report", rep] + (["--threads", str(threads)] if threads else []) + extra
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.exit(f"cpu_ab.py: {' '.join(cmd)}: exit {p.returncode}: {p.stderr.strip()}")
    r = json.load(open(rep))
    with open(os.path.join(tmp, "i.pfm"), "rb") as f:
        film = hashlib.sha256(f.read()).hexdigest()[:16]
    return r["seconds"], r.get("extra", {}).get("isa"), p.stderr, film


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", action="append", required=True, help="NAME=PATH (the first is the baseline)")
    ap.add_argument("--strategies", default="pixel,wavefront")
    ap.add_argument("--isa", default="auto")
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=800)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--extra", default="", help="more render flags, space-separated")
    ap.add_argument("--stderr-to", help="append each run's stderr (e.g. stage timers) to this file")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    bins = [b.split("=", 1) for b in a.bin]
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(a.rounds):
            order = bins if k % 2 == 0 else bins[::-1]
            for s in a.strategies.split(","):
                for isa in a.isa.split(","):
                    for name, exe in order:
                        sec, used, err, film = render(exe, s, isa, a.size, a.spp, a.threads, tmp, a.extra.split())
                        runs.append({"round": k, "build": name, "strategy": s, "isa": isa, "isa_used": used,
                                     "seconds": sec, "film_sha": film})
                        if a.stderr_to and err:
                            with open(a.stderr_to, "a") as f:
                                f.write(f"== round {k} {name} {s} {isa}\n{err}")
                        print(f"round {k} {name:>8} {s:>9} {isa:>6} ({used}) {sec:.4f} s", flush=True)
    json.dump({"args": vars(a), "runs": runs}, open(a.out, "w"), indent=1)
    try:
        from scipy.stats import mannwhitneyu
    except ImportError:
        mannwhitneyu = None
    base = bins[0][0]
    for s in a.strategies.split(","):
        for isa in a.isa.split(","):
            case = [r for r in runs if r["strategy"] == s and r["isa"] == isa]
            ref = [r["seconds"] for r in case if r["build"] == base]
            ref_films = {r["film_sha"] for r in case if r["build"] == base}
            for name, _ in bins:
                x = [r["seconds"] for r in case if r["build"] == name]
                films = {r["film_sha"] for r in case if r["build"] == name}
                same = "one image" if len(films) == 1 else f"{len(films)} images"
                if name != base:
                    same += ", = " + base if films == ref_films else ", != " + base
                p = mannwhitneyu(x, ref).pvalue if mannwhitneyu and name != base else float("nan")
                print(f"{s:>9} {isa:>6} {name:>8}: median {statistics.median(x):.4f} s [{min(x):.4f}-{max(x):.4f}] "
                      f"/ {base} {statistics.median(x) / statistics.median(ref):.3f}  p={p:.3g}  {same}")


if __name__ == "__main__":
    main()
