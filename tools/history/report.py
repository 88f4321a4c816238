"""`pathbench history report --out DIR`: a static dashboard (index.html + dashboard.js + data
inline; no server, nothing fetched from the network). Its first screen: the headline plots (the
paper frame, and the suite, per machine and device over commits, with change points); below it the
latest-against-baseline table (collapsed) and every series. Per benchmark and machine: time (and rays/s
where recorded) over commits, every repetition drawn beside the median so the spread shows, change
points marked with their commit, the latest run against the first (the baseline) and against the
segment before its last change point; CPU and GPU series of one benchmark side by side. The plots
are SVG drawn by dashboard.js (ours, ~200 lines), so the page works offline and in CI's headless
chromium. PNG copies of the series with change points (matplotlib) go to DIR/png/ for the README.
"""
from __future__ import annotations

import html
import json
import math
import os
import re
import shutil
import subprocess
import tempfile
import urllib.parse

from . import changes as cp
from .store import TEMPORARY, UserError, remove_temporary_one
from .text import script_json

HERE = os.path.dirname(os.path.abspath(__file__))
MAX_PNG = 16


def _subjects(repo: str | None, commits: set[str]) -> dict[str, str]:
    if not repo or not commits:
        return {}
    try:
        r = subprocess.run(["git", "-C", repo, "log", "--all", "--format=%H %s"], capture_output=True, text=True,
                           timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return {}
    out = {}
    for line in r.stdout.splitlines():
        sha, _, subject = line.partition(" ")
        if sha in commits:
            out[sha] = subject[:160]
    return out


# The plots people look for first: (label, benchmark pattern, preset or None). The paper frame is
# the 2015 paper's render (256x256, 800 spp, 2 bounces, uniform hemisphere sampling) by every
# strategy; the suite is every series recorded under the suite preset.
HEADLINES = (
    ("paper frame", re.compile(r"^render/(cpu|gpu)/[^/]+/paper-cornell/256x256/spp:800/bounces:2/uniform(/|$)"), None),
    ("suite", re.compile(r""), "suite"),
)
MAX_HEADLINE = 24


def _headline(bench: str, preset: str) -> str:
    for label, pattern, want in HEADLINES:
        if (want is None or preset == want) and pattern.search(bench):
            return label
    return ""


def check_commit_url(url: str | None) -> str:
    """--commit-url: empty, or an http(s) URL with at most one `{}` (the commit goes there,
    percent-encoded); anything else (javascript:, quotes, spaces, control characters) is refused."""
    if not url:
        return ""
    bad = re.search(r"[\x00-\x20\x7f-\x9f\"'<>\\^`|]", url)
    try:
        parts = urllib.parse.urlsplit(url.replace("{}", "0"))
        parts.port  # noqa: B018  (raises on a port that is not a number)
    except ValueError:  # "https://[::1" and other hosts urllib cannot split
        bad = True
        parts = urllib.parse.urlsplit("")
    if bad or parts.scheme.lower() not in ("http", "https") or not parts.netloc or url.count("{}") > 1 \
            or re.search(r"[{}]", url.replace("{}", "")):
        raise UserError(f"--commit-url: {url[:80]!r} is not an http(s) URL template (like https://host/repo/commit/{{}})")
    return url


def _finite(v):
    return v if v is not None and math.isfinite(v) else None


def _group_key(benchmark: str) -> tuple[str, str]:
    """('render/{device}/pixel/...', 'cpu') so the CPU and GPU series of one benchmark pair up."""
    m = re.search(r"(^|/)(cpu|gpu)(/|$)", benchmark)
    if not m:
        return benchmark, ""
    return benchmark[: m.start(2)] + "{device}" + benchmark[m.end(2):], m.group(2)


def collect(db, repo: str | None = None, benchmark: str | None = None, max_pvalue=cp.DEFAULT_MAX_PVALUE,
            min_change=cp.DEFAULT_MIN_CHANGE) -> dict:
    machines = dict(db.execute("SELECT id, name FROM machines").fetchall())
    units = dict(db.execute("SELECT benchmark, MIN(unit) FROM results GROUP BY benchmark").fetchall())
    rays = {}
    for rid, bench, value in db.execute("SELECT run_id, benchmark, rays_per_second FROM results "
                                        "WHERE rays_per_second IS NOT NULL ORDER BY repetition"):
        rays.setdefault((rid, bench), []).append(value)
    all_series = cp.series(db, benchmark)
    subjects = _subjects(repo, {p.commit for pts in all_series.values() for p in pts})
    found = cp.find(db, benchmark, max_pvalue=max_pvalue, min_change=min_change)
    by_series: dict[tuple[str, str, str], list] = {}
    for c in found:
        by_series.setdefault((c.benchmark, c.machine_id, c.preset), []).append(c)
    series = []
    for (bench, mid, preset), pts in sorted(all_series.items()):
        group, device = _group_key(bench)
        medians = [p.median for p in pts]
        chs = sorted(by_series.get((bench, mid, preset), []), key=lambda c: c.index)
        since = chs[-1].index if chs else 0
        before_last = medians[chs[-2].index if len(chs) > 1 else 0: chs[-1].index] if chs else []
        series.append({
            "id": f"s{len(series)}", "benchmark": bench, "group": group, "device": device,
            "headline": _headline(bench, preset),
            "machine": machines[mid], "machine_id": mid, "preset": preset, "unit": units.get(bench, ""),
            "points": [{"commit": p.commit, "date": p.date, "subject": subjects.get(p.commit, ""),
                        "values": p.values, "median": p.median, "rays": rays.get((p.run_id, bench), [])}
                       for p in pts],
            "changes": [{"index": c.index, "commit": c.commit, "previous_commit": c.previous_commit,
                         "change": c.change, "p_value": c.p_value} for c in chs],
            "latest": medians[-1], "baseline": medians[0],
            "latest_vs_baseline": _finite(medians[-1] / medians[0] - 1) if medians[0] else None,
            "latest_vs_before_last_change": _finite(cp.mean(medians[since:]) / cp.mean(before_last) - 1)
            if before_last and cp.mean(before_last) else None,
        })
    chosen = [s for s in series if s["headline"]]
    for s in chosen[MAX_HEADLINE:]:
        s["headline"] = ""
    return {"series": series, "changes": cp.as_json(found)}


def _png(series: dict, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    with matplotlib.rc_context({"text.parse_math": False, "text.usetex": False}):  # names are not TeX: `$` is text
        _png_plot(series, path)


def _png_plot(series: dict, path: str) -> None:
    import matplotlib.pyplot as plt
    pts = series["points"]
    # Drawn in a power of ten of the unit where values are extreme: matplotlib's transforms
    # overflow near the double range (and lose the axis below 1e-300).
    top = max((abs(v) for p in pts for v in p["values"]), default=0.0)
    exp = math.floor(math.log10(top)) if top and not 1e-6 <= top <= 1e12 else 0
    k = 10.0 ** -exp if -300 < exp < 300 else None
    scaled = (lambda v: v * k) if k else (lambda v: v / 10.0 ** (exp // 2) / 10.0 ** (exp - exp // 2))
    fig, ax = plt.subplots(figsize=(9, 3.2), dpi=100)
    for i, p in enumerate(pts):
        ax.plot([i] * len(p["values"]), [scaled(v) for v in p["values"]], ".", color="#9bb7d4", ms=4)
    ax.plot(range(len(pts)), [scaled(p["median"]) for p in pts], "-", color="#1f4e79", lw=1.5)
    for c in series["changes"]:
        ax.axvline(c["index"] - 0.5, color="#c0392b" if c["change"] > 0 else "#1e8449", ls="--", lw=1)
        ax.annotate(f"{c['commit'][:7]} {c['change'] * 100:+.1f}%", (c["index"] - 0.4, ax.get_ylim()[1]),
                    va="top", fontsize=8, color="#333")
    step = max(1, len(pts) // 20)
    ax.set_xticks(range(0, len(pts), step), [pts[i]["commit"][:7] for i in range(0, len(pts), step)],
                  rotation=60, fontsize=7)
    ax.set_ylabel(series["unit"] + (f" x 1e{exp}" if exp else ""))
    ax.set_title(f"{series['benchmark']}  [{series['machine']} {series['machine_id'][:6]}, {series['preset']}]",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def png_name(series: dict) -> str:
    key = f"{series['machine']}_{series['preset']}_{series['benchmark']}"
    name = re.sub(r"[^A-Za-z0-9]+", "_", key).strip("_")[:150] or "series"
    if len(name) == 150 or name == "series":  # a long or unprintable name: unique and within NAME_MAX
        import hashlib
        name += "_" + hashlib.sha256(f"{series['machine_id']}\0{key}".encode("utf-8", "backslashreplace")).hexdigest()[:10]
    return name + ".png"


def _page(data: dict) -> str:
    blob = script_json(data)
    n_changes = len(data["changes"])
    machines = sorted({s["machine"] for s in data["series"]})
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>pathbench performance history</title>
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:">
<link rel="stylesheet" href="dashboard.css"></head>
<body>
<h1>pathbench performance history</h1>
<p>{len(data['series'])} series on {len(machines)} machine(s): {html.escape(', '.join(machines))};
{n_changes} change point(s). Lower is better in every plot but rays/s. Dots: repetitions; line: median per run;
dashed: change points (red slower, green faster).</p>
<div id="headline"></div>
<details id="summary-box"><summary><b>Latest against baseline</b>, every series (baseline: the first run of the series)</summary>
<table id="summary"></table></details>
<h2>Every series</h2>
<div id="plots"></div>
<script id="history-data" type="application/json">{blob}</script>
<script src="dashboard.js"></script>
</body></html>
"""


def write_site(db, out: str, commit_url: str = "", png: bool = True, repo: str | None = None,
               benchmark: str | None = None) -> int:
    """The site is made in a temporary folder beside `out`, then moved in file by file: a failure
    (a name matplotlib cannot draw, a full disk) leaves `out` as it was and no temporary folder."""
    data = collect(db, repo, benchmark)
    data["commit_url"] = check_commit_url(commit_url)
    if os.path.exists(out) and not os.path.isdir(out):
        raise UserError(f"{out}: exists and is not a folder (--out)")
    parent = os.path.dirname(os.path.abspath(out))
    os.makedirs(parent, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="." + os.path.basename(os.path.abspath(out)) + ".", dir=parent)
    TEMPORARY.add(tmp)
    try:
        for name in ("dashboard.js", "dashboard.css"):
            shutil.copy(os.path.join(HERE, name), os.path.join(tmp, name))
        with open(os.path.join(tmp, "data.json"), "w", encoding="utf-8") as f:
            json.dump(data, f, indent=1, allow_nan=False)
        with open(os.path.join(tmp, "index.html"), "w", encoding="utf-8") as f:
            f.write(_page(data))
        names = ["dashboard.js", "dashboard.css", "data.json", "index.html"]
        if png:
            os.makedirs(os.path.join(tmp, "png"))
            ranked = sorted((s for s in data["series"] if len(s["points"]) > 1),
                            key=lambda s: (not s["headline"], not s["changes"], s["benchmark"]))
            for s in ranked[:MAX_PNG]:
                name = os.path.join("png", png_name(s))
                _png(s, os.path.join(tmp, name))
                names.append(name)
        os.makedirs(os.path.join(out, "png") if png else out, exist_ok=True)
        for name in names:
            os.replace(os.path.join(tmp, name), os.path.join(out, name))
    finally:
        remove_temporary_one(tmp)
    return len(data["series"])
