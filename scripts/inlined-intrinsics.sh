#!/usr/bin/env bash
# Checks that the release `glint` calls no SIMD intrinsic out of line. The renderer's kernels
# use `std::arch` intrinsics inside `#[target_feature]` functions, where each inlines to one
# instruction; code that reaches them from a function without those features (a closure, for
# one: it takes the features of the function that defines it, not of the one it is inlined
# into) calls each intrinsic as a function instead, several times slower, with no other sign.
#   scripts/inlined-intrinsics.sh    build the release glint if needed, then check it
# Exits 1 and lists the functions that call `core::core_arch` functions.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet --locked -p glint
binary=${CARGO_TARGET_DIR:-target}/release/glint
listing=$(mktemp)
trap 'rm -f "$listing"' EXIT
objdump -d --no-show-raw-insn -C "$binary" > "$listing"
# The check means nothing on a binary without symbols, or without the kernels.
if ! grep -q '<glint_render::accel::simd::packet_walk::occluded_packet>:' "$listing"; then
  echo "no symbol glint_render::accel::simd::packet_walk::occluded_packet in $binary: cannot check" >&2
  exit 1
fi
# Callers of core::core_arch functions, but for the CPU feature detection of std and
# compiler_builtins (which calls `__cpuid` out of line by design).
callers=$(awk '/^[0-9a-f]+ <.*>:$/ { fn = $0 }
               /call.*<core::core_arch::/ { print fn }' "$listing" |
  grep -v -e '<std_detect::' -e '<compiler_builtins::' | sort | uniq -c || true)
if [ -n "$callers" ]; then
  echo "SIMD intrinsics called out of line (calls, function):" >&2
  echo "$callers" >&2
  exit 1
fi
echo "inlined intrinsics: no out-of-line core::core_arch call in $binary"
