#!/bin/sh
# Runs every fuzz target for RUNS executions (default 1,000,000) or SECONDS seconds each,
# whichever ends first, one after the other at low priority, and prints each target's
# executions and whether it found a crash (artifacts/TARGET/). Needs nightly and cargo-fuzz.
# Usage: fuzz/run-all.sh [RUNS] [SECONDS] [TARGET...]
set -u
here=$(cd "$(dirname "$0")" && pwd)
cd "$here"
runs=${1:-1000000}
seconds=${2:-3600}
shift 2 2>/dev/null || shift $#
targets=${*:-xml json obj ply texture image scene mitsuba mitsuba_serialized gltf}
[ -d corpus ] || ./seed.sh
nice -n 19 cargo +nightly fuzz build -s none -a >/dev/null 2>&1 || { echo "build failed" >&2; exit 1; }
for target in $targets; do
    mkdir -p "corpus/$target" "artifacts/$target"
    log="artifacts/$target.log"
    nice -n 19 cargo +nightly fuzz run -s none -a "$target" "corpus/$target" -- \
        -runs="$runs" -max_total_time="$seconds" -rss_limit_mb=2048 -max_len=65536 \
        -timeout=10 -print_final_stats=1 >"$log" 2>&1
    status=$?
    executed=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    crashes=$(ls "artifacts/$target" | grep -c -E '^(crash|oom|timeout|leak)-' || true)
    echo "$target: ${executed:-?} executions, exit $status, $crashes crash file(s)"
done
