#!/usr/bin/env bash
# The preview window's suite (crates/cli/tests/preview.rs): the Xvfb tests need Xvfb.
#   crates/cli/preview-ci.sh install   apt-get xvfb if missing (idempotent)
#   crates/cli/preview-ci.sh test      run the suite; ends with "preview: N passed, N failed"
# Under CI=1 a missing tool fails the tests instead of skipping them.
set -euo pipefail
cd "$(dirname "$0")/../.."

case "${1:-}" in
install)
  missing=()
  command -v Xvfb > /dev/null || missing+=(xvfb)
  if [ ${#missing[@]} -gt 0 ]; then
    SUDO=$([ "$(id -u)" = 0 ] || echo sudo)
    $SUDO apt-get update -qq
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      "${missing[@]}"
  fi
  echo "preview: Xvfb installed"
  ;;
test)
  log=$(mktemp)
  trap 'rm -f "$log"' EXIT
  status=0
  cargo test -p glint --test preview -- --include-ignored 2>&1 | tee "$log" || status=$?
  passed=$(grep -Eo '[0-9]+ passed' "$log" | awk '{s += $1} END {print s + 0}')
  failed=$(grep -Eo '[0-9]+ failed' "$log" | awk '{s += $1} END {print s + 0}')
  if [ "$status" -ne 0 ] && [ "$failed" -eq 0 ]; then failed=1; fi
  echo "preview: $passed passed, $failed failed"
  exit "$status"
  ;;
*)
  echo "usage: $0 install|test" >&2
  exit 2
  ;;
esac
