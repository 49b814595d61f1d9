#!/usr/bin/env bash
# Glint against native Embree 3 on the same rays, in one run (issues 3 and 14). The anchor is
# ../shared/bench/embree_native.cpp (Debian's Embree 3.13, one thread: rtcIntersect1 single rays,
# rtcIntersect1M streams, rtcIntersect8 packets), not the Python binding embreex, which is
# 1.2-1.6x slower than Embree itself.
#
# For the bunny, igea-sub4 and the dragon, and each ray set of `glint bench make-rays` (primary:
# 1024x1024 camera rays row by row; bounce: cosine rays from their hits; shadow: from the same
# points towards a point light; random: origins uniform in the mesh's box, directions uniform on
# the sphere), each of --rounds rounds runs, one after the other: `glint bench rays` single rays,
# (primary rays) Glint packets of 4x2 pixel blocks and of 8x1 pixels, then `embree_native`.
# Prints medians over the rounds (each figure the best of --repeat passes, as both tools report
# it) and the ratios. Build times are both on 1 thread (Glint's `bench rays --threads 1` builds in
# a 1-thread pool; embree_native's device has threads=1), medians over every run of that mesh.
#
# Every query is closest-hit with t in [0, inf) for both engines: embree_native sets tnear 0 and
# tfar inf and has no occlusion mode, so the shadow rays are traced as closest-hit rays by Glint
# too (not `--occlusion`); they end on the light at t = 1, which lies outside the mesh's box, so
# [0, inf) finds what [0, 1) would. `agree`: the fraction of rays whose Glint hit distance
# matches Embree's (both miss, or relative difference <= 1e-4), from
# ../shared/bench/embree_rays.py --compare (Embree 4 via embreex, untimed, once per ray set);
# '-' where embreex is not installed (../shared/bench/setup-peers.sh installs it).
#
#   bench/embree_compare.sh [--rounds K] [--repeat R] [--only NAME] [--sets primary,bounce,...]
#
# Needs g++ and Debian's Embree 3 headers and library (`apt-get install libembree-dev g++`),
# python3 with numpy. embree_native is built into target/embree_native when missing; meshes are
# converted to target/bench-rays/NAME.bin and ray files written there once and reused.
# GLINT=PATH and EMBREE=PATH take binaries built elsewhere (a machine without cargo or g++, such
# as the lent 16-core one): then nothing is built, and RAYS=DIR moves the ray files.
# GLINT=A,B,... runs several glints side by side: in each round every glint's single rays run
# (in alternating order from round to round) next to the same Embree run; the main table is A's
# (with A's packets), and a second table gives every glint's single rays, their ratio to Embree's
# single rays and to A's. A glint given as PATH@WALK runs `bench rays --walk WALK` (auto, avx2
# or scalar): GLINT=G,G@avx2,G@scalar times one binary's walks side by side.
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${SHARED:-../shared}
ROUNDS=3 REPEAT=3 ONLY="" SETS="primary,bounce,shadow,random"
while [ $# -gt 0 ]; do
  case "$1" in
    --rounds) ROUNDS=$2; shift 2 ;;
    --repeat) REPEAT=$2; shift 2 ;;
    --only) ONLY=$2; shift 2 ;;
    --sets) SETS=$2; shift 2 ;;
    *) echo "unknown argument $1" >&2; exit 2 ;;
  esac
done
if [ -z "${GLINT:-}" ]; then
  nice cargo build --release -q -p glint
  GLINT=target/release/glint
fi
FIRST_GLINT=${GLINT%%,*}
FIRST_GLINT=${FIRST_GLINT%@*}
EMBREE=${EMBREE:-target/embree_native}
if [ ! -x "$EMBREE" ]; then
  if [ ! -f /usr/include/embree3/rtcore.h ] || ! command -v g++ >/dev/null; then
    echo "embree_native needs g++ and Embree 3: apt-get install libembree-dev g++" >&2
    exit 1
  fi
  echo "building $EMBREE from $SHARED/bench/embree_native.cpp" >&2
  g++ -O3 -march=native -o "$EMBREE" "$SHARED/bench/embree_native.cpp" -lembree3
