#!/bin/sh
# Two renders to one --out at once, many times: the file must always be exactly one
# writer's complete image, bit for bit (unique temporary names and an atomic rename;
# a shared temporary name made one writer fail or left the other's image or a mix).
#   sh concurrent_out.sh PATHBENCH DIR
set -eu
pb=$1
dir=$2
rm -rf "$dir"
mkdir -p "$dir"
cd "$dir"
fail() { echo "concurrent_out: $*" >&2; exit 1; }
# A 9 MB PFM keeps the writes long enough to overlap (a shared temporary name failed
# one writer in about one round of five), and a small PNG goes through OpenImageIO.
for ext in pfm png; do
  [ $ext = pfm ] && args="render --quiet --width 1024 --height 768 --spp 1 --bounces 0" ||
    args="render --quiet --width 24 --height 24 --spp 1"
  "$pb" $args --seed 1 --out "ref1.$ext"
  "$pb" $args --seed 2 --out "ref2.$ext"
  if cmp -s "ref1.$ext" "ref2.$ext"; then fail "seeds 1 and 2 gave the same image"; fi
  round=0
  while [ $round -lt 6 ]; do
    "$pb" $args --seed 1 --out "shared.$ext" & a=$!
    "$pb" $args --seed 2 --out "shared.$ext" & b=$!
    wait $a || fail "round $round: the first writer failed"
    wait $b || fail "round $round: the second writer failed"
    cmp -s "shared.$ext" "ref1.$ext" || cmp -s "shared.$ext" "ref2.$ext" ||
      fail "round $round: shared.$ext is neither writer's image"
    round=$((round + 1))
  done
done
left=$(ls -A | grep -v -e '^ref[12]\.' -e '^shared\.' || true)
[ -z "$left" ] || fail "left behind: $left"
echo "concurrent_out: 12 rounds, every time one writer's complete image"
