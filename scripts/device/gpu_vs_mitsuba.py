#!/usr/bin/env python3
"""pathbench's GPU tracer against Mitsuba 3 on the GPU (cuda_ad_rgb, OptiX), interleaved in
one process on the GPU host: per scene, one warm-up of each, then ROUNDS rounds of one
Mitsuba render (wall time around mi.render + dr.sync_thread) and one `pathbench render
--device gpu` (its CUDA-event device seconds). Prints a table and writes JSON.

    env -u LD_LIBRARY_PATH PYTHONPATH=MITSUBA_DIR PB_LD_LIBRARY_PATH=$LD_LIBRARY_PATH \\
      python3 scripts/device/gpu_vs_mitsuba.py PATHBENCH OUT.json NAME=SCENE:XML:BOUNCES ...

SCENE is what `pathbench render --scene` takes; XML is pathbench's own export of it
(tools/mitsuba_scene.py / pathbench.export_mitsuba, 256x256, max_depth = bounces + 1), so
both render the same scene, camera and estimator (path tracing with MIS light sampling).
Mitsuba runs without LD_LIBRARY_PATH (pathbench's Embree would shadow its own); pathbench
gets PB_LD_LIBRARY_PATH back.
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROUNDS = int(os.environ.get("ROUNDS", "5"))
SPP, SIZE = 800, 256


def pathbench_seconds(pb, scene, bounces, report):
    env = dict(os.environ, LD_LIBRARY_PATH=os.environ.get("PB_LD_LIBRARY_PATH", ""))
    cmd = [pb, "render", "--device", "gpu", "--quiet", "--scene", scene, "--width", str(SIZE), "--height", str(SIZE),
           "--spp", str(SPP), "--bounces", str(bounces), "--sampling", "nee", "--report", report]
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL)
    return json.load(open(report))["device_seconds"]


def main():
    import drjit as dr  # noqa: PLC0415
    import mitsuba as mi  # noqa: PLC0415
    mi.set_variant("cuda_ad_rgb")
    pb, out = sys.argv[1], sys.argv[2]
    rows = []
    tmp = tempfile.mkdtemp()
    for spec in sys.argv[3:]:
        name, rest = spec.split("=", 1)
        scene, xml, bounces = rest.rsplit(":", 2)
        bounces = int(bounces)
        ms = mi.load_file(xml)
        report = os.path.join(tmp, f"{name}.json")

        def mitsuba_once(seed):
            t0 = time.perf_counter()
            img = mi.render(ms, spp=SPP, seed=seed)
            dr.sync_thread()
            dt = time.perf_counter() - t0
            del img
            return dt

        mitsuba_once(0)  # JIT compilation / kernel cache
        pathbench_seconds(pb, scene, bounces, report)  # warm-up
        mt, pt = [], []
        for r in range(ROUNDS):
            mt.append(mitsuba_once(r + 1))
            pt.append(pathbench_seconds(pb, scene, bounces, report))
        ratios = [m / p for m, p in zip(mt, pt)]
        row = {"name": name, "scene": scene, "bounces": bounces, "spp": SPP, "size": SIZE,
               "mitsuba_seconds": mt, "pathbench_device_seconds": pt,
               "mitsuba_median": statistics.median(mt), "pathbench_median": statistics.median(pt),
               "speedup_of_medians": statistics.median(mt) / statistics.median(pt),
               "speedup_rounds_min": min(ratios), "speedup_rounds_max": max(ratios)}
        rows.append(row)
        print(f"{name:18s} mitsuba {row['mitsuba_median']*1e3:8.2f} ms  pathbench {row['pathbench_median']*1e3:8.2f} ms"
              f"  {row['speedup_of_medians']:.2f}x (rounds {min(ratios):.2f}-{max(ratios):.2f})", flush=True)
    gpu = subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version", "--format=csv,noheader"],
                         capture_output=True, text=True).stdout.strip()
    json.dump({"gpu": gpu, "mitsuba": mi.__version__, "variant": "cuda_ad_rgb", "rounds": ROUNDS,
               "source_commit": os.environ.get("PATHBENCH_SOURCE_COMMIT"), "rows": rows}, open(out, "w"), indent=1)


if __name__ == "__main__":
    main()
