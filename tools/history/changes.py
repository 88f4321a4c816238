"""`pathbench history changes`: change points per (benchmark, machine) series with Apache Otava
(apache-otava, PyPI; its `compute_change_points`: e-divisive means over sliding windows with a
Student t-test merge, Fleming et al. 2023, as MongoDB's performance CI uses it).

A series is one point per recorded run, ordered by commit date: the median of the run's
repetitions of the benchmark's value (real time, or instructions per sample), lower is better.
Instruction counts (unit "instructions", callgrind) have no noise: a run repeated gives the same
count, so Otava's tests have nothing to weigh (segments of one run each give no variance and a
staircase of consecutive improvements merges into one step). For those series every step between
consecutive runs larger than min_change is reported as it is (`method` "exact", `p_value` null);
`exact=False` (CLI --otava-only) sends them through Otava too.

A change point is reported with the first run after it (`commit`) and the last one before it
(`previous_commit`); `change` is mean after / mean before - 1 (+ is slower), `p_value` Otava's
t-test between the two segments. Points with p >= max_pvalue or |change| <= min_change are merged
away by Otava itself.
"""
from __future__ import annotations

import math
import re
import statistics
from dataclasses import asdict, dataclass

from . import store
from .text import md_cell, term

DEFAULT_MAX_PVALUE = 1e-4  # 0 false positives in 100 noise-only series (false_positives.py)
DEFAULT_MIN_CHANGE = 0.005  # 0.5%: below it, a step is not worth a reviewer's time
WINDOW = 50


@dataclass
class Point:
    run_id: int
    commit: str
    date: str
    values: list[float]

    @property
    def median(self) -> float:
        return median(self.values)


