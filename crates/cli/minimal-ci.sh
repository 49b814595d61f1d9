#!/usr/bin/env bash
# The `glint` without default features (`cargo install --path crates/cli --no-default-features`):
# it compiles none of wgpu, naga, nv-flip and minifb, passes clippy, and its own tests
# (crates/cli/tests/minimal_build.rs) render a course scene and refuse what needs a feature.
#   crates/cli/minimal-ci.sh install   nothing to install
#   crates/cli/minimal-ci.sh test      run the checks; ends with "minimal: N passed, N failed"
set -euo pipefail
cd "$(dirname "$0")/../.."

case "${1:-}" in
install)
  echo "minimal: nothing to install"
  ;;
test)
  log=$(mktemp)
  trap 'rm -f "$log"' EXIT
  status=0
  heavy=$(cargo tree --locked -p glint --no-default-features -e normal --prefix none |
    grep -Eo '^(wgpu|naga|nv-flip|minifb)[a-z-]* ' | sort -u || true)
  if [ -n "$heavy" ]; then
    echo "error: the build without default features compiles $(echo "$heavy" | tr "\n" " ")" >&2
    status=1
  fi
  cargo clippy --locked -p glint --all-targets --no-default-features -- -D warnings || status=1
  cargo test --locked -p glint --no-default-features --test minimal_build 2>&1 | tee "$log" ||
    status=1
  passed=$(grep -Eo '[0-9]+ passed' "$log" | awk '{s += $1} END {print s + 0}')
  failed=$(grep -Eo '[0-9]+ failed' "$log" | awk '{s += $1} END {print s + 0}')
  if [ "$status" -ne 0 ] && [ "$failed" -eq 0 ]; then failed=1; fi
  echo "minimal: $passed passed, $failed failed"
  exit "$status"
  ;;
*)
  echo "usage: $0 install|test" >&2
  exit 2
  ;;
esac
