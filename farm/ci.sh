#!/bin/bash
# The farm suite on a real one-node Slurm (loopback, 2 CPUs).
#   farm/ci.sh install   apt-get slurm-wlm and munge when missing (idempotent)
#   farm/ci.sh test      start munged, slurmctld and slurmd in a temporary folder, then submit
#                        renders with farm/slurm/submit.sh and check them: a 4-task array plus
#                        the merge job, tiles and sample ranges, against a single render bit for
#                        bit; render arguments refused or honoured (-o, -n); a failed task, the
#                        merge that reports it and the resubmit that renders only it; a task
#                        requeued mid-render that resumes from its checkpoint. Stops the daemons.
#                        First, without Slurm: farm/local.sh with -n (honoured) and -o (refused).
#                        GLINT picks the binary (default: a debug build made here), COMPARE the
#                        exr_compare example (default: built here, in CARGO_TARGET_DIR).
# Without Slurm the Slurm cases are SKIPPED with a message (farm/local.sh's still run), but under
# CI=1 that is a failure.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)

install() {
  if command -v slurmctld > /dev/null && command -v slurmd > /dev/null &&
    command -v sbatch > /dev/null && command -v munged > /dev/null; then
    echo "slurm-wlm and munge are installed"
    return
  fi
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y slurm-wlm munge
}

passed=0 failed=0
finish() {
  echo "slurm: $passed passed, $failed failed"
  [ "$failed" -eq 0 ]
}
cannot() {
  if [ -n "${CI:-}" ]; then
    echo "error: $1 (CI is set, so this is a failure)" >&2
    failed=$((failed + 1))
  else
    echo "SKIPPED: $1" >&2
  fi
  finish
  exit
}

