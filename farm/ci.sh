#!/bin/bash
# The farm suite on a real one-node Slurm (loopback, 2 CPUs).
#   farm/ci.sh install   apt-get slurm-wlm and munge when missing (idempotent)
#   farm/ci.sh test      start munged, slurmctld and slurmd in a temporary folder, then submit
#                        a 4-task array plus the merge job (farm/slurm/submit.sh), wait, compare
#                        the merged image with a single render bit for bit, stop the daemons.
#                        GLINT picks the binary (default: a debug build made here), COMPARE the
#                        exr_compare example (default: built here, in CARGO_TARGET_DIR).
# Without Slurm the test is SKIPPED with a message, but under CI=1 that is a failure.
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
  for tool in munged mungekey slurmctld slurmd sbatch squeue sinfo; do
    command -v "$tool" > /dev/null || cannot "$tool is not installed (run farm/ci.sh install)"
  done
  target=${CARGO_TARGET_DIR:-$repo/target}
  [ -n "${COMPARE:-}" ] || cargo build --quiet -p glint --example exr_compare
  [ -n "${GLINT:-}" ] || cargo build --quiet -p glint
  glint=$(realpath "${GLINT:-$target/debug/glint}")
  compare=$(realpath "${COMPARE:-$target/debug/examples/exr_compare}")

  work=$(mktemp -d /tmp/glint-slurm.XXXXXX)
  pids=()
  stop() {
    for pid in "${pids[@]}"; do kill "$pid" 2> /dev/null || true; done
    for pid in "${pids[@]}"; do wait "$pid" 2> /dev/null || true; done
    rm -rf "$work"
  }
  trap stop EXIT
  mkdir -p "$work/spool" "$work/state" "$work/out"
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
  scene=$(realpath "${FARM_CI_SCENE:-$repo/scenes/three_spheres.xml}")
  read -r -a args <<< "${FARM_CI_ARGS:--w 320 -h 240 -r 36}"
  start=$(date +%s.%N)
  "$glint" render "$scene" "${args[@]}" -n 2 -o "$work/out/single.exr" 2> "$work/single.log"
  single_time=$(awk "BEGIN { print $(date +%s.%N) - $start }")
  for split in tiles samples; do
    start=$(date +%s.%N)
    ids=$(GLINT="$glint" FARM_SPLIT=$split farm/slurm/submit.sh "$scene" 4 \
      "$work/out/$split.exr" "${args[@]}")
    merge=$(echo "$ids" | awk '/^merge/ {print $2}')
    for _ in $(seq 300); do
      [ -z "$(squeue -h -j "$merge" 2> /dev/null)" ] && break
      sleep 0.5
    done
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
  finish
}

case "${1:-}" in
  install) install ;;
  test) test_suite ;;
  *)
    echo "usage: farm/ci.sh install|test" >&2
    exit 2
    ;;
esac
