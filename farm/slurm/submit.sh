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

# The render arguments, checked here rather than by N failing tasks. glint's parser (clap)
# takes `-n 8`, `-n8`, `-n=8`, `-vn8`, `--numcpus 8` and `--numcpus=8`: all are recognised.
# Options of `glint render` that take a value, so that a value is never taken for an option.
short_valued=owhrknadsxyD
valued_names=(outputfile width height rpp spp noise-threshold min-spp time recursionDepth numcpus
  aspect background seed integrator shader exposure tonemap transfer device crop-window
  pixel-bounds tile sample-range checkpoint checkpoint-every resume progress-every depth
  aperture split winwidth winheight max-memory max-file-size max-texture-size max-triangles
  define scene camera env env-strength)
long_valued=" ${valued_names[*]} "
refuse() {
  local instead
  case $1 in
    -o | --outputfile | --output)
      instead="OUT is the third argument (submit.sh SCENE N OUT): the tasks write OUT.parts/part-I.exr and the merge job writes OUT" ;;
    --tile | --sample-range)
      instead="the script splits the render itself into N parts (the second argument), tiles or sample ranges by FARM_SPLIT" ;;
    --crop-window | --pixel-bounds)
      instead="the farm renders the whole image in N parts; render a crop with glint render alone" ;;
    --checkpoint | --resume)
      instead="each task checkpoints to OUT.parts/part-I.checkpoint.exr and resumes from it by itself" ;;
    --time)
      instead="a time budget cannot be split into parts; give -r, and a Slurm time limit with SBATCH_ARGS=--time=..." ;;
    -x | -y | --winwidth | --winheight | --preview-close)
      instead="it opens a preview window, and a batch task has no display" ;;
    -i | --inputfile)
      instead="SCENE is the first argument" ;;
    -'?' | --help)
      instead="glint render --help lists the render options" ;;
  esac
  die "$1 cannot be used with farm/slurm/submit.sh: $instead"
}
threads='' args=()
take_threads() {
  [[ $1 =~ ^[1-9][0-9]*$ ]] || die "-n/--numcpus takes a number of threads >= 1, not '$1'"
  threads=$1
}
take_checkpoint_every() {
  [[ $1 =~ ^[0-9]+(\.[0-9]+)?$ ]] || die "--checkpoint-every takes seconds, not '$1'"
  export GLINT_CHECKPOINT_EVERY=$1
}
# One option with its value (long or short, without dashes): honoured, refused or kept.
option() {
  case $1 in
    n | numcpus) take_threads "$2" ;;
    checkpoint-every) take_checkpoint_every "$2" ;;
    o | outputfile | output | tile | sample-range | crop-window | pixel-bounds | checkpoint | \
      resume | time | x | y | winwidth | winheight | i | inputfile)
      if [ ${#1} -eq 1 ]; then refuse "-$1"; else refuse "--$1"; fi ;;
    ?) args+=("-$1" "$2") ;;
    *) args+=("--$1" "$2") ;;
  esac
}
while [ $# -gt 0 ]; do
  arg=$1
  shift
  case $arg in
    --*=*)
      name=${arg%%=*}
      option "${name#--}" "${arg#*=}"
      ;;
    --preview-close | --help) refuse "$arg" ;;
    --?*)
      name=${arg#--}
      if [[ $long_valued == *" $name "* ]]; then
        [ $# -gt 0 ] || die "$arg needs a value"
        option "$name" "$1"
        shift
      else
        args+=("$arg")
        # An option this script does not know keeps the value that follows it: glint judges.
        if [[ " denoise verbose stats strict " != *" $name "* ]] && [ $# -gt 0 ] && [[ $1 != -* ]]; then
          args+=("$1")
          shift
        fi
      fi
      ;;
    -?*)
      # A cluster of short options: flags (-v), then at most one that takes a value, written
      # after it (-n8, -n=8) or as the next argument (-n 8).
      flags=''
      for ((c = 1; c < ${#arg}; c++)); do
        letter=${arg:c:1}
        case $letter in '?' | i) refuse "-$letter" ;; esac
        if [[ $short_valued != *"$letter"* ]]; then
          flags+=$letter
          continue
        fi
        [ -z "$flags" ] || args+=("-$flags")
        flags=''
        value=${arg:c+1}
        if [ -z "$value" ]; then
          [ $# -gt 0 ] || die "-$letter needs a value"
          value=$1
          shift
        fi
        option "$letter" "${value#=}"
        break
      done
      [ -z "$flags" ] || args+=("-$flags")
      ;;
    *)
      die "unexpected argument '$arg': SCENE is the first argument and the render arguments are options"
      ;;
  esac
done

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
