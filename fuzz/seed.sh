#!/bin/sh
# Seed corpora for the fuzz targets from the course scenes (../shared/scenes/course).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
course="$here/../../shared/scenes/course"
[ -d "$course" ] || { echo "no course corpus at $course" >&2; exit 1; }
for target in xml json obj ply texture scene; do mkdir -p "$here/corpus/$target"; done
find "$course" -name '*.xml' -size -200k -exec cp {} "$here/corpus/xml/" \;
find "$course" -name '*.json' -size -200k -exec cp {} "$here/corpus/json/" \;
find "$course" -name '*.xml' -size -200k -exec cp {} "$here/corpus/scene/" \;
find "$course" -name '*.obj' -size -200k -exec cp {} "$here/corpus/obj/" \;
# The first 2,000 lines of the bigger course meshes (libFuzzer's inputs are small).
for mesh in $(find "$course" -name '*.obj' -size +200k | head -3); do
    head -n 2000 "$mesh" > "$here/corpus/obj/head-$(basename "$mesh")"
done
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1/1/1 2/2/2 3/3/3\n' > "$here/corpus/obj/quad.obj"
find "$course" -name '*.png' -size -64k -exec cp {} "$here/corpus/texture/" \;
# Images: the same PNGs, and the small EXRs (parts, references) of the shared folder.
mkdir -p "$here/corpus/image"
find "$course" -name '*.png' -size -64k -exec cp {} "$here/corpus/image/" \;
find "$here/../../shared" -name '*.exr' -size -64k -exec cp {} "$here/corpus/image/" \;
# PLY: the shared models when present, and two small hand-written ones.
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' > "$here/corpus/ply/ascii.ply"
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n' > "$here/corpus/ply/empty.ply"
# glTF: the shared models (../shared/gltf), GLB and JSON.
mkdir -p "$here/corpus/gltf"
gltf="$here/../../shared/gltf"
[ -d "$gltf" ] && find "$gltf" \( -name '*.gltf' -o -name '*.glb' \) -exec cp {} "$here/corpus/gltf/" \;
echo "seeded: $(for t in xml json obj ply texture image scene; do printf '%s=%s ' $t "$(ls "$here/corpus/$t" | wc -l)"; done)"
