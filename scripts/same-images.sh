#!/usr/bin/env bash
# Checks that every scene of the course corpus renders bit-identically to the recorded digests
# (scripts/image-digests.txt): every integrator, fixed size, sample count and seed
# (crates/io/examples/image_digest.rs). Run it before and after any change to the renderer.
#   scripts/same-images.sh            compare, exit 1 and list the scenes that changed
#   scripts/same-images.sh --record   rewrite the digests (only for a deliberate, named change)
set -euo pipefail
cd "$(dirname "$0")/.."
corpus=${GLINT_CORPUS:-../shared/scenes/course}
digests=scripts/image-digests.txt
now=$(mktemp)
trap 'rm -f "$now"' EXIT
cargo run --release --quiet -p glint-io --example image_digest -- "$corpus" > "$now"
if [ "${1:-}" = "--record" ]; then
  cp "$now" "$digests"
  echo "recorded $(wc -l < "$digests") digests in $digests"
  exit 0
fi
if diff -u "$digests" "$now"; then
  echo "same images: $(wc -l < "$digests") renders bit-identical to $digests"
else
  echo "images changed: the lines above differ from $digests" >&2
  exit 1
fi
