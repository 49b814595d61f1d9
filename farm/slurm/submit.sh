#!/bin/bash
# Submits a Glint render to Slurm as an N-task job array plus a merge job.
#
#   farm/slurm/submit.sh SCENE N OUT [GLINT RENDER ARGS...]
#
# Task I (0 <= I < N) renders tile I/N of the image (FARM_SPLIT=tiles, the default) or sample
# range I/N of every pixel (FARM_SPLIT=samples) into OUT.parts/part-I.exr. The merge job runs
# once every task has ended: it runs `glint merge -o OUT` on the N parts, which checks that
# they fit together, or, when a part is missing, exits 1 naming each missing part and its log.
# OUT is .exr or .png. Logs: OUT.parts/part-I.log and OUT.parts/merge.log.
#
# The render arguments (-w, -h, -r, --integrator, --seed, ...) go to every task unchanged.
#
# Environment: GLINT (the glint binary, default `glint` on PATH; give an absolute path),
# FARM_SPLIT (tiles | samples), GLINT_CHECKPOINT_EVERY (seconds, 60), SBATCH_ARGS (extra
# sbatch options for both jobs, e.g. "--partition=render --time=1:00:00").
# Prints the two job ids: `array JOBID` and `merge JOBID`.
set -euo pipefail
if [ $# -lt 3 ]; then
  awk 'NR > 1 && !/^#/ { exit } NR > 1' "$0" >&2
  exit 2
fi
scene=$1 count=$2 out=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)
die() {
  echo "error: $1" >&2
  exit 2
}
split=${FARM_SPLIT:-tiles}
case $split in tiles | samples) ;; *) die "FARM_SPLIT is tiles or samples, not '$split'" ;; esac
[[ $count =~ ^[1-9][0-9]*$ ]] || die "N must be a whole number >= 1, not '$count'"
if [ ! -f "$scene" ] || [ ! -r "$scene" ]; then die "cannot read the scene '$scene'"; fi
case ${out,,} in *.exr | *.png) ;; *) die "OUT is .exr or .png, not '$out'" ;; esac

args=("$@")

scene=$(realpath "$scene")
out=$(realpath -m "$out")
parts="$out.parts"
mkdir -p "$parts"

# shellcheck disable=SC2086 # SBATCH_ARGS is a list of options.
array=$(sbatch --parsable ${SBATCH_ARGS:-} \
  --array="0-$((count - 1))" --output="$parts/part-%a.log" \
  "$here/render.sbatch" "$split" "$count" "$scene" "$parts" "${args[@]}")
array=${array%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_ARGS:-} --dependency="afterany:$array" \
  --output="$parts/merge.log" "$here/merge.sbatch" "$count" "$parts" "$out")
merge=${merge%%;*}
echo "array $array"
echo "merge $merge"
