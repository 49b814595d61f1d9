#!/usr/bin/env bash
# Checks that the single packages CI builds after `cargo test --workspace` (the CLI for the
# Python, farm and README suites, glint-io's examples, glint-gpu) resolve every dependency with
# the features the workspace gives it. A difference makes Cargo build that dependency and all
# above it again, minutes each time on two cores; crates/workspace-hack is where to add it.
#   scripts/same-features.sh    exit 1 and list the differences, if any
set -euo pipefail
cd "$(dirname "$0")/.."

# "name version features" for every package of a selection, host and target alike.
features() {
  cargo tree --locked "$@" -e features,normal,build,dev -f '{p} {f}' --prefix none |
    grep -E '^[A-Za-z0-9_-]+ v[0-9]' | sed -E 's/ \((\*|proc-macro|\/[^)]*)\)//g' |
    awk '{print $1 "@" $2, ($3 == "" ? "-" : $3)}' | sort -u
}

workspace=$(mktemp)
one=$(mktemp)
trap 'rm -f "$workspace" "$one"' EXIT
features --workspace > "$workspace"
status=0
for selection in "-p glint" "-p glint-io" "-p glint-gpu"; do
  # shellcheck disable=SC2086
  features $selection > "$one"
  differences=$(join -j1 "$workspace" "$one" | awk '$2 != $3 {print "  " $1 ": workspace " $2 ", alone " $3}')
  if [ -n "$differences" ]; then
    echo "$selection resolves features the workspace does not:"
    echo "$differences"
    status=1
  fi
done
[ "$status" = 0 ] && echo "same features: glint, glint-io and glint-gpu build as the workspace does"
exit "$status"
