#!/usr/bin/env bash
# The one test command (README, .ci/run): installs what is missing, builds once, runs every
# suite, and closes with one line per suite and the totals.
#   scripts/test-all.sh              install what is missing, then test everything
#   scripts/test-all.sh --no-install test with what is installed (a suite missing something fails
#                                    under CI=1 and says SKIPPED otherwise)
# Suites: the Rust workspace (`cargo test --workspace`: unit, reference-image, corpus, Mitsuba,
# software-Vulkan GPU tests), the course images bit for bit (scripts/same-images.sh),
# Mitsuba's own test scenes by its rule (scripts/mitsuba-suite.sh), their surface scenes on
# the GPU kernel in software Vulkan (scripts/mitsuba-suite.sh --device gpu), the release binary's SIMD intrinsics inlined (scripts/inlined-intrinsics.sh), every
# README command in a fresh clone (scripts/readme-examples.sh), again as a newcomer without
# ../shared (--newcomer), and each
# front end's own script (`ci.sh install|test`, listed in SUITES below).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

# Suites beyond cargo, each a script with `install` and `test` subcommands.
SUITES=(python/ci.sh web/ci.sh farm/ci.sh crates/cli/preview-ci.sh crates/cli/minimal-ci.sh)
# Installs only: the software Vulkan (Mesa's lavapipe) the GPU tests of `cargo test --workspace`
# render on (under CI=1 they fail without an adapter).
INSTALL_ONLY=(crates/gpu/ci.sh)

install=1
if [ "${1:-}" = "--no-install" ]; then
  install=0
fi

if ! command -v cargo >/dev/null 2>&1; then
  if [ -x "$HOME/.cargo/bin/cargo" ]; then
    export PATH="$HOME/.cargo/bin:$PATH"
  elif [ "$install" = 1 ]; then
    echo "== installing Rust (rustup, stable)"
    curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal
    export PATH="$HOME/.cargo/bin:$PATH"
  else
    echo "error: cargo not found" >&2
    exit 1
  fi
fi

if [ "$install" = 1 ]; then
  for suite in "${INSTALL_ONLY[@]}" "${SUITES[@]}"; do
    echo "== $suite install"
    "$suite" install
  done
fi

logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
declare -A result
# Seconds each suite took, for the summary: CI's time limit is what they add up to.
declare -A took

# Totals from the `test result:` lines cargo prints, one per test binary.
cargo_totals() {
  awk '/^test result:/ { for (i = 1; i <= NF; i++) { if ($i == "passed;") p += $(i-1); if ($i == "failed;") f += $(i-1) } }
       END { printf "%d passed, %d failed", p, f }' "$1"
}

# Mesa warns without a private runtime folder.
if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -d "${XDG_RUNTIME_DIR}" ]; then
  XDG_RUNTIME_DIR=$(mktemp -d)
  chmod 700 "$XDG_RUNTIME_DIR"
  export XDG_RUNTIME_DIR
fi