fi
RAYS=${RAYS:-target/bench-rays}
mkdir -p "$RAYS"
MESHES=(
  "$SHARED/models/stanford-bunny.obj"
  "$SHARED/models/igea-sub4.ply"
  "$SHARED/scenes/course/willemsen/scenes_B/objFiles/dragon.obj"
)
for mesh in "${MESHES[@]}"; do
  name=$(basename "${mesh%.*}")
  if [ -n "$ONLY" ] && [[ "$name" != *"$ONLY"* ]]; then continue; fi
  if [ ! -f "$RAYS/$name.random.rays" ]; then
    "$FIRST_GLINT" bench make-rays --mesh "$mesh" --out-dir "$RAYS" >&2
  fi
  if [ ! -f "$RAYS/$name.bin" ]; then
    python3 "$SHARED/bench/mesh_to_bin.py" "$mesh" "$RAYS/$name.bin" >&2
  fi
done
HAVE_EMBREEX=0
python3 -c 'import embreex' 2>/dev/null && HAVE_EMBREEX=1

python3 - "$GLINT" "$EMBREE" "$RAYS" "$ROUNDS" "$REPEAT" "$ONLY" "$SETS" "$SHARED" "$HAVE_EMBREEX" "${MESHES[@]}" <<'PY'
import json, os, statistics, subprocess, sys
glints, embree, rays, rounds, repeat, only, sets, shared, have_embreex = sys.argv[1:10]
glints = glints.split(',')
glint = glints[0]
meshes = sys.argv[10:]
rounds, repeat = max(1, int(rounds)), max(1, int(repeat))
sets = sets.split(',')
check = os.path.join(shared, 'bench', 'embree_rays.py')
med = statistics.median

def run(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])

def glint_rays(spec):
    """`bench rays` of a glint given as PATH or PATH@WALK (`--walk WALK`)."""
    path, _, walk = spec.partition('@')
    return [path, 'bench', 'rays'] + (['--walk', walk] if walk else [])

rows, builds = [], {}
for mesh in meshes:
    name = os.path.splitext(os.path.basename(mesh))[0]
    if only and only not in name:
        continue
    gb, eb = builds.setdefault(name, ([], []))
    for kind in sets:
        rayfile = os.path.join(rays, f'{name}.{kind}.rays')
        tfile = os.path.join(rays, f'{name}.{kind}.glint.t')
        common = ['--mesh', mesh, '--rays', rayfile, '--threads', '1', '--repeat', str(repeat)]
        f = {k: [] for k in ('single', 'pkt42', 'pkt81', 'e_single', 'e_stream', 'e_pkt8')}
        each = {g: [] for g in glints}
        for r in range(rounds):
            for g in (glints if r % 2 == 0 else glints[::-1]):
                j = run(glint_rays(g) + common +
                        (['--write-t', tfile] if r == 0 and g == glint else []))
                each[g].append(j['mrays_per_s'])
                if g == glint:
                    gj = j
                elif r == 0 and j['hits'] != gj['hits']:
                    print(f'note: {name} {kind}: {g} {j["hits"]} hits, {glint} {gj["hits"]}',
                          file=sys.stderr)
            f['single'].append(gj['mrays_per_s']); gb.append(gj['build_s'])
            if kind == 'primary':
                f['pkt42'].append(run(glint_rays(glint) + common + ['--packets'])['mrays_per_s'])
                f['pkt81'].append(run(glint_rays(glint) + common + ['--packets', '--consecutive'])['mrays_per_s'])
            ej = run([embree, os.path.join(rays, f'{name}.bin'), rayfile, str(repeat)])
            f['e_single'].append(ej['single_mrays']); f['e_stream'].append(ej['stream_mrays'])
            f['e_pkt8'].append(ej['packet8_mrays']); eb.append(ej['build_s'])
            if r == 0 and gj['hits'] != ej['hits']:
                print(f'note: {name} {kind}: glint {gj["hits"]} hits, embree {ej["hits"]}', file=sys.stderr)
        agree = None
        if have_embreex == '1':
            agree = run(['python3', check, '--mesh', mesh, '--rays', rayfile, '--repeat', '1',
                         '--compare', tfile]).get('agree')
        m = {k: (med(v) if v else None) for k, v in f.items()}
        rows.append((name, kind, gj['rays'], m, agree, {g: med(v) for g, v in each.items()}))
        print(f'{name:16} {kind:8} glint {m["single"]:6.2f}  embree single {m["e_single"]:6.2f} '
              f'stream {m["e_stream"]:6.2f} packet8 {m["e_pkt8"]:6.2f}', file=sys.stderr)

