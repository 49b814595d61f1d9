#!/usr/bin/env bash
# Runs every command of README.md's ```sh blocks as written, in order, in a fresh clone of this
# repository's committed HEAD, so that the README stays true for a new user: the install line
# puts `glint` on PATH (installed under a temporary CARGO_INSTALL_ROOT, not your ~/.cargo), and
# each later `glint` command must exit 0 and write the files it names with -o / --heatmap.
#
# Two ways, each a suite of scripts/test-all.sh:
#   scripts/readme-examples.sh              with ../shared (the course corpus) beside the clone:
#                                           every command
#   scripts/readme-examples.sh --newcomer   as someone who found Glint on its own: no ../shared
#                                           anywhere near the clone, every command that does
#                                           not name ../shared (those are listed, not run), and
#                                           afterwards no image or untracked file written
#                                           into the clone outside renders/
#
# A few commands are not run, each for the reason printed (the test suite itself, benchmarks
# that need Embree or Mitsuba or take minutes); for those the script checks that the program
# they call exists.
#
#   CARGO_TARGET_DIR=$PWD/target scripts/readme-examples.sh   reuse this checkout's build
#                                               (default: one build inside the clone)
#   GLINT_SHARED=/path/to/shared                the course corpus (default: ../shared)
#
# Ends with `readme-examples: N passed, N failed` (`newcomer: ...` with --newcomer); exits 1 if
# any failed.
set -uo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
name=readme-examples
newcomer=0
if [ "${1:-}" = "--newcomer" ]; then
  name=newcomer
  newcomer=1
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [ "$newcomer" = 1 ]; then
  # Nothing named shared beside the clone, and none up the tree either.
  for dir in "$work" "$(dirname "$work")"; do
    if [ -e "$dir/shared" ]; then
      echo "$name: $dir/shared exists: the clone would not stand alone" >&2
      echo "$name: 0 passed, 1 failed"
      exit 1
    fi
  done
else
  shared=${GLINT_SHARED:-$repo/../shared}
  if [ ! -d "$shared/scenes/course" ]; then
    echo "$name: $shared/scenes/course is missing (set GLINT_SHARED)" >&2
    echo "$name: 0 passed, 1 failed"
    exit 1
  fi
fi
git clone --quiet "$repo" "$work/glint"
[ "$newcomer" = 1 ] || ln -s "$(cd "$shared" && pwd)" "$work/shared"
export CARGO_INSTALL_ROOT="$work/root"
# `cargo install` builds in a temporary directory of its own unless told otherwise: share one
# with the README's `cargo run --release` so the release build is made once.
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$work/glint/target}"
export PATH="$CARGO_INSTALL_ROOT/bin:$PATH"
cd "$work/glint" || exit 1

# The commands of the ```sh blocks, one per line (comments after `#` kept: bash drops them).
mapfile -t commands < <(awk '/^```sh$/ {inside = 1; next} /^```$/ {inside = 0} inside && NF' README.md)

# Not run, with the reason; the first word of the command must still exist.
not_run_reason() {
  case "$1" in
    "cargo test --workspace"* | scripts/test-all.sh*) echo "the test suite itself (CI runs it)" ;;
    "crates/gpu/ci.sh test"*) echo "the GPU tests, which cargo test --workspace runs" ;;
    *"-- bench table"*) echo "a benchmark of several minutes" ;;
    bench/embree_compare.sh*) echo "needs native Embree 3, libembree-dev (see bench/README.md)" ;;
    farm/slurm/submit.sh*) echo "needs a Slurm cluster (farm/ci.sh test starts one and runs it)" ;;
    *"npm run serve"*) echo "serves the page until stopped (web/ci.sh test serves and tests it)" ;;
    bench/cornell_vs_mitsuba.py*) echo "needs Mitsuba 3 (see bench/README.md)" ;;
    *) return 1 ;;
  esac
}

passed=0
failed=0
for command in "${commands[@]}"; do
  if [ "$newcomer" = 1 ] && [[ $command == *../shared* ]]; then
    echo "not run (needs the course corpus, ../shared): $command"
    continue
  fi
  if reason=$(not_run_reason "$command"); then
    program=${command#(}
    program=${program%% *}
    if [ -x "$program" ] || command -v "$program" >/dev/null; then
      echo "not run ($reason): $command"
    else
      echo "FAILED: $command: $program does not exist or is not executable"
      failed=$((failed + 1))
    fi
    continue
  fi
  echo "running: $command"
  bash -c "$command" > "$work/out.txt" 2>&1
  status=$?
  if [ "$status" -ne 0 ]; then
    echo "FAILED (exit $status): $command"
    sed 's/^/    /' "$work/out.txt"
    failed=$((failed + 1))
    continue
  fi
  # Every file it says it writes must be there.
  missing=""
  read -ra words <<< "$command"
  for ((i = 0; i < ${#words[@]} - 1; i++)); do
    case "${words[i]}" in
      -o | --outputfile | --heatmap) [ -s "${words[i + 1]}" ] || missing="$missing ${words[i + 1]}" ;;
    esac
  done
  if [ -n "$missing" ]; then
    echo "FAILED: $command: did not write$missing"
    failed=$((failed + 1))
  elif [[ $command == cargo\ install* ]] && [ "$(command -v glint)" != "$CARGO_INSTALL_ROOT/bin/glint" ]; then
    echo "FAILED: $command: glint is not on PATH afterwards"
    failed=$((failed + 1))
  else
    passed=$((passed + 1))
  fi
done
if [ "$newcomer" = 1 ]; then
  # The README's images go to renders/ (ignored). Besides build outputs that .gitignore names
  # (target/, web/pkg/, web/node_modules/), nothing may appear in the clone: no untracked file,
  # and no image anywhere else.
  stray=$(git status --porcelain --ignored --untracked-files=all |
    awk '$1 == "??" || $2 ~ /\.(png|exr|hdr|pfm|jpg)$/ {print $2}' |
    grep -v -e '^renders/' -e '^target/' -e '^web/node_modules/' || true)
  if [ -n "$stray" ]; then
    echo "FAILED: the commands wrote into the clone outside renders/:"
    echo "$stray" | sed 's/^/    /'
    failed=$((failed + 1))
  else
    passed=$((passed + 1))
  fi
fi
echo "$name: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
