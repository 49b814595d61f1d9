#!/usr/bin/env bash
# Makes Glint's glTF material test models (scenes/gltf/*.glb, Blender's glTF exporter) and
# then the Blender/Cycles references for every shared and test model
# (crates/io/tests/gltf_refs/*.exr and manifest.json). See crates/io/tests/gltf_refs/README.md.
#
#   scripts/gltf-references.sh [--refs-only] [--spp N] [--only NAME[,NAME...]]
#
# --refs-only keeps the committed models and renders only (Blender's exporter does not write
# byte-identical files from run to run, so remaking the models changes them). The remaining
# arguments go to render-references.py. Installs nothing: it needs Blender 3.4 (Debian's
# `blender`) and python3-numpy (the glTF add-on's import of numpy) on the PATH.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v blender >/dev/null || {
    echo "blender is not installed (Debian: apt-get install blender python3-numpy)" >&2
    exit 1
}
blender_run() {
    blender -b --factory-startup --python-exit-code 1 -P "$@"
}
if [[ "${1:-}" == "--refs-only" ]]; then
    shift
else
    blender_run scripts/blender/make-test-models.py -- scenes/gltf
fi
blender_run scripts/blender/render-references.py -- "$@"
