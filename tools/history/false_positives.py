"""The false-positive rate of `history changes`: noise-only synthetic histories (no step anywhere)
built from a real bench JSON, recorded into a scratch database and searched for change points with
the default settings. Prints how many of the series got a change point.

  .venv/bin/python -m history.false_positives [--series 100] [--runs 30] [--noise 0.03]
  (run from tools/; results/history/false-positives.txt holds the committed output)
"""
from __future__ import annotations

import argparse
import os
import tempfile

from . import changes, importer, store, synthetic

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TEMPLATE = os.path.join(ROOT, "tests", "data", "bench", "quick-9rep.json")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--series", type=int, default=100)
    ap.add_argument("--runs", type=int, default=30)
    ap.add_argument("--noise", type=float, default=0.03, help="relative sd of the run-level drift (half of it per repetition)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--template", default=TEMPLATE)
    ap.add_argument("--step", type=float, default=0.0,
                    help="instead: a step of this size at the middle run of every series, and count how many are found there (+-1)")
    a = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        db = store.connect(os.path.join(tmp, "h.sqlite"))
        per_machine = None
        machines = 0
        while per_machine is None or machines * per_machine < a.series:
            host = f"noise-{machines}"
            for p in synthetic.write_history(a.template, os.path.join(tmp, host), a.runs, a.noise, a.seed + machines,
                                             host=host, step_at=a.runs // 2 if a.step else None, step=a.step,
                                             stepped=lambda name: True):
                importer.insert(db, importer.parse(p))
            machines += 1
            per_machine = len(changes.series(db)) // machines
        keys = sorted(changes.series(db).keys())[: a.series]
        found = changes.find(db)
        if a.step:
            near = {(c.benchmark, c.machine_id, c.preset) for c in found if abs(c.index - a.runs // 2) <= 1}
            other = {(c.benchmark, c.machine_id, c.preset) for c in found if abs(c.index - a.runs // 2) > 1}
            print(f"detected: {sum(k in near for k in keys)} of {len(keys)} series with a {a.step:+.0%} step at run "
                  f"{a.runs // 2} of {a.runs} (+-1); {sum(k in other for k in keys)} with a change point elsewhere; "
                  f"noise {a.noise:.0%} run-level + {a.noise / 2:.1%} per repetition")
            return 0
        hit = {(c.benchmark, c.machine_id, c.preset) for c in found}
        fp = sum(k in hit for k in keys)
    rate = fp / len(keys)
    from scipy.stats import beta
    upper = float(beta.ppf(0.95, fp + 1, len(keys) - fp))  # one-sided Clopper-Pearson
    print(f"false positives: {fp} of {len(keys)} noise-only series ({rate:.1%}, 95% upper bound {upper:.1%}); "
          f"{a.runs} runs each, noise {a.noise:.0%} run-level + {a.noise / 2:.1%} per repetition (9 repetitions), "
          f"max p {changes.DEFAULT_MAX_PVALUE:g}, min change {changes.DEFAULT_MIN_CHANGE:.1%}, "
          f"template {os.path.relpath(a.template, ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
