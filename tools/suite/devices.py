"""Which devices `pathbench suite` runs on: the CPU, each visible GPU, MPI ranks when started
under mpirun."""
from __future__ import annotations

import os
import shutil
import subprocess


class DeviceError(ValueError):
    pass


def mpi_world() -> tuple[int, int]:
    """(rank, size) from the launcher's environment (Open MPI, MPICH/PMI, Slurm); (0, 1) alone."""
    for size_key, rank_key in (("OMPI_COMM_WORLD_SIZE", "OMPI_COMM_WORLD_RANK"), ("PMI_SIZE", "PMI_RANK"),
                               ("PMIX_SIZE", "PMIX_RANK")):
        try:
            size = int(os.environ.get(size_key, "1"))
            rank = int(os.environ.get(rank_key, "0"))
        except ValueError:
            continue
        if size > 1:
            return rank, size
    return 0, 1


def build_has_cuda(exe: str) -> tuple[bool, str]:
    try:
        out = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=60).stdout
    except (OSError, subprocess.SubprocessError) as e:
        return False, f"cannot run {exe} --version: {e}"
    if "cuda: on" in out:
        return True, ""
    return False, "this build has no CUDA tracer (configure with -DPATHBENCH_CUDA=ON)"


def visible_gpus() -> tuple[list[dict], str]:
    """[{index, name, id}] of the GPUs CUDA would see (CUDA_VISIBLE_DEVICES honoured), or why none."""
    smi = shutil.which("nvidia-smi")
    if not smi:
        return [], "no nvidia-smi on PATH (no NVIDIA driver)"
    try:
        out = subprocess.run([smi, "--query-gpu=index,name,uuid", "--format=csv,noheader"], capture_output=True,
                             text=True, timeout=60)
    except (OSError, subprocess.SubprocessError) as e:
        return [], f"nvidia-smi failed: {e}"
    if out.returncode != 0:
        return [], f"nvidia-smi failed: {out.stderr.strip() or out.stdout.strip()}"
    gpus = []
    for line in out.stdout.splitlines():
        parts = [p.strip() for p in line.split(",")]
        if len(parts) >= 3:
            gpus.append({"index": parts[0], "name": parts[1], "id": parts[2]})
    visible = os.environ.get("CUDA_VISIBLE_DEVICES")
    if visible is not None:
        keep = [v.strip() for v in visible.split(",") if v.strip()]
        gpus = [g for k in keep for g in gpus if k in (g["index"], g["id"])]
    if not gpus:
        return [], "no GPU visible (nvidia-smi lists none, or CUDA_VISIBLE_DEVICES hides them)"
    return gpus, ""


def plan(exe: str, wanted: str | None) -> tuple[list[dict], list[dict]]:
    """(devices to run, devices skipped with reason). Each device: {label, device, env, name}.
    `wanted`: "cpu,gpu" style; None = every device present. DeviceError for an unknown name,
    or a device asked for by name that is not here."""
    kinds = ["cpu", "gpu"]
    if wanted:
        asked = [w.strip() for w in wanted.split(",") if w.strip()]
        for a in asked:
            if a not in kinds:
                raise DeviceError(f"--devices: unknown device '{a}' (expected cpu, gpu or cpu,gpu)")
        kinds = asked
    run, skipped = [], []
    if "cpu" in kinds:
        run.append({"label": "cpu", "device": "cpu", "env": {}, "name": "CPU"})
    if "gpu" in kinds:
        ok, why = build_has_cuda(exe)
        gpus, why_gpu = visible_gpus() if ok else ([], why)
        if not gpus:
            if wanted:
                raise DeviceError(f"--devices gpu: {why_gpu}")
            skipped.append({"label": "gpu", "reason": why_gpu})
        for g in gpus:
            label = "gpu" if len(gpus) == 1 else f"gpu{g['index']}"
            run.append({"label": label, "device": "gpu", "env": {"CUDA_VISIBLE_DEVICES": g["id"]}, "name": g["name"]})
    return run, skipped