# The denoise tests (glint-denoise, crates/cli/tests/denoise.rs) need Open Image Denoise: the
# pyoidn wheel that python/ci.sh installs into its venv holds it. Named here, because the
# python3 on the PATH, where glint-denoise would look, is not that venv's.
if [ -z "${GLINT_OIDN_LIB:-}" ] && [ -x python/.venv/bin/python ]; then
  oidn_lib=$(python/.venv/bin/python -c 'import importlib.util as u
s = u.find_spec("pyoidn")
print(s.submodule_search_locations[0] + "/oidn/lib/libOpenImageDenoise.so.2" if s else "")' || true)
  if [ -n "$oidn_lib" ] && [ -f "$oidn_lib" ]; then
    export GLINT_OIDN_LIB="$oidn_lib"
    echo "== Open Image Denoise: $GLINT_OIDN_LIB"
  fi
fi

echo "== cargo test --workspace"
t0=$SECONDS
status=0
cargo test --workspace --locked --no-fail-fast 2>&1 | tee "$logs/cargo.log" || status=$?
result[cargo]="$(cargo_totals "$logs/cargo.log")$([ "$status" = 0 ] || echo " (exit $status)")"
took[cargo]=$((SECONDS - t0))
failed=$status

echo "== course images bit for bit (scripts/same-images.sh)"
t0=$SECONDS
status=0
scripts/same-images.sh 2>&1 | tee "$logs/same-images.log" || status=$?
result[same-images]=$(tail -n 1 "$logs/same-images.log")
took[same-images]=$((SECONDS - t0))
[ "$status" = 0 ] || failed=1

echo "== Mitsuba's test suite by its rule (scripts/mitsuba-suite.sh)"
t0=$SECONDS
status=0
scripts/mitsuba-suite.sh 2>&1 | tee "$logs/mitsuba.log" || status=$?
result[mitsuba-suite]=$(tail -n 1 "$logs/mitsuba.log")
took[mitsuba-suite]=$((SECONDS - t0))
[ "$status" = 0 ] || failed=1

echo "== Mitsuba's test suite on the GPU by its rule (scripts/mitsuba-suite.sh --device gpu)"
t0=$SECONDS
status=0
# An eighth of the rule's samples (at least 64 a pixel, or the rule's own count where lower:
# mitsuba_suite.rs): software Vulkan on CI's two cores would otherwise take a fifth of CI's 90
# minutes here; the Z-test is computed with the samples taken. The rule's full budget passes
# too (bench/results/2026-11-29-gpu-parity.md).
GLINT_SUITE_SAMPLE_BUDGET=250000 scripts/mitsuba-suite.sh --device gpu 2>&1 | tee "$logs/mitsuba-gpu.log" || status=$?
result[mitsuba-suite-gpu]=$(tail -n 1 "$logs/mitsuba-gpu.log")
took[mitsuba-suite-gpu]=$((SECONDS - t0))
[ "$status" = 0 ] || failed=1

echo "== SIMD intrinsics inlined in the release glint (scripts/inlined-intrinsics.sh)"
t0=$SECONDS
status=0
scripts/inlined-intrinsics.sh 2>&1 | tee "$logs/intrinsics.log" || status=$?
result[intrinsics]=$(tail -n 1 "$logs/intrinsics.log")
took[intrinsics]=$((SECONDS - t0))
[ "$status" = 0 ] || failed=1

echo "== README examples in a fresh clone (scripts/readme-examples.sh)"
t0=$SECONDS
status=0
CARGO_TARGET_DIR="$root/target" scripts/readme-examples.sh 2>&1 | tee "$logs/readme.log" || status=$?
result[readme]=$(tail -n 1 "$logs/readme.log")
took[readme]=$((SECONDS - t0))
[ "$status" = 0 ] || failed=1

echo "== README as a newcomer: a fresh clone, no ../shared (scripts/readme-examples.sh --newcomer)"
t0=$SECONDS
status=0
CARGO_TARGET_DIR="$root/target" scripts/readme-examples.sh --newcomer 2>&1 | tee "$logs/newcomer.log" || status=$?
result[newcomer]=$(tail -n 1 "$logs/newcomer.log")
took[newcomer]=$((SECONDS - t0))
[ "$status" = 0 ] || failed=1

for suite in "${SUITES[@]}"; do
  echo "== $suite test"
  t0=$SECONDS
  status=0
  "$root/$suite" test 2>&1 | tee "$logs/suite.log" || status=$?
  result[$suite]="$(tail -n 1 "$logs/suite.log")$([ "$status" = 0 ] || echo " (exit $status)")"
  took[$suite]=$((SECONDS - t0))
  [ "$status" = 0 ] || failed=1
done

echo
echo "== summary"
for name in cargo same-images mitsuba-suite mitsuba-suite-gpu intrinsics readme newcomer "${SUITES[@]}"; do
  printf '%-26s %5s s  %s\n' "$name" "${took[$name]}" "${result[$name]}"
done
if [ "$failed" != 0 ]; then
  echo "FAILED" >&2
  exit 1
fi
echo "all suites passed"
