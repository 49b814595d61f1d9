#!/bin/bash
# Kills a checkpointed render with SIGKILL at a random moment, resumes it to the end, and
# compares the image with an uninterrupted render, bit for bit; ROUNDS times.
#   farm/kill-resume.sh [ROUNDS] [SCENE] [RENDER ARGS...]
# Default: 20 rounds of scenes/three_spheres.xml at 240x180, 16 rpp. Needs the glint binary
# and the exr_compare example (cargo build -p glint --example exr_compare; GLINT and COMPARE
# override their paths). Ends with `kill-resume: N of ROUNDS identical`.
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-20}
scene=${2:-scenes/three_spheres.xml}
shift 2 2> /dev/null || shift $#
args=("$@")
[ ${#args[@]} -gt 0 ] || args=(-w 240 -h 180 -r 16)
glint=${GLINT:-target/debug/glint}
compare=${COMPARE:-target/debug/examples/exr_compare}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
start=$(date +%s%N)
"$glint" render "$scene" "${args[@]}" -o "$work/single.exr" 2> /dev/null
span=$((($(date +%s%N) - start) / 1000000))
same=0
for ((round = 1; round <= rounds; round++)); do
  rm -f "$work/ck.exr" "$work/resumed.exr"
  delay=$((RANDOM % span))
  "$glint" render "$scene" "${args[@]}" -o "$work/resumed.exr" --checkpoint "$work/ck.exr" \
    --checkpoint-every 0 2> /dev/null &
  pid=$!
  sleep "$(awk "BEGIN { print $delay / 1000 }")"
  kill -KILL "$pid" 2> /dev/null || true
  wait "$pid" 2> /dev/null || true
  rows=$([ -f "$work/ck.exr" ] && echo checkpoint || echo "no checkpoint yet")
  "$glint" render "$scene" "${args[@]}" -o "$work/resumed.exr" --resume "$work/ck.exr" 2> /dev/null
  if result=$("$compare" "$work/resumed.exr" "$work/single.exr"); then
    same=$((same + 1))
  fi
  echo "round $round: SIGKILL after $delay ms of ~$span ms ($rows): $result"
done
echo "kill-resume: $same of $rounds identical"
[ "$same" -eq "$rounds" ]
