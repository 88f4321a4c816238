"""`pathbench suite`: every workload of the manifest on every device present, with enough
repetitions for compare's U test; a progress bar and a table; bench JSON; records into the
history database; one page (HTML + Markdown).

Exit status: 0 done (skipped workloads are listed with their reason), 2 bad input (one line on
stderr, nothing written), 3 a measurement process failed."""
from __future__ import annotations

import datetime as dt
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

from . import crosscheck, devices, manifest, page, results, runner
from .options import ROOT, InputError, _check_db, _check_out, _data_home, _exe, default_db, parse_args, repetitions_of


def _finite(x):
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_finite(v) for v in x]
    return x


def _work_dir(out: str) -> str:
    """A hidden folder beside `out` where everything is written, moved into `out` at the end."""
    parent = os.path.dirname(os.path.abspath(out)) or "."
    os.makedirs(parent, exist_ok=True)
    return tempfile.mkdtemp(prefix=f".{os.path.basename(out)}.partial-", dir=parent)


def _record(db: str, files: list[str], a) -> None:
    cmd = [sys.executable, "-m", "history", "record", "--db", db]
    cmd += ["--export", a.export] if a.export else []
    cmd += ["--machine", a.machine] if a.machine else []
    r = subprocess.run(cmd + files, capture_output=True, text=True)
    sys.stdout.write(r.stdout)
    if r.returncode != 0:
        msg = (r.stderr.strip().splitlines() or ["history record failed"])[-1]
        raise InputError(f"--db {db}: recording failed: {msg}")


def _facts(s: dict, ctx: dict, elapsed: float, reps: int) -> list:
    f = [("date", s["date"]), ("commit", (ctx.get("git_revision") or "unknown")[:12]),
         ("CPU", f"{ctx.get('cpu_model', '?')} ({ctx.get('cpu_hardware_threads', '?')} threads)")]
    gpus = sorted({r["device_name"] for r in s["rows"] if r["device"].startswith("gpu") and r.get("device_name")})
    f.append(("GPU", ", ".join(gpus) if gpus else "none"))
    f += [("repetitions", reps), ("manifest", s["manifest_sha256"][:12])]
    if elapsed is not None:
        f.append(("took", f"{elapsed / 60:.1f} min"))
    return f


def _table(rows: list[dict]) -> str:
    head = f"{'workload':<22} {'device':<8} {'ms/frame':>10} {'Mrays/s':>9} {'Msmp/s':>8} {'MiB':>7} {'J/frame':>9} " \
           f"{'Mrays/J':>8} {'throttle':>8}  vs previous"
    out = [head, "-" * len(head)]
    for r in rows:
        if r["status"] != "ok":
            out.append(f"{r['workload']:<22} {r['device']:<8} skipped: {r.get('reason', '')}")
            continue
        def n(v, scale=1.0, fmt="{:.4g}"):
            return "-" if v is None else fmt.format(v * scale)
        prev = r.get("previous") or {}
        vs = f"{prev['verdict']} {prev['change'] * 100:+.1f}%" if "change" in prev else "-"
        th = "-" if r.get("throttled") is None else ("YES" if r["throttled"] else "no")
        mem = max(r.get("peak_host_bytes") or 0, r.get("peak_device_bytes") or 0) / 2**20
        out.append(f"{r['workload']:<22} {r['device']:<8} {n(r['ms']):>10} {n(r['rays_per_second'], 1e-6):>9} "
                   f"{n(r['samples_per_second'], 1e-6):>8} {mem:>7.0f} {n(r.get('joules_per_frame')):>9} "
                   f"{n(r.get('rays_per_joule'), 1e-6):>8} {th:>8}  {vs}")
    return "\n".join(out)