def fmt(x, w=7):
    return f'{"-":>{w}}' if x is None else f'{x:{w}.2f}'

print(f'Glint vs native Embree 3.13 (embree_native), 1 thread, medians of {rounds} alternating rounds, '
      f'each figure the best of {repeat} passes; Mrays/s. Closest hit, t in [0, inf), for every set.')
print('G single: Glint single rays; G 4x2 / G 8x1: Glint packets of 4x2 pixel blocks / of 8 consecutive '
      'rays (primary only); E single / stream / pkt8: rtcIntersect1 / rtcIntersect1M / rtcIntersect8 '
      '(8 consecutive rays: 8x1 pixels of primary rays).')
print('G/E1: G single / E single; G/Ebest: G single / best of E single, stream, pkt8; '
      'pk/E8: G 4x2 / E pkt8; 81/E8: G 8x1 / E pkt8; agree: hit distances matching Embree ray by ray.')
print(f'{"mesh":16} {"rays":8} {"count":>8} {"G single":>8} {"G 4x2":>7} {"G 8x1":>7} {"E single":>8} '
      f'{"E stream":>8} {"E pkt8":>7} | {"G/E1":>5} {"G/Ebest":>7} {"pk/E8":>6} {"81/E8":>6} {"agree":>9}')
ratios = {'G/E1': [], 'G/Ebest': [], 'pk/E8': [], '81/E8': []}
for name, kind, n, m, agree, _ in rows:
    best = max(m['e_single'], m['e_stream'], m['e_pkt8'])
    r1, rb = m['single'] / m['e_single'], m['single'] / best
    rp = m['pkt42'] / m['e_pkt8'] if m['pkt42'] else None
    r8 = m['pkt81'] / m['e_pkt8'] if m['pkt81'] else None
    ratios['G/E1'].append(r1); ratios['G/Ebest'].append(rb)
    if rp: ratios['pk/E8'].append(rp); ratios['81/E8'].append(r8)
    a = '-' if agree is None else f'{agree:.6f}'
    print(f'{name:16} {kind:8} {n:8d} {fmt(m["single"], 8)} {fmt(m["pkt42"])} {fmt(m["pkt81"])} '
          f'{fmt(m["e_single"], 8)} {fmt(m["e_stream"], 8)} {fmt(m["e_pkt8"])} | {r1:5.2f} {rb:7.2f} '
          f'{fmt(rp, 6)} {fmt(r8, 6)} {a:>9}')
print()
print(f'{"build, 1 thread":16} {"glint s":>8} {"embree s":>8} {"ratio":>6}   (medians over every run of the mesh)')
build_ratios = []
for name, (gb, eb) in builds.items():
    if gb:
        build_ratios.append(med(gb) / med(eb))
        print(f'{name:16} {med(gb):8.4f} {med(eb):8.4f} {build_ratios[-1]:6.2f}')
print()
for k, v in ratios.items():
    if v:
        print(f'lowest {k} {min(v):.2f}', end='; ')
print(f'highest build ratio {max(build_ratios):.2f}' if build_ratios else '')
print('targets: G/E1 >= 1.0 on every set, pk/E8 >= 1.0 on primary rays, build ratio <= 1.0')
if len(glints) > 1:
    print()
    print('Single rays of each glint, side by side (medians, Mrays/s; /E1: to Embree single, '
          f'/A: to the first glint): ' + ', '.join(f'{chr(65 + i)} = {g}' for i, g in enumerate(glints)))
    print(f'{"mesh":16} {"rays":8} ' + ' '.join(f'{chr(65 + i):>6} {"/E1":>5} {"/A":>5}'
                                                for i in range(len(glints))))
    for name, kind, n, m, agree, each in rows:
        a = each[glint]
        print(f'{name:16} {kind:8} ' + ' '.join(
            f'{each[g]:6.2f} {each[g] / m["e_single"]:5.2f} {each[g] / a:5.3f}' for g in glints))
PY
