# shellcheck shell=bash
# The render arguments of a farm script (farm/slurm/submit.sh, farm/local.sh), checked once
# here rather than by N failing parts. Sourced, not run:
#
#   . farm/render-args.sh
#   farm_render_args submit|local [GLINT RENDER ARGS...]
#
# Sets farm_args (the arguments every part gets unchanged), farm_threads (-n/--numcpus, empty
# when not given) and farm_checkpoint_every (--checkpoint-every, empty when not given; local.sh
# refuses it). An option the script sets itself or cannot honour (-o, --tile, --sample-range,
# --crop-window, --pixel-bounds, --checkpoint, --resume, --time, -x/-y/--preview-close, -i,
# -?/--help) or an argument that is not an option: an error naming it and the script, exit 2.

farm_die() {
  echo "error: $1" >&2
  exit 2
}

# glint's parser (clap) takes `-n 8`, `-n8`, `-n=8`, `-vn8`, `--numcpus 8` and `--numcpus=8`:
# all are recognised. Options of `glint render` that take a value, so that a value is never
# taken for an option.
farm_short_valued=owhrknadsxyD
farm_valued_names=(outputfile width height rpp spp noise-threshold min-spp time recursionDepth
  numcpus aspect background seed integrator shader exposure tonemap transfer device crop-window
  pixel-bounds tile sample-range checkpoint checkpoint-every resume progress-every depth
  aperture split winwidth winheight max-memory max-file-size max-texture-size max-triangles
  define scene camera env env-strength)
farm_long_valued=" ${farm_valued_names[*]} "

# Refuses option $1 with the reason it cannot be used with the calling script.
farm_refuse() {
  local instead script=farm/slurm/submit.sh usage='submit.sh SCENE N OUT'
  if [ "$farm_caller" = local ]; then script=farm/local.sh usage='local.sh SCENE N OUT'; fi
  case $farm_caller:$1 in
    submit:-o | submit:--outputfile | submit:--output)
      instead="OUT is the third argument ($usage): the tasks write OUT.parts/part-I.exr and the merge job writes OUT" ;;
    local:-o | local:--outputfile | local:--output)
      instead="OUT is the third argument ($usage): the parts go to OUT.parts/part-I.exr and the merge writes OUT" ;;
    *:--tile | *:--sample-range)
      instead="the script splits the render itself into N parts (the second argument), tiles or sample ranges by FARM_SPLIT" ;;
    *:--crop-window | *:--pixel-bounds)
      instead="the farm renders the whole image in N parts; render a crop with glint render alone" ;;
    submit:--checkpoint | submit:--resume)
      instead="each task checkpoints to OUT.parts/part-I.checkpoint.exr and resumes from it by itself" ;;
    local:--checkpoint | local:--resume | local:--checkpoint-every)
      instead="its parts are not checkpointed; for checkpoints render with glint render alone or with farm/slurm/submit.sh" ;;
    submit:--time)
      instead="a time budget cannot be split into parts; give -r, and a Slurm time limit with SBATCH_ARGS=--time=..." ;;
    local:--time)
      instead="a time budget cannot be split into parts; give -r" ;;
    submit:-x | submit:-y | submit:--winwidth | submit:--winheight | submit:--preview-close)
      instead="it opens a preview window, and a batch task has no display" ;;
    local:-x | local:-y | local:--winwidth | local:--winheight | local:--preview-close)
      instead="it opens a preview window, one per part; preview with glint render alone" ;;
    *:-i | *:--inputfile)
      instead="SCENE is the first argument" ;;
    *:-'?' | *:--help)
      instead="glint render --help lists the render options" ;;
  esac
  farm_die "$1 cannot be used with $script: $instead"
}

# One option with its value (long or short, without dashes): honoured, refused or kept.
farm_option() {
  case $1 in
    n | numcpus)
      [[ $2 =~ ^[1-9][0-9]*$ ]] || farm_die "-n/--numcpus takes a number of threads >= 1, not '$2'"
      farm_threads=$2
      ;;
    checkpoint-every)
      [ "$farm_caller" = submit ] || farm_refuse --checkpoint-every
      [[ $2 =~ ^[0-9]+(\.[0-9]+)?$ ]] || farm_die "--checkpoint-every takes seconds, not '$2'"
      farm_checkpoint_every=$2
      ;;
    o | outputfile | output | tile | sample-range | crop-window | pixel-bounds | checkpoint | \
      resume | time | x | y | winwidth | winheight | i | inputfile)
      if [ ${#1} -eq 1 ]; then farm_refuse "-$1"; else farm_refuse "--$1"; fi ;;
    ?) farm_args+=("-$1" "$2") ;;
    *) farm_args+=("--$1" "$2") ;;
  esac
}

farm_render_args() {
  farm_caller=$1
  shift
  # shellcheck disable=SC2034 # read by the script that sources this file
  farm_args=() farm_threads='' farm_checkpoint_every=''
  local arg name flags letter value c
  while [ $# -gt 0 ]; do
    arg=$1
    shift
    case $arg in
      --*=*)
        name=${arg%%=*}
        farm_option "${name#--}" "${arg#*=}"
        ;;
      --preview-close | --help) farm_refuse "$arg" ;;
      --?*)
        name=${arg#--}
        if [[ $farm_long_valued == *" $name "* ]]; then
          [ $# -gt 0 ] || farm_die "$arg needs a value"
          farm_option "$name" "$1"
          shift
        else
          farm_args+=("$arg")
          # An option this script does not know keeps the value that follows it: glint judges.
          if [[ " denoise verbose stats strict " != *" $name "* ]] && [ $# -gt 0 ] && [[ $1 != -* ]]; then
            farm_args+=("$1")
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
          case $letter in '?' | i) farm_refuse "-$letter" ;; esac
          if [[ $farm_short_valued != *"$letter"* ]]; then
            flags+=$letter
            continue
          fi
          [ -z "$flags" ] || farm_args+=("-$flags")
          flags=''
          value=${arg:c+1}
          if [ -z "$value" ]; then
            [ $# -gt 0 ] || farm_die "-$letter needs a value"
            value=$1
            shift
          fi
          farm_option "$letter" "${value#=}"
          break
        done
        [ -z "$flags" ] || farm_args+=("-$flags")
        ;;
      *)
        farm_die "unexpected argument '$arg': SCENE is the first argument and the render arguments are options"
        ;;
    esac
  done
}
