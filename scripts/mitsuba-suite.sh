#!/usr/bin/env bash
# Mitsuba 3's own render tests (../shared/mitsuba/tests/scenes, every folder, media included),
# each scene judged by Mitsuba's rule (crates/render/src/testing/mitsuba_rule.rs): a line per
# scene, a summary line, exit 1 when a scene fails. A failing scene leaves its render, the
# reference and the map of rejected pixels in target/mitsuba-suite/.
#   scripts/mitsuba-suite.sh [filter]   only the scenes whose path contains `filter`
#   scripts/mitsuba-suite.sh --device gpu [filter]
#                                       the surface scenes on the GPU kernel (glint-gpu), by
#                                       the same rule; the volumetric ones are listed as not on
#                                       the GPU, a scene the kernel refuses fails. Failures go
#                                       to target/mitsuba-suite-gpu/.
# Runs in the dev profile, whose glint-render is optimised (Cargo.toml), so that it reuses
# the build of `cargo test --workspace`.
set -euo pipefail
cd "$(dirname "$0")/.."
suite=${GLINT_MITSUBA_SUITE:-../shared/mitsuba/tests/scenes}
if [ ! -d "$suite" ]; then
  if [ -n "${CI:-}" ]; then
    echo "error: Mitsuba's suite $suite is absent (CI is set, so this is a failure)" >&2
    exit 1
  fi
  echo "SKIPPED: Mitsuba's suite $suite is absent"
  exit 0
fi
device=cpu
args=()
while [ $# -gt 0 ]; do
  case $1 in
    --device) device=${2:-}; shift $(($# > 1 ? 2 : 1)) ;;
    --device=*) device=${1#--device=}; shift ;;
    *) args+=("$1"); shift ;;
  esac
done
case $device in
  cpu) out=target/mitsuba-suite ;;
  gpu)
    out=target/mitsuba-suite-gpu
    # Mesa's software Vulkan warns without a private runtime folder (as scripts/test-all.sh).
    if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -d "$XDG_RUNTIME_DIR" ]; then
      XDG_RUNTIME_DIR=$(mktemp -d)
      chmod 700 "$XDG_RUNTIME_DIR"
      export XDG_RUNTIME_DIR
    fi
    ;;
  *) echo "error: --device '$device': expected cpu or gpu" >&2; exit 2 ;;
esac
rm -rf "$out"
exec cargo run --quiet --locked -p glint-io --example mitsuba_suite -- "$suite" "$out" "${args[@]}" --device "$device"
