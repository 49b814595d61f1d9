#!/bin/bash
# The standard figures of issue 14 on the lent 16-core machine, in one call, from what
# bench/device/pack.sh put into target/device/: Glint against native Embree
# (bench/embree_compare.sh, every glint packed side by side), whole-frame scaling at 1 and
# all threads (bench/scaling.py), the machine's own ceiling (16 single-thread copies at once)
# and the stage times of two 16-thread frames. Each part has a time limit, so that the call
# ends within the 600 s a command may run; what ran is in $OUT (machine.txt, embree.txt,
# scaling.txt, ceiling.txt, stages.txt (with the largest tree's build phases), align.txt:
# each glint's single rays by the stack's place in a cache line, see align_sweep), and printed.
#
# Options by environment: EC (embree_compare.sh's, default "--rounds 3 --repeat 2"), SC
# (scaling.py's, default "--rounds 3"), CE (the ceiling's, default "--size 0.5 --rounds 2"),
# and EC_S, SC_S, CE_S, their limits in seconds (290, 150, 60; CE_S=0 skips the ceiling, which
# `SC="--copies ..."` measures in the frames' own rounds); EC_GLINTS, the glints
# embree_compare.sh runs (default all of them, comma-separated paths under target/device/bin,
# each perhaps with @WALK: `bench rays --walk WALK`).
#
# Where pack.sh packed perf (PERF=1), a last part (limit PF_S, default 70 s; EC_S then
# defaults to 220) profiles the first glint and embree_native, one thread, on the rays
# embree_compare.sh made (PF_SETS, default "dragon.bounce stanford-bunny.primary"): `perf
# stat` of each process (task-clock, and cycles, instructions, branch and cache misses where
# the machine's PMU counts them: clock rate and IPC on that core) and `perf record` samples of
# each (cpu-clock), all in $OUT/prof.tar with their summary (profile.txt; a call brings back
# eight files at most). Read here: `perf buildid-cache -a GLINT` (the
# unstripped binary packed), then `perf report -i FILE.data` or `perf annotate -i FILE.data`.
set -u
cd "$(dirname "$0")/../.."
D=target/device
OUT=${OUT:-/tmp/device-out}
mkdir -p "$OUT"
T0=$(date +%s)
el() { echo "== $1 at $(($(date +%s) - T0)) s"; }
[ -d "$D/bin" ] || { echo "no $D: run bench/device/pack.sh here first, then carry it" >&2; exit 2; }
for f in "$D"/bin/*.xz "$D"/lib/*.xz "$D"/shared/models/*.xz "$D"/perf/*.xz "$D"/perf/lib/*.xz; do
  [ -e "$f" ] && xz -d -f -T0 "$f"
done
chmod +x "$D"/bin/*
export LD_LIBRARY_PATH=$PWD/$D/lib
THREADS=$(nproc)
PERF_BIN=
if [ -e "$D/perf/perf" ]; then
  PERF_BIN=$PWD/$D/perf/perf
  chmod +x "$PERF_BIN"
  : "${EC_S:=220}"
fi
{ lscpu; free -g; } > "$OUT/machine.txt" 2>&1
grep -E "Model name|^CPU\(s\)|Thread" "$OUT/machine.txt"
echo "AVX-512: $(grep -o 'avx512[a-z]*' "$OUT/machine.txt" | sort -u | tr '\n' ' ')"
GLINTS=$(find "$D/bin" -type f ! -name embree_native | sort | paste -sd, -)
FIRST=${GLINTS%%,*}
export SHARED=$PWD/$D/shared RAYS=/tmp/device-rays EMBREE=$PWD/$D/bin/embree_native
el setup
# shellcheck disable=SC2086
GLINT=${EC_GLINTS:-$GLINTS} timeout "${EC_S:-290}" bash bench/embree_compare.sh ${EC:---rounds 3 --repeat 2} \
  > "$OUT/embree.txt" 2> "$OUT/embree.err"
echo "embree_compare: rc $?"
cat "$OUT/embree.txt"
tail -3 "$OUT/embree.err"
el embree
# shellcheck disable=SC2086
PYTHONUNBUFFERED=1 timeout "${SC_S:-150}" python3 bench/scaling.py --glint "$GLINTS" \
  --shared "$SHARED" --threads "1,$THREADS" ${SC:---rounds 3} > "$OUT/scaling.txt" 2>&1
cat "$OUT/scaling.txt"
el scaling
if [ "${CE_S:-60}" != 0 ]; then
  # shellcheck disable=SC2086
  PYTHONUNBUFFERED=1 timeout "${CE_S:-60}" python3 bench/scaling.py --glint "$FIRST" \
    --shared "$SHARED" --ceiling --threads "1,$THREADS" ${CE:---size 0.5 --rounds 2} \
    > "$OUT/ceiling.txt" 2>&1
  cat "$OUT/ceiling.txt"
  el ceiling
fi
C=$SHARED/scenes/course/willemsen
for s in scenes_A/spheres_1K.xml:9 scenes_B/StanfordDragon_Instanced.json:16; do
  echo "${s%%:*}, $THREADS threads: $("$FIRST" render "$C/${s%%:*}" -w 1024 -h 1024 -r "${s##*:}" \
    -n "$THREADS" --stats -o /tmp/device-stages.png 2>&1 | grep -E "^ +(load|hash|build|render|write) |^BVH build phases" \
    | tr -s ' ' | paste -sd';' -)"
done | tee "$OUT/stages.txt"
el stages
# The stack's alignment: the single-ray walks run on the main thread (`--threads 1`), whose
# stack starts below the environment, so the environment's size moves every frame. The
# closest-hit walk writes its entry distances as one 32-byte vector and reads them back 4 bytes
# at a time; Intel cores forward such a store to the loads only when it is 32-byte aligned.
# Builds before 726c52c aligned that buffer to the stack's 16 bytes only, so their speed depended
# on where the stack fell (it is aligned whatever the stack since). The kernel also moves the
# stack by a random multiple of 16 bytes for every process (ASLR), which padding the environment
# alone does not undo (gdb turns ASLR off, so placements checked under it are not the ones a
# plain run gets). So each run goes under `setarch -R` (ASLR off for that process) where the
# machine allows it: an environment 0, 16, 32 and 48 bytes longer then puts the stack at each of
# the four 16-byte places in a 64-byte line: a build before 726c52c, packed beside HEAD, should
# run slow at two of them and HEAD at none. Every glint packed, the paddings alternating,
# AL_ROUNDS times (limit AL_S, default 40 s): Mrays/s by padding. The two speeds were found on
# the lent Xeon: bench/results/2026-11-28-issue14-pass28-xeon-16core-alignment.md.
align_sweep() {
  norand=(setarch "$(uname -m)" -R)
  "${norand[@]}" true 2> /dev/null || {
    echo "setarch -R refused here: ASLR stays on, so the paddings are random places"
    norand=()
  }
  for set in dragon.bounce stanford-bunny.primary; do
    mesh=$(find "$SHARED/models" "$SHARED/scenes" -name "${set%%.*}.*" \( -name '*.obj' -o -name '*.ply' \) | head -1)
    [ -n "$mesh" ] && [ -f "$RAYS/$set.rays" ] || continue
    for round in $(seq "${AL_ROUNDS:-3}"); do
      for glint in ${GLINTS//,/ }; do
        line="$set $(basename "$glint") round $round:"
        for pad in 0 16 32 48; do
          rate=$(env GLINT_PAD="$(head -c "$pad" /dev/zero | tr '\0' a)" "${norand[@]}" "$glint" \
            bench rays --mesh "$mesh" --rays "$RAYS/$set.rays" --threads 1 --repeat 3 | tail -1 \
            | python3 -c 'import json, sys; print(json.load(sys.stdin)["mrays_per_s"])')
          line="$line pad $pad $rate"
        done
        echo "$line"
      done
    done
  done
}
export -f align_sweep
export GLINTS RAYS SHARED
timeout "${AL_S:-40}" bash -c align_sweep | tee "$OUT/align.txt"
el align
if [ -n "$PERF_BIN" ]; then
  P=/tmp/device-prof
  rm -rf "$P"; mkdir -p "$P"
  perf_run() { LD_LIBRARY_PATH=$PWD/$D/perf/lib:$LD_LIBRARY_PATH timeout 30 "$PERF_BIN" "$@"; }
  EVENTS=task-clock,cycles,instructions,branches,branch-misses,L1-dcache-load-misses,LLC-load-misses
  profile() {
    for set in ${PF_SETS:-dragon.bounce stanford-bunny.primary}; do
      mesh=$(find "$SHARED/models" "$SHARED/scenes" -name "${set%%.*}.*" \( -name '*.obj' -o -name '*.ply' \) | head -1)
      rays=$RAYS/$set.rays
      [ -n "$mesh" ] && [ -f "$rays" ] || { echo "profile: no mesh or rays for $set"; continue; }
      glint=("$FIRST" bench rays --mesh "$mesh" --rays "$rays" --threads 1 --repeat 5)
      embree=("$EMBREE" "$RAYS/${set%%.*}.bin" "$rays" 5)
      perf_run stat -x, -e "$EVENTS" -o "$P/glint-$set.stat" -- "${glint[@]}" > "$P/glint-$set.json"
      perf_run stat -x, -e "$EVENTS" -o "$P/embree-$set.stat" -- "${embree[@]}" > "$P/embree-$set.json"
      perf_run record -q -e cpu-clock -F 4000 -o "$P/glint-$set.data" -- "${glint[@]}" > /dev/null
      perf_run record -q -e cpu-clock -F 4000 -o "$P/embree-$set.data" -- "${embree[@]}" > /dev/null
      for f in "$P/glint-$set.stat" "$P/embree-$set.stat"; do
        echo "$(basename "$f"): $(grep -v '^#' "$f" | grep . | awk -F, '{ printf "%s %s; ", $3, $1 }')"
      done
    done
  }
  export -f perf_run profile
  export PERF_BIN D P EVENTS FIRST EMBREE RAYS SHARED
  timeout "${PF_S:-70}" bash -c profile | tee "$P/profile.txt"
  tar cf "$OUT/prof.tar" -C "$P" .
  el profile
fi

