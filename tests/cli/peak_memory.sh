#!/bin/sh
# The report's peak_host_bytes covers the whole run, image writing included: it is
# at least the process's peak resident set as the kernel measured it (getrusage of
# the child). It once was read before the image was written and under-counted
# (602 MB against 797 MB at 4096x4096); render_peak_host_bytes keeps the render's own.
#   sh peak_memory.sh PATHBENCH DIR
set -eu
rm -rf "$2"
mkdir -p "$2"
python3 - "$1" "$2" <<'PY'
import json, resource, subprocess, sys
pb, d = sys.argv[1:3]
subprocess.run([pb, "render", "--quiet", "--width", "2048", "--height", "2048", "--spp", "1", "--bounces", "0",
                "--out", d + "/m.png", "--report", d + "/m.json"], check=True)
max_rss = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
r = json.load(open(d + "/m.json"))
peak = r["peak_host_bytes"]
print(f"peak_memory: max RSS {max_rss / 1e6:.1f} MB, report peak {peak / 1e6:.1f} MB")
assert peak >= 0.98 * max_rss, f"the report's peak {peak} under-counts the measured {max_rss}"
render_peak = r["render_peak_host_bytes"]
print(f"peak_memory: render peak {render_peak / 1e6:.1f} MB")
assert render_peak <= peak, "the run's peak is below the render's"
PY
