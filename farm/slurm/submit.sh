#!/bin/bash
# Submits a Glint render to Slurm as an N-task job array plus a merge job.
#
#   farm/slurm/submit.sh SCENE N OUT [GLINT RENDER ARGS...]
#
# Task I (0 <= I < N) renders tile I/N of the image (FARM_SPLIT=tiles, the default) or sample
# range I/N of every pixel (FARM_SPLIT=samples) into OUT.parts/part-I.exr. The merge job runs
# once every task has ended: it runs `glint merge -o OUT` on the N parts, which checks that
# they fit together, or, when a part is missing, exits 1 naming each missing part and its log.
# OUT is .exr or .png. Logs: OUT.parts/part-I.log (appended to by every run of task I) and
# OUT.parts/merge.log.
#
# The render arguments (-w, -h, -r, --integrator, --seed, ...) go to every task unchanged,
# except -n/--numcpus THREADS, which becomes the tasks' --cpus-per-task, and
# --checkpoint-every SECONDS, which sets GLINT_CHECKPOINT_EVERY. Refused (exit 2, nothing
# submitted): -o (OUT is the third argument), --tile, --sample-range, --crop-window,
# --pixel-bounds (N and FARM_SPLIT split the image), --checkpoint, --resume (each task
# checkpoints by itself), --time, -x/-y/--preview-close, and arguments that are not options.
#
# Resubmitting the same SCENE N OUT and arguments after a failure submits only the parts not
# yet in OUT.parts (each resumes from its checkpoint), then the merge. OUT.parts/submission
# records what the parts were rendered with; a resubmit with other arguments is refused
# unless FARM_RESTART=1, which deletes the old parts, checkpoints and logs first.
#
# Each task is submitted with --requeue --signal=B:TERM@120 --open-mode=append (render.sbatch):
# a task that is preempted or requeued gets SIGTERM, writes its checkpoint and continues from
# it when Slurm runs it again; one that reaches its time limit gets SIGTERM two minutes before
# it and writes its checkpoint, and a resubmit continues it. SBATCH_ARGS overrides these.
#
# Environment: GLINT (the glint binary, default `glint` on PATH; give an absolute path),
# FARM_SPLIT (tiles | samples), GLINT_CHECKPOINT_EVERY (seconds, 60), FARM_RESTART (1: start
# over), SBATCH_ARGS (extra sbatch options for both jobs, e.g. "--partition=render
# --time=1:00:00"). Prints `array JOBID` (unless every part is already done) and `merge JOBID`.
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

# The render arguments, checked here rather than by N failing tasks (farm/render-args.sh).
# shellcheck source=farm/render-args.sh
. "$here/../render-args.sh"
farm_render_args submit "$@"
args=("${farm_args[@]}") threads=$farm_threads
[ -z "$farm_checkpoint_every" ] || export GLINT_CHECKPOINT_EVERY=$farm_checkpoint_every

scene=$(realpath "$scene")
out=$(realpath -m "$out")
parts="$out.parts"
record="$parts/submission"
mkdir -p "$parts"

# What the parts are rendered with, so that a resubmit reuses only parts of this render. The
# thread count is left out: it does not change the image.
submission=$(
  echo "# farm/slurm/submit.sh: the parts in this folder are of this render"
  echo "split $split"
  echo "count $count"
  echo "scene $scene"
  echo "scene-sha256 $(sha256sum < "$scene" | cut -d' ' -f1)"
  printf 'args'
  printf ' %q' "${args[@]}"
  echo
)
# A resubmit while the last submission still runs would render its parts twice.
if [ -f "$parts/jobs" ]; then
  read -r -a previous < "$parts/jobs"
  if [ -n "$(squeue -h -j "$(IFS=,; echo "${previous[*]}")" 2> /dev/null)" ]; then
    die "the last submission for $out (jobs ${previous[*]}) is still queued or running: wait for it, or scancel ${previous[*]}"
  fi
fi
# Checkpoints are not counted: glint refuses to resume one of other settings.
old_parts=$(find "$parts" -maxdepth 1 -regex '.*/part-[0-9]+\.exr' -print -quit)
if [ "${FARM_RESTART:-}" = 1 ]; then
  find "$parts" -maxdepth 1 \( -name 'part-*.exr' -o -name 'part-*.log' -o -name merge.log \
    -o -name submission -o -name jobs \) -delete
elif [ -f "$record" ] && [ "$(cat "$record")" != "$submission" ]; then
  echo "error: $parts holds parts of another render; what differs (< then, > now):" >&2
  diff <(grep -v '^#' "$record") <(grep -v '^#' <<< "$submission") | grep '^[<>]' >&2 || true
  die "resubmit with the same arguments to finish that render, or set FARM_RESTART=1 to delete its parts and start over"
elif [ ! -f "$record" ] && [ -n "$old_parts" ]; then
  die "$parts holds parts with no record of what they were rendered with ($record); set FARM_RESTART=1 to delete them and start over"
fi
echo "$submission" > "$record"

# Parts are written atomically (glint renames a finished image into place), so a part that
# exists is complete.
todo=() ranges=''
for ((i = 0; i < count; i++)); do
  [ -f "$parts/part-$i.exr" ] || todo+=("$i")
done
# Slurm's --array list, runs of indices as ranges: 0-9,12,14-15.
for ((k = 0; k < ${#todo[@]}; k = j + 1)); do
  for ((j = k; j + 1 < ${#todo[@]} && todo[j + 1] == todo[j] + 1; j++)); do :; done
  ranges+=${ranges:+,}${todo[k]}
  [ "$j" -eq "$k" ] || ranges+=-${todo[j]}
done
cpus=()
[ -z "$threads" ] || cpus=(--cpus-per-task="$threads")
dependency=()
jobs=()
if [ ${#todo[@]} -gt 0 ]; then
  # shellcheck disable=SC2086 # SBATCH_ARGS is a list of options.
  array=$(sbatch --parsable ${SBATCH_ARGS:-} "${cpus[@]}" \
    --array="$ranges" --output="$parts/part-%a.log" \
    "$here/render.sbatch" "$split" "$count" "$scene" "$parts" "${args[@]}")
  array=${array%%;*}
  dependency=(--dependency="afterany:$array")
  jobs+=("$array")
  if [ ${#todo[@]} -lt "$count" ]; then
    echo "rendering parts $ranges of 0-$((count - 1)); the others are done" >&2
  fi
else
  echo "all $count parts are done: submitting the merge only" >&2
fi
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_ARGS:-} "${dependency[@]}" \
  --output="$parts/merge.log" "$here/merge.sbatch" "$count" "$parts" "$out")
merge=${merge%%;*}
jobs+=("$merge")
echo "${jobs[*]}" > "$parts/jobs"
[ ${#todo[@]} -eq 0 ] || echo "array $array"
echo "merge $merge"
