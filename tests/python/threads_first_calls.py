"""Run by test_threads.py in a fresh interpreter: N threads make their *first* calls into
`pathbench` at the same moment (load_scene, intersect, occluded, render), so every lazy
initialisation inside the module (numpy's C API table, pybind11's internals, Embree's
device, TBB's arena, the scene caches) is raced. Prints "ok" and exits 0 when every
thread finished; a deadlock shows as a timeout in the caller.

usage: python threads_first_calls.py [THREADS] [DEVICE]   (DEVICE: cpu, the default, or gpu)
"""
import sys
import threading

import numpy as np

import pathbench


def main() -> int:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 8
    device = sys.argv[2] if len(sys.argv) > 2 else "cpu"
    barrier = threading.Barrier(n)
    errors = []

    def work(k: int) -> None:
        try:
            barrier.wait()
            scene = pathbench.load_scene("paper-cornell")
            o = np.zeros((4, 3))  # float64 on purpose: the conversion path is raced too
            d = np.eye(4, 3) + np.float64(k + 1)
            scene.intersect(o, d, backend="embree" if k % 2 else "bvh")
            scene.occluded(o, d)
            image, report = pathbench.render(scene, 8, 8, 1, seed=k, threads=1 + k % 2, device=device)
            assert image.shape == (8, 8, 3) and report["spp"] == 1
        except BaseException as e:  # noqa: BLE001 - reported to the caller below
            errors.append(f"thread {k}: {type(e).__name__}: {e}")

    threads = [threading.Thread(target=work, args=(k,)) for k in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        print("\n".join(errors), file=sys.stderr)
        return 1
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
