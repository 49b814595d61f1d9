#!/bin/bash
# The farm contract of farm/slurm/submit.sh on one machine: N parts, then the merge.
#
#   farm/local.sh SCENE N OUT [GLINT RENDER ARGS...]
#
# Runs the N parts (tiles, or sample ranges with FARM_SPLIT=samples) with GNU parallel when it
# is installed (JOBS at a time, default: the number of cores) and otherwise with a plain shell
# loop, each part on THREADS threads (default 1), into OUT.parts/part-I.exr, then
# `glint merge -o OUT`. Environment: GLINT (the glint binary, default `glint`), FARM_SPLIT,
# JOBS, THREADS.
set -euo pipefail
if [ $# -lt 3 ]; then
  sed -n '2,11p' "$0" >&2
  exit 2
fi
scene=$1 count=$2 out=$3
shift 3
glint=${GLINT:-glint}
split=${FARM_SPLIT:-tiles}
case $split in tiles) flag=--tile ;; samples) flag=--sample-range ;; *) echo "error: FARM_SPLIT is tiles or samples" >&2; exit 2 ;; esac
jobs=${JOBS:-$(nproc)}
threads=${THREADS:-1}
parts="$out.parts"
mkdir -p "$parts"
if command -v parallel > /dev/null; then
  seq 0 $((count - 1)) | parallel --halt now,fail=1 -j "$jobs" \
    "$glint" render "$scene" "$@" "$flag" "{}/$count" -n "$threads" -o "$parts/part-{}.exr"
else
  pids=()
  for ((i = 0; i < count; i++)); do
    "$glint" render "$scene" "$@" "$flag" "$i/$count" -n "$threads" -o "$parts/part-$i.exr" &
    pids+=($!)
    if [ ${#pids[@]} -ge "$jobs" ]; then wait "${pids[0]}"; pids=("${pids[@]:1}"); fi
  done
  for pid in "${pids[@]}"; do wait "$pid"; done
fi
files=()
for ((i = 0; i < count; i++)); do files+=("$parts/part-$i.exr"); done
"$glint" merge -o "$out" "${files[@]}"
