#!/usr/bin/env bash
# Installs the meshes the suite's workloads need (scenes/suite/manifest.json, "requires")
# into pathbench's data folder: $PATHBENCH_DATA_DIR, else
# ${XDG_DATA_HOME:-$HOME/.local/share}/pathbench/data; meshes go to <data>/meshes/.
# They come from Debian's libcgal-demo (its /usr/share/doc/libcgal-dev/data.tar.gz): the
# installed package's file when there is one, else the .deb fetched with
# `apt-get download libcgal-demo` (24 MB; no root needed, nothing installed system-wide).
# Idempotent and quick: files already there with the right SHA-256 are kept.
#   scripts/install-suite-data.sh          (scripts/install-deps.sh runs it)
set -euo pipefail
data=${PATHBENCH_DATA_DIR:-${XDG_DATA_HOME:-$HOME/.local/share}/pathbench/data}
meshes="$data/meshes"
# name sha256 (libcgal-demo 5.5.1-2, Debian 12)
wanted=(
  "bunny00.off ab651cb04955c161efaeb079035a1e5e1f0e0d1f816a2df67beaea68f393ff2b"
  "armadillo.off 6f7f3ca1abc506569466b72f2f59d49493a284e7376d7a7e23c08115ec8cec4e"
  "ChineseDragon-10kv.off f633bdfaac7a0f99e0fab668c34862f0c26f341cfdb4665bab282d79b788db02"
  "refined_elephant.off a170eed4ef33ef412a72b824d791f69ea59ee5f5a7c12dc1ae9077b6eb030650"
)
ok() { [ -f "$meshes/$1" ] && [ "$(sha256sum "$meshes/$1" | cut -d' ' -f1)" = "$2" ]; }
missing=()
for w in "${wanted[@]}"; do
  set -- $w
  ok "$1" "$2" || missing+=("$1")
done
if ((${#missing[@]} == 0)); then
  echo "[install-suite-data] meshes: all present in $meshes"
  exit 0
fi
mkdir -p "$meshes"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
archive=/usr/share/doc/libcgal-dev/data.tar.gz
if [ ! -f "$archive" ]; then
  echo "[install-suite-data] apt-get download libcgal-demo (the package's data.tar.gz only)"
  if ! (cd "$tmp" && apt-get download -qq libcgal-demo >/dev/null 2>&1); then
    echo "install-suite-data: cannot fetch the Debian package libcgal-demo (apt-get download libcgal-demo" \
         "failed; run apt-get update, or install libcgal-demo, or copy a data folder made by" \
         "scripts/pack-suite-data.sh)" >&2
    exit 2
  fi
  dpkg-deb --fsys-tarfile "$tmp"/libcgal-demo_*.deb | tar -x -C "$tmp" ./usr/share/doc/libcgal-dev/data.tar.gz
  archive="$tmp/usr/share/doc/libcgal-dev/data.tar.gz"
fi
tar -xzf "$archive" -C "$tmp" "${missing[@]/#/data/meshes/}"
for w in "${wanted[@]}"; do
  set -- $w
  [ -f "$tmp/data/meshes/$1" ] || continue
  got=$(sha256sum "$tmp/data/meshes/$1" | cut -d' ' -f1)
  if [ "$got" != "$2" ]; then
    echo "install-suite-data: $1 from libcgal-demo has SHA-256 $got, expected $2 (another package version?)" >&2
    exit 2
  fi
  install -m 644 "$tmp/data/meshes/$1" "$meshes/$1.part" && mv "$meshes/$1.part" "$meshes/$1"
done
cat > "$meshes/SOURCE.txt" <<'TXT'
These meshes come from Debian's libcgal-demo 5.5.1-2 (/usr/share/doc/libcgal-dev/data.tar.gz,
data/meshes/). Licence, as Debian's copyright file for libcgal-dev states it: "All other files
that do not have an explicit copyright notice (e.g., all examples and some demos) are licensed
under the Creative Commons CC0 1.0 license." The files carry no copyright notice; the bunny,
armadillo and dragon are scans from the Stanford 3D Scanning Repository (Stanford University
is among the copyright holders the file lists).
TXT
echo "[install-suite-data] installed ${missing[*]} into $meshes"