def run(a) -> int:
    exe = _exe()
    bench = os.path.join(os.path.dirname(exe), "pathbench-bench")
    m = manifest.load(a.manifest)
    chosen = manifest.select(m, a.workloads)
    mode = "quick" if a.quick else "full"
    preset = "suite-quick" if a.quick else "suite"
    if a.list:
        for w in chosen:
            s = manifest.run_settings(w, a.quick)
            flat, inst = manifest.triangle_estimate(w, manifest.data_dir(), a.quick)
            print(f"{w['name']:<20} {s['width']}x{s['height']} {s['spp']:>4} spp {flat:>11,} tri {inst:>12,} instanced  "
                  f"{w['stresses'][:60]}")
        return 0
    db = None if a.no_record else (a.db or default_db())
    if db:
        _check_db(db)
    stamp = dt.datetime.now(dt.timezone.utc).strftime("%Y%m%dT%H%M%SZ")
    out = a.out or os.path.join(_data_home(), "pathbench", "suite", f"{stamp}-{mode}")
    _check_out(out)
    if a.from_json:
        work = _work_dir(out)
        try:
            return _from_json(a, work, out, m, chosen, mode, preset, db, None)
        finally:
            shutil.rmtree(work, ignore_errors=True)
    run_devs, skipped_devs = devices.plan(exe, a.devices)
    if a.crosscheck:
        return _crosscheck(a, exe, out, chosen, run_devs, skipped_devs)
    rank, size = devices.mpi_world()
    data = manifest.data_dir()
    runnable, skipped_rows = [], []
    for w in chosen:
        why = manifest.missing_requirement(w, data)
        if why:
            for d in run_devs:
                skipped_rows.append({"workload": w["name"], "device": d["label"], "status": "skipped",
                                     "reason": f"workload {w['name']} {why}"})
            print(f"pathbench suite: skipped {w['name']}: {why}", file=sys.stderr)
        else:
            runnable.append(w)
    for d in skipped_devs:
        print(f"pathbench suite: no {d['label']}: {d['reason']}", file=sys.stderr)

    work = _work_dir(out)
    t0 = time.monotonic()
    try:
        return _run_in(a, work, out, exe, bench, m, runnable, chosen, run_devs, skipped_rows, mode, preset, db,
                       stamp, rank, size, t0)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _crosscheck(a, exe, out, chosen, run_devs, skipped_devs) -> int:
    """--crosscheck: every chosen workload on every device against Mitsuba 3; exit 0 when all
    pass, 1 when one does not (or could not be judged)."""
    for d in skipped_devs:
        print(f"pathbench suite: no {d['label']}: {d['reason']}", file=sys.stderr)
    data = manifest.data_dir()
    runnable = []
    for w in chosen:
        why = manifest.missing_requirement(w, data)
        if why:
            print(f"pathbench suite: skipped {w['name']}: {why}", file=sys.stderr)
        else:
            runnable.append(w)
    work = _work_dir(out)
    try:
        t0 = time.monotonic()
        with open(os.path.join(work, "crosscheck.log"), "w") as log:
            rows = crosscheck.run(exe, runnable, run_devs, a.crosscheck_frame, a.crosscheck_spp, a.mitsuba_variant,
                                  work, log)
        version = subprocess.run([exe, "--version"], capture_output=True, text=True).stdout.strip().splitlines()
        gpus = sorted({d["name"] for d in run_devs if d["device"] == "gpu"})
        facts = [("date", dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")),
                 ("pathbench", version[0] if version else "?"), ("devices", ", ".join(d["label"] for d in run_devs)),
                 ("GPU", ", ".join(gpus) or "none"), ("took", f"{(time.monotonic() - t0) / 60:.1f} min")]
        doc = {"suite": "pathbench", "command": "pathbench suite " + " ".join(sys.argv[1:]), "facts": facts,
               "frame": list(a.crosscheck_frame), "spp": a.crosscheck_spp, "mitsuba_variant": a.mitsuba_variant,
               "rows": rows}
        with open(os.path.join(work, "crosscheck.json"), "w") as f:
            json.dump(_finite(doc), f, indent=1, allow_nan=False)
            f.write("\n")
        with open(os.path.join(work, "crosscheck.md"), "w") as f:
            f.write(crosscheck.markdown(rows, a.crosscheck_frame, a.crosscheck_spp, a.mitsuba_variant, facts))
        os.makedirs(out, exist_ok=True)
        for n in os.listdir(work):
            os.replace(os.path.join(work, n), os.path.join(out, n))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    bad = [r for r in rows if r["status"] != "pass"]
    print(f"crosscheck: {len(rows) - len(bad)} of {len(rows)} pass; {os.path.join(out, 'crosscheck.md')}")
    return 1 if bad or not rows else 0


def _run_in(a, work, out, exe, bench, m, runnable, chosen, run_devs, skipped_rows, mode, preset, db, stamp, rank, size, t0):
    groups = [[d] for d in run_devs]
    if size > 1:  # under mpirun: one pathbench-bench for every device, its frames over the ranks
        groups = [[dict(d, label=f"ranks{size}-{d['label']}") for d in run_devs]]
    plans = []
    for g in groups:
        cases, label = [], "-".join(d["label"] for d in g)
        for d in g:
            cases += runner.cases_for(runnable, d, a.quick, a.isa, manifest.data_dir())
        # One pathbench-bench per repetition count (--repetitions-for), so that every benchmark
        # keeps its name (Google Benchmark would append /repeats:N to a per-benchmark count).
        counts = sorted({repetitions_of(a, c["workload"]) for c in cases}, reverse=True) or [a.repetitions]
        for n in counts:
            part = [c for c in cases if repetitions_of(a, c["workload"]) == n]
            plans.append((g, label if n == counts[0] else f"{label}-r{n}", part, n))
    total = sum(len(cs) * n for _, _, cs, n in plans)
    progress = runner.Progress(total)
    rows, bench_files, ctx = list(skipped_rows), [], {}
    with open(os.path.join(work, "bench.log"), "w") as log:
        for g, label, cases, reps in plans:
            if not cases:
                continue
            min_time = a.min_time or (1.0 if any(d["device"] == "gpu" for d in g) else (0.1 if a.quick else 0.5))
            doc = {"suite": "pathbench", "version": m["version"], "mode": mode, "manifest_sha256": m["sha256"],
                   "device_label": "-".join(d["label"] for d in g),
                   "cases": [{k: c[k] for k in ("name", "scene", "device", "settings", "iterations") if k in c}
                             for c in cases]}
            env = dict(g[0]["env"]) if len(g) == 1 else {}
            env["PATHBENCH_DATA_DIR"] = manifest.data_dir()
            rc, path = runner.run_device(bench, doc, work, label, reps, min_time, env, progress, log)
            if rank != 0:
                continue
            if rc == 2:
                progress.close()
                raise InputError(f"pathbench-bench refused the suite's cases for {label} (see {out}/bench.log)")
            if rc != 0 or not os.path.exists(path):
                progress.close()
                print(f"pathbench suite: failed: pathbench-bench for {label} exited with {rc}", file=sys.stderr)
                return 3
            bench_doc = runner.read_bench_json(path)
            ctx = ctx or bench_doc.get("context", {})
            final = os.path.join(work, f"suite-{stamp}-{label}.json")
            os.replace(path, final)
            bench_files.append(final)
            for d in g:
                rows += results.rows_from_bench(bench_doc, [c for c in cases if c["device"] == d["device"]], d)
    progress.close()
    if rank != 0:
        return 0
    return _report(a, work, out, m, chosen, rows, bench_files, ctx, mode, preset, db, t0)


def _from_json(a, work, out, m, chosen, mode, preset, db, t0) -> int:
    """--from-json: the page and the records from bench JSON an earlier run wrote (a run cut
    short, or one made on another host): no measurement."""
    rows, files, ctx = [], [], {}
    names = {w["name"]: w for w in chosen}
    for path in a.from_json:
        try:
            doc = _finite(runner.read_bench_json(path, strict=False))
        except (OSError, ValueError) as e:
            raise InputError(f"--from-json {path}: not readable bench JSON ({e})") from None
        if not isinstance(doc, dict) or not isinstance(doc.get("benchmarks"), list):
            raise InputError(f"--from-json {path}: not Google Benchmark JSON")
        ctx = ctx or doc.get("context", {})
        seen = {}
        for b in doc["benchmarks"]:
            parts = str(b.get("run_name", b.get("name", ""))).split("/")
            if len(parts) >= 4 and parts[0] == "suite" and parts[1] in names:
                seen.setdefault((parts[1], parts[2], parts[3]), None)
        for (wl, label, strategy) in seen:
            dev = {"label": label, "device": "gpu" if "gpu" in label else "cpu",
                   "name": doc.get("context", {}).get("gpu_name", "") if "gpu" in label else "CPU"}
            case = runner.cases_for([names[wl]], dev, mode == "quick", None, manifest.data_dir())[0]
            rows += results.rows_from_bench(doc, [case], dev)
        dest = os.path.join(work, os.path.basename(path))
        shutil.copyfile(path, dest)
        files.append(dest)
    have = {r["workload"] for r in rows}
    for w in chosen:
        if w["name"] not in have:
            rows.append({"workload": w["name"], "device": "-", "status": "skipped",
                         "reason": "not measured: no result for it in the bench JSON given"})
    return _report(a, work, out, m, chosen, rows, files, ctx, mode, preset, db, t0)


def _report(a, work, out, m, chosen, rows, bench_files, ctx, mode, preset, db, t0) -> int:
    order = {w["name"]: i for i, w in enumerate(chosen)}
    rows.sort(key=lambda r: (order.get(r["workload"], 0), r["device"]))
    if db:
        os.makedirs(os.path.dirname(os.path.abspath(db)), exist_ok=True)
        _record(db, bench_files, a)
        prev = results.previous_runs(db, [os.path.basename(f) for f in bench_files], preset)
        for r in rows:
            p = prev.get(results.series(r.get("benchmark", "")))
            if p and r["status"] == "ok":
                r["previous"] = results.verdict(r["times_ms"], p["times_ms"]) | {"run_date": p["run_date"],
                                                                                 "commit": p["commit"]}
    sources = {os.path.basename(f) for f in bench_files}
    refs = results.reference_runs(a.references, preset, sources) if a.references and os.path.isdir(a.references) else {}
    ref_names = sorted(n for n, per in refs.items() if any(results.series(r.get("benchmark", "")) in per for r in rows))
    for r in rows:
        for n in ref_names:
            ref = refs[n].get(results.series(r.get("benchmark", "")))
            if ref:
                r.setdefault("references", {})[n] = {"ms": results._median(ref["times_ms"]), "run_date": ref["run_date"],
                                                     "commit": ref["commit"]}
    name = a.machine or ctx.get("machine", "this machine")
    gpus = sorted({r.get("device_name") for r in rows if r["device"].startswith("gpu") and r.get("device_name")})
    if gpus and not a.machine:
        name = f"{', '.join(gpus)} ({name} host)"
    summary = {"suite": "pathbench", "version": m["version"], "mode": mode, "preset": preset,
               "date": dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
               "machine": {"name": name, "machine_id": ctx.get("machine_id"), "cpu": ctx.get("cpu_model"),
                           "fingerprint": ctx.get("fingerprint")},
               "git_revision": ctx.get("git_revision"), "manifest": os.path.relpath(m["path"], ROOT)
               if m["path"].startswith(ROOT) else m["path"], "manifest_sha256": m["sha256"],
               "repetitions": a.repetitions, "db": db, "reference_machines": ref_names,
               "command": "pathbench suite " + " ".join(sys.argv[1:]),
               "bench_json": [os.path.basename(f) for f in bench_files], "rows": rows,
               "workloads": [dict(w, run_settings=manifest.run_settings(w, a.quick),
                                  triangles=max(w["triangles"], manifest.triangle_estimate(w, manifest.data_dir(), a.quick)[0]),
                                  instanced_triangles=max(w["instanced_triangles"],
                                                          manifest.triangle_estimate(w, manifest.data_dir(), a.quick)[1]))
                             for w in chosen]}
    fewer = sorted({f"{r['workload']} {r['repetitions']}" for r in rows
                    if r["status"] == "ok" and r.get("repetitions", a.repetitions) < a.repetitions})
    summary["facts"] = _facts(summary, ctx, None if t0 is None else time.monotonic() - t0,
                              a.repetitions if not fewer else f"{a.repetitions} (fewer: {', '.join(fewer)})")
    summary = _finite(summary)
    with open(os.path.join(work, "suite.json"), "w") as f:
        json.dump(summary, f, indent=1, allow_nan=False)
        f.write("\n")
    page.write_html(os.path.join(work, "index.html"), summary)
    page.write_markdown(os.path.join(work, "suite.md"), summary)
    os.makedirs(out, exist_ok=True)
    for n in os.listdir(work):
        os.replace(os.path.join(work, n), os.path.join(out, n))
    print(_table(rows))
    print(f"\npage: {os.path.join(out, 'index.html')} (and suite.md, suite.json, the bench JSON)")
    return 0


def main(argv=None) -> int:
    try:
        return run(parse_args(argv if argv is not None else sys.argv[1:]))
    except (InputError, manifest.ManifestError, devices.DeviceError) as e:
        print(f"pathbench suite: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("pathbench suite: interrupted; nothing written", file=sys.stderr)
        return 130
    except BrokenPipeError:  # `pathbench suite --list | head`
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as e:
        print(f"pathbench suite: failed: {e}", file=sys.stderr)
        return 3
