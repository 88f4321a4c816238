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
import re
import signal
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


class BadInput(Exception):
    """Input this tool cannot judge: one line for the user, exit status 2."""


def shown(text) -> str:
    """`text` for a terminal: control characters, C1 controls and invisible reordering
    code points escaped (a file name or a Mitsuba message is data, not terminal input)."""
    out = []
    for c in str(text):
        o = ord(c)
        if o < 0x20 or o == 0x7F or 0x80 <= o <= 0x9F or o in INVISIBLE:
            out.append({"\n": "\\n", "\r": "\\r", "\t": "\\t", "\x1b": "\\e"}.get(
                c, f"\\x{o:02x}" if o < 0x80 else f"\\u{{{o:x}}}"))
        elif 0xD800 <= o <= 0xDFFF:  # a byte that was not UTF-8 (surrogateescape)
            out.append(f"\\x{o - 0xDC00:02x}" if o >= 0xDC80 else f"\\u{{{o:x}}}")
        else:
            out.append(c)
    return "".join(out)


INVISIBLE = {0x061C, 0x200E, 0x200F, 0x2028, 0x2029, 0xFEFF, *range(0x202A, 0x202F), *range(0x2066, 0x206A)}
MAX_SPP = 2**32 - 1       # Mitsuba's sample count is a 32-bit unsigned integer
MAX_PASSES = 4096
DEVICE = re.compile(r"[a-z0-9_]{1,32}")  # names a file (diff-DEVICE.pfm): no path in it


def pathbench_integrator(bounces: int) -> dict:
    """What `pathbench render` renders a scene without an <integrator> with: --bounces N
    and light sampling + MIS is Mitsuba's `path` with max_depth N + 1 and no Russian
    roulette; unbounded (-1) is max_depth -1, ended by Russian roulette."""
    if bounces < 0:
        return {"type": "path", "max_depth": -1, "hide_emitters": False}
    return {"type": "path", "max_depth": bounces + 1, "rr_depth": bounces + 101, "hide_emitters": False}


def rgb(image: np.ndarray) -> np.ndarray:
    """Mitsuba's film as (height, width, 3): luminance repeated, alpha and AOVs dropped."""
    a = np.asarray(image, dtype=np.float32)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3 or a.shape[2] == 0:
        raise BadInput(f"Mitsuba's film has shape {a.shape}, not an image")
    return np.repeat(a[:, :, :1], 3, axis=2) if a.shape[2] < 3 else a[:, :, :3]


