#!/bin/sh
# A full disk: every write is checked, so pathbench exits 2 naming the file and the
# reason, and leaves nothing (no image, no report, no temporary file) -- also when
# only the last output (the report) does not fit. The disk fills through a file size
# limit (ulimit -f; SIGXFSZ ignored, so writes fail with EFBIG), which works without
# privileges; where tmpfs can be mounted (root with CAP_SYS_ADMIN), also a real
# ENOSPC on a 64 KB tmpfs.
#   sh full_disk.sh PATHBENCH DIR
set -eu
pb=$1
dir=$2
fail() { echo "full_disk: $*" >&2; exit 1; }
rm -rf "$dir"
mkdir -p "$dir"
render="render --quiet --spp 1"

# expect_full NAME LIMIT_BLOCKS EXPECT_REGEX ARGS...: runs in a subshell with the limit.
expect_full() {
  name=$1 limit=$2 expect=$3
  shift 3
  status=0
  (trap '' XFSZ; ulimit -f "$limit"; "$pb" "$@") 2>"$dir/err" || status=$?
  [ $status = 2 ] || fail "$name: exit status $status, expected 2 ($(cat "$dir/err"))"
  grep -q -E "$expect" "$dir/err" || fail "$name: stderr '$(cat "$dir/err")' does not match '$expect'"
  [ "$(wc -l <"$dir/err")" = 1 ] || fail "$name: stderr is not one line: $(cat "$dir/err")"
  rm "$dir/err"
  left=$(ls -A "$dir")
  [ -z "$left" ] || fail "$name: left behind: $left"
  echo "full_disk: $name: exit 2, nothing left"
}
for ext in png exr pfm; do
  expect_full "$ext image" 16 "o\\.$ext: write failed: File too large" $render --width 128 --height 128 \
    --out "$dir/o.$ext" --report "$dir/r.json"
done
# The image fits, the report does not: the image must not appear either.
expect_full "report last" 1 "r\\.json: write failed: File too large" $render --width 4 --height 4 \
  --out "$dir/o.pfm" --report "$dir/r.json"

mnt="$dir/tmpfs"
mkdir "$mnt"
if mount -t tmpfs -o size=64k tmpfs "$mnt" 2>/dev/null; then
  trap 'umount "$mnt" 2>/dev/null || true' EXIT
  for ext in png pfm; do
    status=0
    "$pb" $render --width 256 --height 256 --out "$mnt/o.$ext" 2>"$dir/err" || status=$?
    [ $status = 2 ] || fail "tmpfs $ext: exit status $status, expected 2"
    grep -q "No space left on device" "$dir/err" || fail "tmpfs $ext: $(cat "$dir/err")"
    left=$(ls -A "$mnt")
    [ -z "$left" ] || fail "tmpfs $ext: left behind: $left"
    echo "full_disk: a full 64 KB tmpfs, $ext: exit 2, nothing left"
  done
  rm "$dir/err"
else
  echo "full_disk: tmpfs cannot be mounted here; the ulimit cases above stand in for it"
fi
