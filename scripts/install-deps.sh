#!/usr/bin/env bash
# Installs everything pathbench needs on Debian 12: build tools and libraries from
# apt, Python tools into .venv. Safe to run twice: it installs only what is missing.
#   scripts/install-deps.sh            libraries + Python tools
#   PATHBENCH_SKIP_VENV=1 scripts/install-deps.sh   libraries only
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

apt_pkgs=(build-essential cmake ninja-build ccache pkg-config git python3 python3-venv
          libembree-dev libtbb-dev libopenimageio-dev openimageio-tools
          librandom123-dev libcli11-dev nlohmann-json3-dev libtinyobjloader-dev libtinygltf-dev libpugixml-dev
          libfmt-dev libgtest-dev libgmock-dev googletest libbenchmark-dev
          python3-dev  # the `pathbench` Python module (python/; pybind11 from PyPI: tools/requirements.txt)
          libllvm19  # libllvm19: Mitsuba 3 llvm_ad_rgb, the reference and speed comparison
          clang libfuzzer-14-dev  # the fuzz targets (scripts/fuzz.sh): libFuzzer + ASan + UBSan
          valgrind chromium  # history: instruction counts; the dashboard's headless-browser test
          openmpi-bin libopenmpi-dev)  # MPI ranks (PATHBENCH_MPI, issue 13): mpirun and mpicxx
missing=()
for p in "${apt_pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "[install-deps] apt-get install: ${missing[*]}"
  sudo_cmd=(); [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "[install-deps] apt packages: all present"
fi
# The suite's meshes (Debian libcgal-demo) into the data folder: scripts/install-suite-data.sh.
"$root/scripts/install-suite-data.sh" ||
  echo "[install-deps] warning: the suite's meshes are not installed (above); the workloads that need them are skipped"

if [ "${PATHBENCH_SKIP_VENV:-0}" != 1 ]; then
  if [ ! -x "$root/.venv/bin/python" ]; then
    echo "[install-deps] creating .venv"
    python3 -m venv "$root/.venv"
  fi
  req="$root/tools/requirements.txt"
  # Installed without their declared dependencies (see the file's header): apache-otava pins
  # numpy/scipy and pulls cloud clients that its change-point code does not use.
  nodeps="$root/tools/requirements-nodeps.txt"
  stamp="$root/.venv/.requirements.sha"
  sum=$(cat "$req" "$nodeps" | sha256sum | cut -d' ' -f1)
  if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$sum" ]; then
    echo "[install-deps] pip install -r tools/requirements.txt"
    "$root/.venv/bin/python" -m pip install -q --upgrade pip
    "$root/.venv/bin/python" -m pip install -q -r "$req"
    "$root/.venv/bin/python" -m pip install -q --no-deps -r "$nodeps"
    echo "$sum" > "$stamp"
  else
    echo "[install-deps] .venv: up to date"
  fi
fi
# NCCL (the GPU ranks' film reduction on the GPUs, PATHBENCH_NCCL, issue 30): where neither the
# system nor .venv has nccl.h, NVIDIA's wheel (nvidia-nccl-cu13, ~300 MB: nccl.h + libnccl.so.2)
# goes into .venv, where cmake/FindNCCL.cmake looks. PATHBENCH_SKIP_NCCL=1: not installed.
if [ "${PATHBENCH_SKIP_VENV:-0}" != 1 ] && [ "${PATHBENCH_SKIP_NCCL:-0}" != 1 ] && [ -x "$root/.venv/bin/python" ] &&
   ! ls /usr/include/nccl.h /usr/local/include/nccl.h /usr/local/cuda/include/nccl.h \
        "$root"/.venv/lib/python3*/site-packages/nvidia/nccl/include/nccl.h >/dev/null 2>&1; then
  echo "[install-deps] pip install nvidia-nccl-cu13 (NCCL headers and library)"
  "$root/.venv/bin/python" -m pip install -q --no-deps nvidia-nccl-cu13==2.32.3
fi
echo "[install-deps] done"