def render_mitsuba(xml: Path, variant: str, spp: int, passes: int, bounces: int = 2):
    mi = ms.import_mitsuba(variant)
    try:
        scene = mi.load_file(str(xml))
        # A scene without an <integrator> renders in pathbench (its defaults); Mitsuba's
        # render() refuses one, so it gets pathbench's estimator.
        integrator = scene.integrator() or mi.load_dict(pathbench_integrator(bounces))
        each = max(1, spp // passes)
        images = np.stack([rgb(mi.render(scene, integrator=integrator, spp=each, seed=i)) for i in range(passes)])
    except BadInput:
        raise
    except Exception as e:  # Mitsuba's parser and plugins: the message names the file and what is wrong
        raise BadInput(f"Mitsuba cannot render {xml}: {str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__}") from None
    return images.mean(0), images.var(0, ddof=1) / passes, each * passes


def check_arguments(a) -> None:
    if not a.image:
        raise BadInput("no --image given")
    if not 1 <= a.spp <= MAX_SPP:
        raise BadInput(f"--spp {a.spp}: must be 1 to {MAX_SPP} (Mitsuba's sample count is 32 bits)")
    if not 2 <= a.passes <= MAX_PASSES:
        raise BadInput(f"--passes {a.passes}: must be 2 to {MAX_PASSES}")
    if not (math.isfinite(a.mean_tolerance) and a.mean_tolerance >= 0):
        raise BadInput(f"--mean-tolerance {a.mean_tolerance}: must be a finite number >= 0")
    if a.out_dir.exists() and not a.out_dir.is_dir():
        raise BadInput(f"--out-dir {a.out_dir}: is a file, not a directory")


def read_images(specs):
    images = {}
    for spec in specs:
        device, sep, path = spec.partition("=")
        if not sep or not DEVICE.fullmatch(device):
            raise BadInput(f"--image {spec}: expected DEVICE=FILE.pfm, DEVICE of a-z, 0-9 and _")
        if device in images:
            raise BadInput(f"--image {spec}: device {device} given twice")
        p = Path(path)
        var = p.with_name(p.stem + "-var.pfm")
        try:
            images[device] = (ms.read_pfm(p), ms.read_pfm(var))
        except (OSError, ValueError) as e:
            raise BadInput(f"{p}: {e}") from None
        if images[device][0].shape != images[device][1].shape:
            raise BadInput(f"{var}: {images[device][1].shape[1]}x{images[device][1].shape[0]}, its image "
                           f"{images[device][0].shape[1]}x{images[device][0].shape[0]}")
    return images


def write_outputs(out_dir: Path, files: dict, verdict: dict) -> None:
    """All of a run's files, or (on any failure, a signal included) none of them: what
    this call created, the folders included, is removed again before the error goes on."""
    created = [p for p in [out_dir, *out_dir.parents] if not p.exists()]
    written = []
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        for name, image in files.items():
            written.append(out_dir / name)
            ms.write_pfm(out_dir / name, image)
        written.append(out_dir / "verdict.json")
        tmp = out_dir / "verdict.json.tmp"
        tmp.write_text(json.dumps(verdict, indent=2) + "\n")
        tmp.replace(out_dir / "verdict.json")
    except BaseException as e:
        for p in written:
            for q in (p, p.with_name(p.name + ".tmp")):
                q.unlink(missing_ok=True)
        for d in created:  # innermost first
            try:
                d.rmdir()
            except OSError:
                pass
        if isinstance(e, OSError):
            raise BadInput(f"--out-dir {out_dir}: {e.strerror or e}") from None
        raise


def run(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--xml", type=Path, required=True, help="the Mitsuba 3 scene")
    ap.add_argument("--image", action="append", default=[], metavar="DEVICE=FILE.pfm",
                    help="a pathbench image (FILE-var.pfm beside it: its variance of the mean)")
    ap.add_argument("--spp", type=int, default=256, help="Mitsuba's samples per pixel in all")
    ap.add_argument("--pathbench-spp", type=int, default=0, help="for the record")
    ap.add_argument("--passes", type=int, default=16, help="independent Mitsuba renders (variance)")
    ap.add_argument("--bounces", type=int, default=2,
                    help="pathbench's bounces, for a scene without an <integrator> (-1: unbounded)")
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--mean-tolerance", type=float, default=0.02, help="per-channel image mean, relative")
    ap.add_argument("--scene", default="", help="for the record")
    ap.add_argument("--out-dir", type=Path, required=True)
    a = ap.parse_args(argv)
    check_arguments(a)
    images = read_images(a.image)
    try:
        ref, var_ref, spp = render_mitsuba(a.xml, a.variant, a.spp, a.passes, a.bounces)
    except ModuleNotFoundError as e:
        raise BadInput(f"Mitsuba 3 is not installed ({e}); scripts/install-deps.sh installs it") from None
    except ImportError as e:
        if "unsupported variant" in str(e):
            raise BadInput(f"--variant {a.variant}: not a variant this Mitsuba has") from None
        # Installed, but it failed to load (seen: another Embree first on LD_LIBRARY_PATH).
        raise BadInput(f"Mitsuba 3 is installed but failed to load ({e}); a library it needs may be missing or "
                       f"shadowed (LD_LIBRARY_PATH={os.environ.get('LD_LIBRARY_PATH', '')!r})") from None
    verdict = {"scene": a.scene, "mitsuba_xml": str(a.xml), "mitsuba_spp": spp, "pathbench_spp": a.pathbench_spp,
               "variant": a.variant, "devices": {}}
    files = {"mitsuba.pfm": ref.astype(np.float32)}
    lines = []
    ok = True
    for device, (ours, var_ours) in images.items():
        if ours.shape != ref.shape:
            raise BadInput(f"pathbench's {device} image is {ours.shape[1]}x{ours.shape[0]}, Mitsuba's "
                           f"{ref.shape[1]}x{ref.shape[0]} (give the film's size)")
        summary, zimg = compare(ours, var_ours, ref, var_ref, a.mean_tolerance)
        files[f"diff-{device}.pfm"] = np.abs(ours - ref).astype(np.float32)
        files[f"z-{device}.pfm"] = np.minimum(zimg, 1e30)
        verdict["devices"][device] = summary
        ok &= summary["pass"]
        r = summary["mean_ratio"]
        lines.append(f"crosscheck: {device}: {'PASS' if summary['pass'] else 'FAIL'}: {100 * summary['share_passed']:.2f} "
                     f"% of {summary['values']} pixel-channels pass (need {100 * MIN_SHARE:.0f} %); image mean / "
                     f"Mitsuba's: R {r[0]:.4f} G {r[1]:.4f} B {r[2]:.4f} (within {a.mean_tolerance:g})")
    write_outputs(a.out_dir, files, verdict)  # only once every check has passed: all of them or none
    for line in lines:
        print(line)
    print(f"crosscheck: {'same up to noise' if ok else 'DIFFERENT'}; images and verdict.json in {shown(a.out_dir)}")
    return 0 if ok else 1


class Stopped(BaseException):
    """SIGINT, SIGTERM or SIGHUP: the run stops, removing what it wrote; exit 128 + N."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def _stop(signum, _frame):
    # The first signal stops the run; later ones (`pathbench crosscheck` passes a signal
    # on, and the terminal may have sent it to both) must not interrupt the cleanup.
    for s in STOP_SIGNALS:
        signal.signal(s, signal.SIG_IGN)
    raise Stopped(signum)


def catch_stop_signals() -> None:
    for s in STOP_SIGNALS:
        if signal.getsignal(s) is not signal.SIG_IGN:  # one ignored by the parent (nohup) stays so
            signal.signal(s, _stop)


def main(argv=None) -> int:
    """Exit status: 0 every device passes, 1 one does not, 2 bad input (one line on
    stderr, nothing written), 3 an internal failure (one line, no traceback), 128 + N
    stopped by signal N (nothing written)."""
    try:
        catch_stop_signals()
        return run(argv)
    except BadInput as e:
        print(f"crosscheck.py: error: {shown(e)}", file=sys.stderr)
        return 2
    except Stopped as e:
        return 128 + e.signum
    except KeyboardInterrupt:
        return 130
    except Exception as e:  # noqa: BLE001 (a bug here: said in one line, never taken for "different")
        print(f"crosscheck.py: internal error: {type(e).__name__}: {shown(e)}", file=sys.stderr)
        return 3


if __name__ == "__main__":
    sys.exit(main())
