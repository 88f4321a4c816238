#!/usr/bin/env python3
"""`pathbench crosscheck`'s second half: renders a Mitsuba 3 scene and judges pathbench's
images (with their variance images) against it, per pixel, as the test suite does
(tests/unit/stat_test.h, compare_images): z = (ours - ref) / sqrt(var_ours + var_ref)
per pixel-channel, two-sided p against a Sidak-corrected alpha of 0.01 over all of
them (values with no variance on either side must agree within 1e-4 relative); a
device passes when at least 99 % of the values pass and every channel's image mean is
within --mean-tolerance of Mitsuba's.

Mitsuba's variance comes from --passes independent renders (seeds 0..passes-1): the
variance of their mean. Writes OUT_DIR/mitsuba.pfm, OUT_DIR/diff-DEVICE.pfm (|ours -
ref|), OUT_DIR/z-DEVICE.pfm (|z| per channel) and OUT_DIR/verdict.json; prints one
verdict line per device. Exit 0: every device passes; 1: one does not; 2: bad input.

    tools/crosscheck.py --xml scene.xml --spp 256 --pathbench-spp 64 --out-dir DIR \
        --image cpu=DIR/pathbench-cpu.pfm   (and DIR/pathbench-cpu-var.pfm beside it)
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mitsuba_scene as ms  # noqa: E402  (read_pfm, write_pfm, import_mitsuba)

MIN_SHARE = 0.99
FAMILY_ALPHA = 0.01
EXACT_TOL = 1e-4


def sidak(alpha: float, tests: int) -> float:
    return 1.0 - (1.0 - alpha) ** (1.0 / tests)


def two_sided_p(z: np.ndarray) -> np.ndarray:
    return np.vectorize(lambda x: math.erfc(abs(x) / math.sqrt(2.0)))(z)


def compare(ours, var_ours, ref, var_ref, mean_tolerance):
    """stat_test.h's compare_images, vectorised; returns (summary dict, |z| image)."""
    o, f = ours.astype(np.float64), ref.astype(np.float64)
    v = var_ours.astype(np.float64) + var_ref.astype(np.float64)
    scale = np.maximum(np.maximum(np.abs(o), np.abs(f)), 1e-3)
    exact = ~(v > (1e-6 * scale) ** 2)
    alpha = sidak(FAMILY_ALPHA, o.size)
    z = np.where(exact, 0.0, (o - f) / np.sqrt(np.where(exact, 1.0, v)))
    p = two_sided_p(z)
    passed = np.where(exact, np.abs(o - f) <= EXACT_TOL * scale, np.isfinite(o) & (p >= alpha))
    mean_o, mean_f = o.reshape(-1, 3).mean(0), f.reshape(-1, 3).mean(0)
    ratio = [float(a / b) if b != 0 else (1.0 if a == 0 else float("inf")) for a, b in zip(mean_o, mean_f)]
    share = float(passed.mean())
    ok = share >= MIN_SHARE and all(abs(r - 1) <= mean_tolerance for r in ratio)
    summary = {"pass": bool(ok), "share_passed": share, "values": int(o.size), "alpha": alpha,
               "min_p": float(p[~exact].min()) if (~exact).any() else 1.0,
               "zero_variance": int(exact.sum()), "zero_variance_failed": int((exact & ~passed).sum()),
               "mean_pathbench": mean_o.tolist(), "mean_mitsuba": mean_f.tolist(), "mean_ratio": ratio}
    return summary, np.where(exact, np.where(passed, 0.0, np.inf), np.abs(z)).astype(np.float32)


