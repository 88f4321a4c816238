#!/usr/bin/env bash
# Packs the meshes the suite needs (scenes/suite/manifest.json, "requires") from this
# machine's data folder into DIR, for a host without network (the GPU host):
#   scripts/pack-suite-data.sh DIR        -> DIR/suite-meshes.tar.xz, DIR/unpack.sh
# On the other host: DIR/unpack.sh puts them into its data folder ($PATHBENCH_DATA_DIR,
# else ${XDG_DATA_HOME:-$HOME/.local/share}/pathbench/data), checking each SHA-256.
# Run scripts/install-suite-data.sh (or install-deps.sh) here first. About 3 MB.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${1:?usage: scripts/pack-suite-data.sh DIR}
data=${PATHBENCH_DATA_DIR:-${XDG_DATA_HOME:-$HOME/.local/share}/pathbench/data}
manifest="$root/scenes/suite/manifest.json"
# "file sha256" lines, from the manifest's requires.
mapfile -t files < <(python3 - "$manifest" <<'PY'
import json, sys
seen = {}
for w in json.load(open(sys.argv[1]))["workloads"]:
    for r in w.get("requires", []):
        seen[r["file"]] = r.get("sha256", "")
for f, h in sorted(seen.items()):
    print(f, h)
PY
)
((${#files[@]})) || { echo "pack-suite-data: the manifest requires no files" >&2; exit 2; }
names=()
for line in "${files[@]}"; do
  set -- $line
  if [ ! -f "$data/meshes/$1" ]; then
    echo "pack-suite-data: $data/meshes/$1 is missing: run scripts/install-suite-data.sh first" >&2
    exit 2
  fi
  names+=("$1")
done
mkdir -p "$out"
extra=(); [ -f "$data/meshes/SOURCE.txt" ] && extra=(SOURCE.txt)  # where they come from, their licence
tar -C "$data/meshes" -cJf "$out/suite-meshes.tar.xz.part" "${names[@]}" "${extra[@]}"
mv "$out/suite-meshes.tar.xz.part" "$out/suite-meshes.tar.xz"
{
  cat <<'HEAD'
#!/usr/bin/env bash
# Unpacks the suite's meshes (written by pathbench's scripts/pack-suite-data.sh) into this
# host's pathbench data folder, checking each file's SHA-256.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
data=${PATHBENCH_DATA_DIR:-${XDG_DATA_HOME:-$HOME/.local/share}/pathbench/data}
mkdir -p "$data/meshes"
tar -C "$data/meshes" -xJf "$here/suite-meshes.tar.xz"
HEAD
  for line in "${files[@]}"; do
    set -- $line
    [ -n "${2:-}" ] && echo "echo \"$2  \$data/meshes/$1\" | sha256sum -c --quiet -"
  done
  echo 'echo "[unpack] suite meshes in $data/meshes"'
} > "$out/unpack.sh"
chmod +x "$out/unpack.sh"
echo "[pack-suite-data] $(du -h "$out/suite-meshes.tar.xz" | cut -f1) in $out (${names[*]})"