test_suite() {
  target=${CARGO_TARGET_DIR:-$repo/target}
  [ -n "${COMPARE:-}" ] || cargo build --quiet -p glint --example exr_compare
  [ -n "${GLINT:-}" ] || cargo build --quiet -p glint
  glint=$(realpath "${GLINT:-$target/debug/glint}")
  compare=$(realpath "${COMPARE:-$target/debug/examples/exr_compare}")

  work=$(mktemp -d /tmp/glint-slurm.XXXXXX)
  pids=()
  stop() {
    # A case that failed can leave jobs queued or running; slurmd does not stop on SIGTERM
    # while a job step runs, so cancel them and let the queue drain first (10 s at most).
    if [ -n "${SLURM_CONF:-}" ]; then
      local left
      left=$(squeue -h -o %A 2> /dev/null | tr '\n' ' ') || true
      if [ -n "${left// /}" ]; then
        # shellcheck disable=SC2086 # a list of job ids
        scancel $left 2> /dev/null || true
        for _ in $(seq 20); do
          [ -z "$(squeue -h 2> /dev/null)" ] && break
          sleep 0.5
        done
      fi
    fi
    for pid in "${pids[@]}"; do kill "$pid" 2> /dev/null || true; done
    # Then SIGKILL whatever of ours did not stop, so that the suite never hangs here.
    for _ in $(seq 20); do
      local alive=0
      for pid in "${pids[@]}"; do kill -0 "$pid" 2> /dev/null && alive=1; done
      [ "$alive" = 0 ] && break
      sleep 0.5
    done
    for pid in "${pids[@]}"; do kill -KILL "$pid" 2> /dev/null || true; done
    for pid in "${pids[@]}"; do wait "$pid" 2> /dev/null || true; done
    rm -rf "$work"
  }
  trap stop EXIT
  mkdir -p "$work/spool" "$work/state" "$work/out"

  # farm/local.sh needs no Slurm: its cases run first, on a small render of the scene below.
  scene=$(realpath "${FARM_CI_SCENE:-$repo/scenes/three_spheres.xml}")
  small=(-w 64 -h 48 -r 16)
  "$glint" render "$scene" "${small[@]}" -n 2 -o "$work/out/small.exr" 2> "$work/small.log"
  case_local

  for tool in munged mungekey slurmctld slurmd sbatch squeue sinfo; do
    command -v "$tool" > /dev/null || cannot "$tool is not installed (run farm/ci.sh install)"
  done
  mungekey --create --keyfile="$work/munge.key" > /dev/null 2>&1 ||
    dd if=/dev/urandom of="$work/munge.key" bs=1024 count=1 2> /dev/null
  chmod 0400 "$work/munge.key"
  munged -F --force --key-file="$work/munge.key" --socket="$work/munge.sock" \
    --pid-file="$work/munged.pid" --log-file="$work/munged.log" \
    --seed-file="$work/munged.seed" > "$work/munged.out" 2>&1 &
  pids+=($!)
  port=$((17000 + RANDOM % 20000))
  cat > "$work/slurm.conf" << CONF
ClusterName=glintci
SlurmctldHost=localhost
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge.sock
CredType=cred/munge
MpiDefault=none
# Many sites do not requeue jobs unless asked: the farm scripts must ask (--requeue).
JobRequeue=0
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SchedulerType=sched/backfill
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
NodeName=localhost NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$work/slurm.conf"
  sleep 1
  slurmctld -D -f "$SLURM_CONF" > "$work/slurmctld.out" 2>&1 &
  pids+=($!)
  slurmd -D -N localhost -f "$SLURM_CONF" > "$work/slurmd.out" 2>&1 &
  pids+=($!)
  up=
  for _ in $(seq 60); do
    if sinfo -h -o %T 2> /dev/null | grep -q idle; then up=1; break; fi
    sleep 1
  done
  if [ -z "$up" ]; then
    tail -5 "$work"/slurmctld.log "$work"/slurmd.log "$work"/munged.log >&2 || true
    cannot "Slurm did not start (one node on loopback)"
  fi
  echo "slurm: one node up ($(sinfo -h -o '%N %c CPUs %T'))"

  # One scene, split two ways: 4 tiles, and 4 sample ranges.
  # FARM_CI_SCENE and FARM_CI_ARGS pick another render (e.g. a longer one to time).
  read -r -a args <<< "${FARM_CI_ARGS:--w 320 -h 240 -r 36}"
  start=$(date +%s.%N)
  "$glint" render "$scene" "${args[@]}" -n 2 -o "$work/out/single.exr" 2> "$work/single.log"
  single_time=$(awk "BEGIN { print $(date +%s.%N) - $start }")
  for split in tiles samples; do
    start=$(date +%s.%N)
    ids=$(GLINT="$glint" FARM_SPLIT=$split farm/slurm/submit.sh "$scene" 4 \
      "$work/out/$split.exr" "${args[@]}")
    merge=$(echo "$ids" | awk '/^merge/ {print $2}')
    wait_for "$merge" || true
    wall=$(awk "BEGIN { print $(date +%s.%N) - $start }")
    if [ ! -f "$work/out/$split.exr" ]; then
      echo "FAILED: $split: no merged image" >&2
      tail -n 5 "$work/out/$split.exr.parts"/*.log >&2 || true
      failed=$((failed + 1))
      continue
    fi
    if result=$("$compare" "$work/out/$split.exr" "$work/out/single.exr"); then
      echo "passed: slurm array of 4 $split + merge == single render: $result"
      passed=$((passed + 1))
    elif [ "$split" = samples ] && [[ $result == differ:* ]]; then
      # Sample ranges add the same samples in another order (README: render farms).
      echo "passed: slurm array of 4 sample ranges + merge: $result (floating-point reassociation)"
      passed=$((passed + 1))
    else
      echo "FAILED: $split: $result" >&2
      failed=$((failed + 1))
    fi
    printf 'slurm: %s: array + merge %.1f s wall, single render (2 threads) %.1f s\n' \
      "$split" "$wall" "$single_time"
  done

  # The cases below use small renders of the same scene ($small), each judged against its own
  # single render.
  case_refused_arguments
  case_threads
  case_failed_part_and_resubmit
  case_requeue
  finish
}

# Waits until job $1 has left the queue (120 s at most). Fails at once when Slurm says it can
# never run (a dependency that can no longer be satisfied), printing the reason.
wait_for() {
  local state
  for _ in $(seq 240); do
    state=$(squeue -h -j "$1" -o '%T %r' 2> /dev/null | sort -u) || true
    [ -n "$state" ] || return 0
    if [[ $state == *DependencyNeverSatisfied* ]]; then
      echo "job $1 can never run: $state" >&2
      return 1
    fi
    sleep 0.5
  done
  echo "job $1 still queued after 120 s: $state" >&2
  return 1
}

# Submits with the suite's glint; the arguments are submit.sh's.
submit() {
  GLINT="$glint" farm/slurm/submit.sh "$@"
}

# A field of `scontrol show job` (e.g. ExitCode, NumCPUs) for job $1, every task on a line.
job_field() {
  scontrol -o show job "$1" | grep -o " $2=[^ ]*" | cut -d= -f2-
}

pass() {
  echo "passed: $1"
  passed=$((passed + 1))
}
fail() {
  echo "FAILED: $1" >&2
  failed=$((failed + 1))
}

# farm/local.sh takes the same render arguments as submit.sh: -n THREADS is each part's thread
# count and the merge is the single render bit for bit; -o is refused with exit 2, a message
# naming it, and nothing written (no parts folder, no image).
case_local() {
  local out="$work/out/local.exr" message rc
  if ! message=$(GLINT="$glint" farm/local.sh "$scene" 2 "$out" "${small[@]}" -n 2 2>&1); then
    fail "local.sh -n 2: $message"
  elif ! result=$("$compare" "$out" "$work/out/small.exr" 2>&1); then
    fail "local.sh -n 2: $result"
  else
    pass "local.sh ... -n 2: 2 parts + merge == single render: $result"
  fi
  out="$work/out/local-o.exr"
  message=$(cd "$work/out" && GLINT="$glint" "$repo/farm/local.sh" "$scene" 2 "$out" \
    "${small[@]}" -o x.png 2>&1) && rc=0 || rc=$?
  if [ "$rc" -ne 2 ] || [[ $message != *"-o cannot be used with farm/local.sh"* ]] ||
    [ -e "$out.parts" ] || [ -e "$out" ] || [ -e "$work/out/x.png" ]; then
    fail "local.sh ... -o x.png: exit $rc, parts folder $([ -e "$out.parts" ] && echo made || echo absent), x.png $([ -e "$work/out/x.png" ] && echo written || echo absent), message: $message"
  else
    pass "local.sh ... -o x.png is refused with exit 2, nothing written: $message"
  fi
}

# Options that render.sbatch sets itself are refused before anything is submitted: exit 2,
# a message naming the option, no parts folder. Each case: the name expected|the arguments.
case_refused_arguments() {
  local cases=("-o|-o x.png" "-o|-ox.png" "--outputfile|--outputfile=x.png" "-o|-vo x.png"
    "--tile|--tile 1/4" "--sample-range|--sample-range=0/2" "--resume|--resume ck.exr"
    "--checkpoint|--checkpoint ck.exr" "--time|--time 10" "--crop-window|--crop-window 0,1,0,1"
    "-x|-x 64" "'extra'|extra")
  local bad=0 i name words out message rc
  for ((i = 0; i < ${#cases[@]}; i++)); do
    name=${cases[i]%%|*}
    read -r -a words <<< "${cases[i]#*|}"
    out="$work/out/refused-$i.exr"
    message=$(submit "$scene" 2 "$out" "${small[@]}" "${words[@]}" 2>&1) && rc=0 || rc=$?
    if [ "$rc" -ne 2 ] || [[ $message != *"$name"* ]] || [ -e "$out.parts" ]; then
      echo "  submit.sh ... ${words[*]}: exit $rc, parts folder $([ -e "$out.parts" ] && echo made || echo absent), message: $message" >&2
      bad=$((bad + 1))
    fi
  done
  if [ "$bad" -gt 0 ]; then
    fail "$bad of ${#cases[@]} kinds of render arguments the farm cannot honour were not refused"
  else
    pass "${#cases[@]} kinds of render arguments the farm cannot honour are refused with exit 2, nothing submitted"
  fi
  message=$(submit "$scene" 2 "$work/out/refused.exr" "${small[@]}" -o x.png 2>&1) || true
  echo "  e.g. $message"
}

# -n THREADS in every form clap takes becomes the tasks' --cpus-per-task (and glint's -n),
# and the image is still the single render's.
case_threads() {
  local forms=("-n 2" "-n2" "--numcpus 2" "--numcpus=2") arrays=() merges=() i ids words cpus out
  for ((i = 0; i < ${#forms[@]}; i++)); do
    read -r -a words <<< "${forms[i]}"
    ids=$(submit "$scene" 2 "$work/out/threads$i.exr" "${small[@]}" "${words[@]}") || true
    arrays+=("$(echo "$ids" | awk '/^array/ {print $2}')")
    merges+=("$(echo "$ids" | awk '/^merge/ {print $2}')")
  done
  for ((i = 0; i < ${#forms[@]}; i++)); do
    out="$work/out/threads$i.exr"
    if [ -z "${merges[i]}" ]; then
      fail "submit.sh ${forms[i]}: refused"
      continue
    fi
    wait_for "${merges[i]}" || scancel "${merges[i]}"
    cpus=$(job_field "${arrays[i]}" NumCPUs | sort -u | tr '\n' ' ')
    if [ "$cpus" != "2 " ]; then
      fail "submit.sh ${forms[i]}: the tasks were given NumCPUs=$cpus, not 2"
    elif ! result=$("$compare" "$out" "$work/out/small.exr" 2>&1); then
      fail "submit.sh ${forms[i]}: $result"
      tail -n 3 "$out.parts"/*.log >&2 || true
    else
      pass "submit.sh ${forms[i]}: tasks with 2 CPUs each, merge == single render: $result"
    fi
  done
}

# A task that fails (a checkpoint it cannot read, as a disk error would leave) ends the
# merge job, which names the part and its log instead of merging; the same command again
# renders only that part, and the merge then equals the single render.
case_failed_part_and_resubmit() {
  local out="$work/out/failed.exr" parts="$work/out/failed.exr.parts" ids merge code
  mkdir -p "$parts"
  echo "not an EXR" > "$parts/part-1.checkpoint.exr"
  ids=$(submit "$scene" 4 "$out" "${small[@]}") || true
  merge=$(echo "$ids" | awk '/^merge/ {print $2}')
  if [ -z "$merge" ] || ! wait_for "$merge"; then
    fail "failed part: the merge job never ran"
    scancel "$merge" 2> /dev/null || true
    return
  fi
  code=$(job_field "$merge" ExitCode)
  if [ -e "$out" ] || [ "$code" = 0:0 ] ||
    ! grep -q "part 1 failed.*part-1.exr.*$parts/part-1.log" "$parts/merge.log" ||
    grep -q "part [023] failed" "$parts/merge.log"; then
    fail "failed part: merge exit $code, image $([ -e "$out" ] && echo written || echo absent), merge.log:"
    cat "$parts/merge.log" >&2
    return
  fi
  pass "a failed task ends the merge job (exit $code), which names part 1 and its log"
  sed 's/^/  merge.log: /' "$parts/merge.log"

  local before after
  before=$(stat -c '%n %i %y' "$parts"/part-{0,2,3}.exr)
  rm "$parts/part-1.checkpoint.exr"
  ids=$(submit "$scene" 4 "$out" "${small[@]}" 2> "$work/resubmit.err") || true
  merge=$(echo "$ids" | awk '/^merge/ {print $2}')
  local array
  array=$(echo "$ids" | awk '/^array/ {print $2}')
  wait_for "$merge" || true
  after=$(stat -c '%n %i %y' "$parts"/part-{0,2,3}.exr)
  local tasks
  tasks=$(scontrol -o show job "$array" | grep -o ' ArrayTaskId=[^ ]*' | cut -d= -f2 | tr '\n' ' ')
  if [ "$before" != "$after" ] || [ "$tasks" != "1 " ]; then
    fail "resubmit: tasks run: $tasks; parts 0, 2, 3 $([ "$before" = "$after" ] && echo kept || echo rendered again)"
  elif ! result=$("$compare" "$out" "$work/out/small.exr" 2>&1); then
    fail "resubmit: $result"
    cat "$parts/merge.log" >&2
  else
    pass "resubmit renders only part 1 ($(cat "$work/resubmit.err")), merge == single render: $result"
  fi

  # Other arguments for the same OUT: refused, unless FARM_RESTART=1 starts over.
  local message
  if message=$(submit "$scene" 4 "$out" -w 64 -h 48 -r 4 2>&1) ||
    [[ $message != *"-r 4"* || $message != *FARM_RESTART=1* ]]; then
    fail "resubmit with -r 4 instead of -r 16 was not refused as it should be: $message"
    return
  fi
  "$glint" render "$scene" -w 64 -h 48 -r 4 -n 2 -o "$work/out/small-r4.exr" 2> /dev/null
  ids=$(FARM_RESTART=1 submit "$scene" 4 "$out" -w 64 -h 48 -r 4) || true
  array=$(echo "$ids" | awk '/^array/ {print $2}')
  merge=$(echo "$ids" | awk '/^merge/ {print $2}')
  wait_for "$merge" || true
  tasks=$(scontrol -o show job "$array" | grep -o ' ArrayTaskId=[^ ]*' | cut -d= -f2 | sort | tr '\n' ' ')
  if [ "$tasks" != "0 1 2 3 " ]; then
    fail "FARM_RESTART=1: tasks run: $tasks, not all 4"
  elif ! result=$("$compare" "$out" "$work/out/small-r4.exr" 2>&1); then
    fail "FARM_RESTART=1: $result"
  else
    pass "other arguments for the same OUT are refused; FARM_RESTART=1 renders all parts again: $result"
  fi
}

# A task requeued mid-render (as preemption does) gets SIGTERM, checkpoints, runs again and
# resumes from its checkpoint; the merge still equals the single render. JobRequeue=0 in this
# cluster's slurm.conf, so this needs the tasks' --requeue.
case_requeue() {
  # Tall enough for eight bands of rows, so that the first checkpoint comes early in the tile.
  local long=(-w 64 -h 128 -r 1024) out="$work/out/requeue.exr" parts="$work/out/requeue.exr.parts"
  local ids array merge state
  "$glint" render "$scene" "${long[@]}" -n 2 -o "$work/out/long.exr" 2> /dev/null
  ids=$(GLINT_CHECKPOINT_EVERY=0 submit "$scene" 2 "$out" "${long[@]}") || true
  array=$(echo "$ids" | awk '/^array/ {print $2}')
  merge=$(echo "$ids" | awk '/^merge/ {print $2}')
  # Requeue task 0 once it has checkpointed part of its tile.
  for _ in $(seq 300); do
    [ -f "$parts/part-0.checkpoint.exr" ] && break
    sleep 0.1
  done
  if [ -f "$parts/part-0.exr" ]; then
    fail "requeue: task 0 finished before it could be requeued (a render too short for this machine)"
    return
  fi
  if ! scontrol requeue "${array}_0" 2> "$work/requeue.err"; then
    fail "scontrol requeue of a running task: $(cat "$work/requeue.err")"
    scancel "$array" "$merge" 2> /dev/null || true
    return
  fi
  # Slurm holds a requeued job back for a while (BeginTime); let it start at once.
  for _ in $(seq 100); do
    state=$(squeue -h -j "${array}_0" -o %T 2> /dev/null) || true
    [ "$state" = PENDING ] && break
    sleep 0.1
  done
  scontrol update JobId="${array}_0" StartTime=now 2> /dev/null || true
  wait_for "$merge" || true
  if ! grep -q "run 2" "$parts/part-0.log" || ! grep -q "resuming" "$parts/part-0.log"; then
    fail "requeue: task 0 did not run again from its checkpoint; its log:"
    cat "$parts/part-0.log" >&2
  elif ! result=$("$compare" "$out" "$work/out/long.exr" 2>&1); then
    fail "requeue: $result"
    cat "$parts/merge.log" >&2
  else
    pass "a task requeued mid-render resumes from its checkpoint ($(grep -o 'resuming.*' "$parts/part-0.log")), merge == single render: $result"
  fi
}

case "${1:-}" in
  install) install ;;
  test) test_suite ;;
  *)
    echo "usage: farm/ci.sh install|test" >&2
    exit 2
    ;;
esac
