#!/bin/sh
# SIGTERM and SIGINT while the outputs are being written: pathbench dies by the
# signal (status 128 + its number) and leaves no file, temporary or final, behind.
# The signal is sent as soon as the first temporary output file appears; if the run
# finished its outputs before the signal arrived (status 0, or the signal's status
# with all three outputs complete and nothing else: a signal during the renames waits
# for them), it retries with a larger image.
#   sh signal_cleanup.sh PATHBENCH DIR
set -eu
pb=$1
dir=$2
fail() { echo "signal_cleanup: $*" >&2; exit 1; }
# A background job of a non-interactive shell starts with SIGINT ignored (and
# pathbench leaves an ignored signal alone), so SIGINT runs go through a python3 that
# restores the default first.
launch() {
  sig=$1
  shift
  if [ "$sig" = INT ]; then
    python3 -c 'import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); os.execv(sys.argv[1], sys.argv[1:])' "$@" &
  else
    "$@" &
  fi
  pid=$!
}
for sig in TERM INT; do
  [ $sig = TERM ] && want=143 || want=130
  done_sig=0
  for side in 512 1024 2048; do
    rm -rf "$dir"
    mkdir -p "$dir"
    launch $sig "$pb" render --quiet --width $side --height $side --spp 1 --bounces 0 \
      --out "$dir/big.exr" --variance-out "$dir/var.exr" --report "$dir/r.json"
    seen=0
    while kill -0 $pid 2>/dev/null; do
      if ls -A "$dir" | grep -q '\.tmp$'; then
        kill -$sig $pid
        seen=1
        break
      fi
    done
    status=0
    wait $pid || status=$?
    [ $seen = 1 ] && [ $status = 0 ] && continue  # it finished between the look and the signal
    [ $seen = 1 ] || continue
    [ $status = $want ] || fail "SIG$sig during the write: exit status $status, expected $want"
    left=$(ls -A "$dir" | tr '\n' ' ')
    [ "$left" = "big.exr r.json var.exr " ] && continue  # all renamed before the signal came
    [ -z "$left" ] || fail "SIG$sig during the write left: $left"
    echo "signal_cleanup: SIG$sig during the write of a ${side}x$side image: status $status, folder clean"
    done_sig=1
    break
  done
  [ $done_sig = 1 ] || fail "never caught a write in progress for SIG$sig"
done
