#!/usr/bin/env bash
# Mitsuba 3's own render tests (../shared/mitsuba/tests/scenes, every folder, media included),
# each scene judged by Mitsuba's rule (crates/render/src/testing/mitsuba_rule.rs): a line per
# scene, a summary line, exit 1 when a scene fails. A failing scene leaves its render, the
# reference and the map of rejected pixels in target/mitsuba-suite/.
#   scripts/mitsuba-suite.sh [filter]   only the scenes whose path contains `filter`
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
rm -rf target/mitsuba-suite
exec cargo run --quiet --locked -p glint-io --example mitsuba_suite -- "$suite" target/mitsuba-suite "$@"
