#!/bin/bash
# Packs what bench/device/run.sh needs on the lent 16-core machine into target/device/
# (ignored, as all of target/): the glint binaries given (default target/release/glint),
# stripped and xz-compressed; embree_native built for x86-64-v3 (the lent machines' CPUs
# differ from this one) with Debian's libembree3 and TBB beside it; the meshes and scenes of
# bench/embree_compare.sh and bench/scaling.py, and the helpers they call. About 30 MB, under
# the 64 MiB a `run` call may carry.
#
# With PERF=1, also this machine's `perf` (Debian's linux-perf) and the libraries it links but
# glibc's own (about 7 MB more, xz-compressed), for run.sh's profiles: the lent machine has
# no perf of its own. Keep the unstripped glints: `perf report` here reads the samples
# brought back against them (by build id, `perf buildid-cache -a GLINT`).
#
# usage: [PERF=1] bash bench/device/pack.sh [NAME=]GLINT ...   (NAME: the binary's name there,
#        so that two builds can be compared side by side; default the file's name)
# then:  run(command="bash bench/device/run.sh", carry=["target/device"], timeout_s=600)
set -euo pipefail
cd "$(dirname "$0")/../.."
SHARED=${SHARED:-../shared}
D=target/device
[ $# -gt 0 ] || set -- target/release/glint
for command in xz strip g++ ldconfig; do
  command -v "$command" > /dev/null || { echo "pack.sh needs $command" >&2; exit 2; }
done
rm -rf "$D"
mkdir -p "$D/bin" "$D/lib" "$D/shared"
for spec in "$@"; do
  name=${spec%%=*}; path=${spec#*=}
  [ "$name" = "$spec" ] && name=$(basename "$path")
  [ -x "$path" ] || { echo "no executable $path (cargo build --release -p glint)" >&2; exit 2; }
  [ -e "$D/bin/$name.xz" ] && { echo "two binaries named $name: name them (NAME=PATH)" >&2; exit 2; }
  strip -o "$D/bin/$name" "$path"
  xz -T0 "$D/bin/$name"
done
g++ -O3 -march=x86-64-v3 -o "$D/bin/embree_native" "$SHARED/bench/embree_native.cpp" -lembree3
for lib in libembree3.so.3 libtbb.so.12; do
  found=$(ldconfig -p | awk -v l="$lib" '$1 == l && /x86-64/ { print $NF; exit }')
  [ -n "$found" ] || { echo "no $lib (apt-get install libembree-dev)" >&2; exit 2; }
  xz -T0 -c "$(readlink -f "$found")" > "$D/lib/$lib.xz"
done
for f in models/stanford-bunny.obj models/igea-sub4.ply \
  scenes/course/willemsen/scenes_A/spheres_1K.xml \
  scenes/course/willemsen/scenes_A/CornellRoom_wMirroredSpheres.xml \
  scenes/course/willemsen/scenes_B/StanfordDragon_Instanced.json \
  scenes/course/willemsen/scenes_B/objFiles/dragon.obj \
  refs/cornell/cornell.json bench/mesh_to_bin.py bench/meshio_min.py bench/embree_rays.py; do
  mkdir -p "$D/shared/$(dirname "$f")"
  cp "$SHARED/$f" "$D/shared/$f"
done
xz -T0 "$D/shared/models/igea-sub4.ply"
if [ "${PERF:-0}" = 1 ]; then
  perf=$(command -v perf) || { echo "PERF=1 needs perf (apt-get install linux-perf)" >&2; exit 2; }
  mkdir -p "$D/perf/lib"
  cp "$(readlink -f "$perf")" "$D/perf/perf"
  ldd "$perf" | awk '$3 ~ /^\// { print $3 }' | while read -r lib; do
    case $(basename "$lib") in libc.so.*|libm.so.*|ld-linux*) continue ;; esac
    cp -L "$lib" "$D/perf/lib/"
  done
  xz -T0 "$D/perf/perf" "$D"/perf/lib/*
fi
du -sh "$D"