def render_mitsuba(xml: Path, variant: str, spp: int, passes: int):
    mi = ms.import_mitsuba(variant)
    scene = mi.load_file(str(xml))
    each = max(1, spp // passes)
    images = np.stack([np.array(mi.render(scene, spp=each, seed=i))[:, :, :3] for i in range(passes)])
    return images.mean(0), images.var(0, ddof=1) / passes, each * passes


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--xml", type=Path, required=True, help="the Mitsuba 3 scene")
    ap.add_argument("--image", action="append", default=[], metavar="DEVICE=FILE.pfm",
                    help="a pathbench image (FILE-var.pfm beside it: its variance of the mean)")
    ap.add_argument("--spp", type=int, default=256, help="Mitsuba's samples per pixel in all")
    ap.add_argument("--pathbench-spp", type=int, default=0, help="for the record")
    ap.add_argument("--passes", type=int, default=16, help="independent Mitsuba renders (variance)")
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--mean-tolerance", type=float, default=0.02, help="per-channel image mean, relative")
    ap.add_argument("--scene", default="", help="for the record")
    ap.add_argument("--out-dir", type=Path, required=True)
    a = ap.parse_args(argv)
    if not a.image:
        print("crosscheck.py: error: no --image given", file=sys.stderr)
        return 2
    if a.passes < 2:
        print("crosscheck.py: error: --passes must be at least 2", file=sys.stderr)
        return 2
    images = {}
    for spec in a.image:
        device, _, path = spec.partition("=")
        p = Path(path)
        var = p.with_name(p.stem + "-var.pfm")
        try:
            images[device] = (ms.read_pfm(p), ms.read_pfm(var))
        except (OSError, ValueError) as e:
            print(f"crosscheck.py: error: {p}: {e}", file=sys.stderr)
            return 2
    try:
        ref, var_ref, spp = render_mitsuba(a.xml, a.variant, a.spp, a.passes)
    except ModuleNotFoundError as e:
        print(f"crosscheck.py: error: Mitsuba 3 is not installed ({e}); scripts/install-deps.sh installs it",
              file=sys.stderr)
        return 2
    except ImportError as e:  # installed, but it failed to load (seen: another Embree first on LD_LIBRARY_PATH)
        print(f"crosscheck.py: error: Mitsuba 3 is installed but failed to load ({e}); a library it needs may be "
              f"missing or shadowed (LD_LIBRARY_PATH={os.environ.get('LD_LIBRARY_PATH', '')!r})", file=sys.stderr)
        return 2
    except RuntimeError as e:  # Mitsuba's parser: the message names the file and line
        print(f"crosscheck.py: error: Mitsuba cannot load {a.xml}: {e}", file=sys.stderr)
        return 2
    a.out_dir.mkdir(parents=True, exist_ok=True)
    ms.write_pfm(a.out_dir / "mitsuba.pfm", ref.astype(np.float32))
    verdict = {"scene": a.scene, "mitsuba_xml": str(a.xml), "mitsuba_spp": spp, "pathbench_spp": a.pathbench_spp,
               "variant": a.variant, "devices": {}}
    ok = True
    for device, (ours, var_ours) in images.items():
        if ours.shape != ref.shape:
            print(f"crosscheck.py: error: pathbench's {device} image is {ours.shape[1]}x{ours.shape[0]}, Mitsuba's "
                  f"{ref.shape[1]}x{ref.shape[0]} (give the film's size)", file=sys.stderr)
            return 2
        summary, zimg = compare(ours, var_ours, ref, var_ref, a.mean_tolerance)
        ms.write_pfm(a.out_dir / f"diff-{device}.pfm", np.abs(ours - ref).astype(np.float32))
        ms.write_pfm(a.out_dir / f"z-{device}.pfm", np.minimum(zimg, 1e30))
        verdict["devices"][device] = summary
        ok &= summary["pass"]
        r = summary["mean_ratio"]
        print(f"crosscheck: {device}: {'PASS' if summary['pass'] else 'FAIL'}: {100 * summary['share_passed']:.2f} % of "
              f"{summary['values']} pixel-channels pass (need {100 * MIN_SHARE:.0f} %); image mean / Mitsuba's: "
              f"R {r[0]:.4f} G {r[1]:.4f} B {r[2]:.4f} (within {a.mean_tolerance:g})")
    (a.out_dir / "verdict.json").write_text(json.dumps(verdict, indent=2) + "\n")
    print(f"crosscheck: {'same up to noise' if ok else 'DIFFERENT'}; images and verdict.json in {a.out_dir}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
