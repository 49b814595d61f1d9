#!/usr/bin/env bash
# Formats every tracked Rust file; `scripts/fmt.sh --check` changes nothing and fails on a diff.
# `cargo fmt --all` reaches every file of the workspace's crates. The fuzz targets and the
# Python module are crates of their own outside the workspace (fuzz/, python/), so their files
# are given to rustfmt directly.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo fmt --all -- "$@"
git ls-files -z 'fuzz/*.rs' 'python/*.rs' | xargs -0 rustfmt --edition 2021 "$@"
