#!/bin/sh
# `pathbench bench --out`: Google Benchmark writes the JSON unchecked, so pathbench
# has it write a temporary file and renames it into place only when pathbench-bench
# succeeded and the JSON is complete. A full disk (ulimit -f) is exit 2 and leaves
# nothing; a good run leaves exactly the JSON.
#   sh bench_out.sh PATHBENCH DIR
set -eu
pb=$1
dir=$2
fail() { echo "bench_out: $*" >&2; exit 1; }
rm -rf "$dir"
mkdir -p "$dir"
[ -x "$(dirname "$pb")/pathbench-bench" ] || { echo "bench_out: no pathbench-bench in this build; nothing to test"; exit 0; }
one="--benchmark_filter=raycast/cpu/occluded16/coherent --benchmark_min_time=0.01"
# stderr goes through a pipe: a file would be cut by the size limit too.
err=$( (trap '' XFSZ; ulimit -f 1; status=0; "$pb" bench --preset quick --out "$dir/b.json" $one >/dev/null || status=$?
        echo "exit status $status") 2>&1)
case "$err" in *"exit status 2") ;; *) fail "full disk: expected exit status 2: $err" ;; esac
case "$err" in *"b.json: pathbench-bench wrote incomplete JSON"*) ;; *) fail "full disk: $err" ;; esac
[ -z "$(ls -A "$dir")" ] || fail "full disk left: $(ls -A "$dir")"
"$pb" bench --preset quick --out "$dir/b.json" $one >/dev/null
python3 -c 'import json, sys; json.load(open(sys.argv[1]))["benchmarks"][0]' "$dir/b.json" || fail "b.json is not complete"
[ "$(ls -A "$dir")" = b.json ] || fail "left besides b.json: $(ls -A "$dir")"
echo "bench_out: full disk exit 2 and nothing left; a good run leaves exactly b.json"