def median(values: list[float]) -> float:
    """statistics.median, but halves added (not the sum halved): no overflow near the double range."""
    s = sorted(values)
    n = len(s)
    return s[n // 2] if n % 2 else s[n // 2 - 1] / 2 + s[n // 2] / 2


def mean(values: list[float]) -> float:
    """The mean, computed in units of the largest magnitude so that huge values cannot overflow."""
    scale = max((abs(v) for v in values), default=0.0) or 1.0
    return statistics.fmean(v / scale for v in values) * scale


@dataclass
class Change:
    benchmark: str
    machine: str
    machine_id: str
    preset: str
    commit: str
    previous_commit: str
    index: int
    change: float
    p_value: float | None
    mean_before: float
    mean_after: float
    regression: bool
    method: str = "otava"


def series(db, benchmark: str | None = None, machine: str | None = None) -> dict[tuple[str, str, str], list[Point]]:
    """{(benchmark, machine_id, preset): points in commit order}; machine matches a machine's name or id
    prefix. The preset is part of the key: one benchmark name under two presets measures different work."""
    rows = db.execute(
        "SELECT r.benchmark, u.machine_id, COALESCE(u.preset, ''), u.id, u.commit_sha, COALESCE(u.commit_date, u.run_date), r.value "
        "FROM results r JOIN runs u ON u.id = r.run_id JOIN machines m ON m.id = u.machine_id "
        "WHERE r.value IS NOT NULL AND (? IS NULL OR m.name = ? OR m.id LIKE ? || '%') "
        "ORDER BY COALESCE(u.commit_date, u.run_date), u.commit_seq, u.run_date, u.id, r.repetition",
        (machine, machine, machine)).fetchall()
    pattern = re.compile(benchmark) if benchmark else None
    out: dict[tuple[str, str], list[Point]] = {}
    for bench, mid, preset, rid, commit, date, value in rows:
        if not isinstance(value, (int, float)) or not math.isfinite(value) or not isinstance(bench, str):
            # Only a database edited by hand (or damaged) holds these: record never writes them.
            raise store.UserError(f"the database holds a value that is not a number (run {rid}, {str(bench)[:80]}): "
                                  "rebuild it from the run files")
        commit, date, preset = str(commit), str(date), str(preset)
        if pattern and not pattern.search(bench):
            continue
        pts = out.setdefault((bench, mid, preset), [])
        if pts and pts[-1].run_id == rid:
            pts[-1].values.append(value)
        else:
            pts.append(Point(rid, commit, date, [value]))
    return out


def detect(values: list[float], max_pvalue: float = DEFAULT_MAX_PVALUE, min_change: float = DEFAULT_MIN_CHANGE):
    """[(index of the first point after the change, relative change, p)] by Otava."""
    if len(values) < 3:
        return []
    if max(values) == min(values):
        return []  # a flat series (instruction counts of unchanged code): Otava's t-test would give NaN
    from otava.analysis import compute_change_points  # imported late: `record` works without it
    # Relative changes and the t-test do not depend on the unit: scaled to the largest value, a
    # series of huge numbers cannot overflow inside Otava.
    scale = max(abs(v) for v in values) or 1.0
    cps, _ = compute_change_points([float(v) / scale for v in values], window_len=WINDOW, max_pvalue=max_pvalue,
                                   min_magnitude=min_change)
    out = [(int(c.index), float(c.stats.forward_rel_change()), float(c.stats.pvalue)) for c in cps]
    return [o for o in out if math.isfinite(o[1]) and math.isfinite(o[2])]


def exact_steps(values: list[float], min_change: float = DEFAULT_MIN_CHANGE):
    """[(index, relative change, None)] wherever a noise-free value moves by more than min_change."""
    steps = [(i, values[i] / values[i - 1] - 1, None) for i in range(1, len(values)) if values[i - 1]]
    return [s for s in steps if math.isfinite(s[1]) and abs(s[1]) > min_change]


def find(db, benchmark=None, machine=None, max_pvalue=DEFAULT_MAX_PVALUE, min_change=DEFAULT_MIN_CHANGE,
         exact: bool = True) -> list[Change]:
    names = {k: str(v) for k, v in db.execute("SELECT id, name FROM machines").fetchall()}
    units = dict(db.execute("SELECT benchmark, MAX(unit) FROM results GROUP BY benchmark").fetchall())
    found = []
    for (bench, mid, preset), pts in sorted(series(db, benchmark, machine).items()):
        medians = [p.median for p in pts]
        deterministic = exact and units.get(bench) == "instructions"
        steps = exact_steps(medians, min_change) if deterministic else detect(medians, max_pvalue, min_change)
        bounds = [0] + [i for i, _, _ in steps] + [len(medians)]
        for k, (idx, change, p) in enumerate(steps):
            # Means of the segments on either side (between neighbouring change points).
            before, after = medians[bounds[k]:idx], medians[idx:bounds[k + 2]]
            found.append(Change(bench, names[mid], mid, preset, pts[idx].commit, pts[idx - 1].commit, idx, change, p,
                                mean(before), mean(after), change > 0,
                                "exact" if deterministic else "otava"))
    return found


def newest_after_regression(changes: list[Change]) -> list[Change]:
    """Per series, its last change point if it is a regression: the newest run still sits after it."""
    last: dict[tuple[str, str, str], Change] = {}
    for c in changes:
        key = (c.benchmark, c.machine_id, c.preset)
        if key not in last or c.index > last[key].index:
            last[key] = c
    return [c for c in last.values() if c.regression]


def as_json(changes: list[Change]) -> list[dict]:
    return [asdict(c) for c in changes]


def format_table(changes: list[Change]) -> str:
    """For a terminal: names escaped (text.term), so a name cannot forge or hide a line."""
    if not changes:
        return "no change points"
    lines = [f"{'change':>8}  {'p':>8}  {'commit':12}  {'previous':12}  machine  benchmark"]
    for c in changes:
        p = "exact" if c.p_value is None else f"{c.p_value:8.1e}"
        lines.append(f"{c.change * 100:+7.2f}%  {p:>8}  {term(c.commit[:12]):12}  {term(c.previous_commit[:12]):12}  "
                     f"{term(c.machine)}  {term(c.benchmark)}")
    return "\n".join(lines)


def format_markdown(changes: list[Change]) -> str:
    """A Markdown table (for a pull request or a CI summary): cells escaped (text.md_cell), so a
    `|` or a newline in a name neither splits a cell nor starts a row."""
    if not changes:
        return "no change points"
    lines = ["| change | p | commit | previous | machine | benchmark |", "|---:|---:|---|---|---|---|"]
    for c in changes:
        p = "exact" if c.p_value is None else f"{c.p_value:.1e}"
        lines.append(f"| {c.change * 100:+.2f}% | {p} | `{md_cell(c.commit[:12]).replace('`', '')}` | "
                     f"`{md_cell(c.previous_commit[:12]).replace('`', '')}` | {md_cell(c.machine)} | "
                     f"{md_cell(c.benchmark)} |")
    return "\n".join(lines)
