#!/usr/bin/env bash
# Glint against Embree 4 on the same rays, in one run (issue 3): for each mesh workload of
# `glint bench table` (coherent primary rays of a 1024x1024 camera framing the model,
# cosine bounce rays from their hits, shadow rays to a point light), trace the same ray file
# with `glint bench rays` and with ../shared/bench/embree_rays.py, alternating, ROUNDS times,
# and print the medians and Glint / Embree. Embree also checks Glint's hit distances ray by ray
# (`agree`, which must be at least 0.9999).
#
#   bench/embree_compare.sh [--threads N] [--rounds K] [--repeat R] [--only NAME] [--setup]
#
# --setup runs ../shared/bench/setup-peers.sh first (installs embreex; idempotent).
# Ray files are written once to target/bench-rays/ and reused. Needs python3 with numpy and
# embreex. Takes a few minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${SHARED:-../shared}
THREADS=1 ROUNDS=3 REPEAT=3 ONLY="" SETUP=0
while [ $# -gt 0 ]; do
  case "$1" in
    --threads) THREADS=$2; shift 2 ;;
    --rounds) ROUNDS=$2; shift 2 ;;
    --repeat) REPEAT=$2; shift 2 ;;
    --only) ONLY=$2; shift 2 ;;
    --setup) SETUP=1; shift ;;
    *) echo "unknown argument $1" >&2; exit 2 ;;
  esac
done
if [ "$SETUP" = 1 ]; then
  for try in 1 2 3; do bash "$SHARED/bench/setup-peers.sh" && break || sleep 20; done
fi
cargo build --release -q -p glint
GLINT=target/release/glint
RAYS=target/bench-rays
mkdir -p "$RAYS"
MESHES=(
  "$SHARED/models/stanford-bunny.obj"
  "$SHARED/models/igea-sub4.ply"
  "$SHARED/scenes/course/willemsen/scenes_B/objFiles/dragon.obj"
)
for mesh in "${MESHES[@]}"; do
  name=$(basename "${mesh%.*}")
  if [ -n "$ONLY" ] && [[ "$name" != *"$ONLY"* ]]; then continue; fi
  if [ ! -f "$RAYS/$name.shadow.rays" ]; then
    "$GLINT" bench make-rays --mesh "$mesh" --out-dir "$RAYS" >&2
  fi
done

python3 - "$GLINT" "$RAYS" "$THREADS" "$ROUNDS" "$REPEAT" "$ONLY" "$SHARED" "${MESHES[@]}" <<'PY'
import json, os, statistics, subprocess, sys
glint, rays, threads, rounds, repeat, only, shared = sys.argv[1:8]
meshes = sys.argv[8:]
threads, rounds, repeat = int(threads), int(rounds), int(repeat)
embree = os.path.join(shared, 'bench', 'embree_rays.py')

def run(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])

rows = []
for mesh in meshes:
    name = os.path.splitext(os.path.basename(mesh))[0]
    if only and only not in name:
        continue
    for kind in ('primary', 'bounce', 'shadow'):
        rayfile = os.path.join(rays, f'{name}.{kind}.rays')
        occl = ['--occlusion'] if kind == 'shadow' else []
        tfile = os.path.join(rays, f'{name}.{kind}.glint.t')
        g, e, gb, eb, agree = [], [], [], [], None
        for r in range(rounds):
            common = ['--mesh', mesh, '--rays', rayfile, '--threads', str(threads), '--repeat', str(repeat)] + occl
            gj = run([glint, 'bench', 'rays'] + common + (['--write-t', tfile] if r == 0 else []))
            ej = run(['python3', embree] + common + (['--compare', tfile] if r == 0 else []))
            g.append(gj['mrays_per_s']); e.append(ej['mrays_per_s'])
            gb.append(gj['build_s']); eb.append(ej['build_s'])
            if r == 0:
                agree = ej.get('agree')
                if gj['hits'] != ej['hits']:
                    print(f'note: {name} {kind}: glint {gj["hits"]} hits, embree {ej["hits"]}', file=sys.stderr)
        gm, em = statistics.median(g), statistics.median(e)
        rows.append((name, kind, gj['rays'], gm, em, gm / em, statistics.median(gb), statistics.median(eb), agree))
        print(f'{name:16} {kind:8} glint {gm:7.2f}  embree {em:7.2f}  ratio {gm/em:5.2f}', file=sys.stderr)

print(f'Glint vs Embree 4 (embreex, rtcIntersect1), {threads} thread(s), medians of {rounds} alternating rounds, '
      f'each the best of {repeat} runs; Mrays/s')
print(f'{"mesh":16} {"rays":8} {"count":>8} {"glint":>8} {"embree":>8} {"ratio":>6} {"build glint s":>14} {"build embree s":>15} {"agree":>9}')
for name, kind, n, gm, em, ratio, gb, eb, agree in rows:
    a = '-' if agree is None else f'{agree:.6f}'
    print(f'{name:16} {kind:8} {n:8d} {gm:8.2f} {em:8.2f} {ratio:6.2f} {gb:14.4f} {eb:15.4f} {a:>9}')
worst = min(r[5] for r in rows) if rows else float('nan')
print(f'lowest ratio {worst:.2f} (target >= 0.7); build ratio glint/embree up to '
      f'{max(r[6] / r[7] for r in rows):.2f} (target <= 2)')
PY
