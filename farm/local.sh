#!/bin/bash
# The farm contract of farm/slurm/submit.sh on one machine: N parts, then the merge.
#
#   farm/local.sh SCENE N OUT [GLINT RENDER ARGS...]
#
# Runs the N parts (tiles, or sample ranges with FARM_SPLIT=samples) with GNU parallel when it
# is installed (JOBS at a time, default: the number of cores) and otherwise with a plain shell
# loop, each part on THREADS threads (default 1; -n/--numcpus among the render arguments sets
# it), into OUT.parts/part-I.exr, then `glint merge -o OUT`. The render arguments (-w, -h, -r,
# --integrator, --seed, ...) go to every part unchanged. Refused (exit 2, nothing rendered or
# written): -o (OUT is the third argument), --tile, --sample-range, --crop-window,
# --pixel-bounds (N and FARM_SPLIT split the image), --checkpoint, --checkpoint-every,
# --resume (the parts are not checkpointed), --time, -x/-y/--preview-close, and arguments
# that are not options. Environment: GLINT (the glint binary, default `glint`), FARM_SPLIT,
# JOBS, THREADS.
set -euo pipefail
if [ $# -lt 3 ]; then
  awk 'NR > 1 && !/^#/ { exit } NR > 1' "$0" >&2
  exit 2
fi
scene=$1 count=$2 out=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=farm/render-args.sh
. "$here/render-args.sh"
glint=${GLINT:-glint}
split=${FARM_SPLIT:-tiles}
case $split in tiles) flag=--tile ;; samples) flag=--sample-range ;; *) farm_die "FARM_SPLIT is tiles or samples, not '$split'" ;; esac
[[ $count =~ ^[1-9][0-9]*$ ]] || farm_die "N must be a whole number >= 1, not '$count'"
# Checked before anything is written: an option the parts cannot take would fail all N.
farm_render_args local "$@"
set -- "${farm_args[@]}"
jobs=${JOBS:-$(nproc)}
threads=${farm_threads:-${THREADS:-1}}
parts="$out.parts"
mkdir -p "$parts"
if command -v parallel > /dev/null; then
  # -q: each argument stays one argument (parallel would otherwise run them through a shell).
  seq 0 $((count - 1)) | parallel -q --halt now,fail=1 -j "$jobs" \
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
