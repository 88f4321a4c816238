#!/bin/sh
# PATHBENCH_SCALING_MAX (pathbench-bench --preset scaling's largest scaling:N): a whole
# number from 10 to 10^7, else one line naming it, exit 2 and no benchmark run. It was
# read with strtoull: "abc" ran no sweep, "-1" or 2^64-1 a sweep that never ended.
#   sh scaling_max.sh PATHBENCH DIR
set -eu
bench=$(dirname "$1")/pathbench-bench
[ -x "$bench" ] || { echo "scaling_max: no pathbench-bench in this build; nothing to test"; exit 0; }
fail() { echo "scaling_max: $*" >&2; exit 1; }
for v in abc -1 18446744073709551615 99999999999999999999 100000001 9 "" "1e6" " 100" "100 " "0x10"; do
  status=0
  err=$(PATHBENCH_SCALING_MAX="$v" "$bench" --preset scaling --benchmark_list_tests=true 2>&1 >/dev/null) || status=$?
  [ $status = 2 ] || fail "PATHBENCH_SCALING_MAX='$v': exit status $status, expected 2 ($err)"
  [ "$(printf '%s\n' "$err" | wc -l)" = 1 ] || fail "PATHBENCH_SCALING_MAX='$v': more than one line: $err"
  case "$err" in "pathbench-bench: PATHBENCH_SCALING_MAX="*"expected a whole number of triangles from 10 to 10000000"*) ;;
    *) fail "PATHBENCH_SCALING_MAX='$v': $err" ;; esac
done
list=$(PATHBENCH_SCALING_MAX=1000 "$bench" --preset scaling --benchmark_list_tests=true)
for n in 10 100 1000; do
  printf '%s\n' "$list" | grep -q "scaling:$n/" || fail "PATHBENCH_SCALING_MAX=1000: no scaling:$n benchmark"
done
! printf '%s\n' "$list" | grep -q "scaling:10000/" || fail "PATHBENCH_SCALING_MAX=1000 listed scaling:10000"
echo "scaling_max: 11 bad values exit 2 with one line; 1000 sweeps 10..1000"
