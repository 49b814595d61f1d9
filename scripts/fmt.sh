#!/usr/bin/env bash
# Formats every tracked Rust file; `scripts/fmt.sh --check` changes nothing and fails on a diff.
# `cargo fmt` alone does not reach the modules that crates/render/src/lib.rs declares through
# its `internal_modules!` macro (rustfmt does not look inside macro invocations), so each file
# is also given to rustfmt directly.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo fmt --all -- "$@"
git ls-files -z '*.rs' | xargs -0 rustfmt --edition 2021 "$@"
