#!/bin/sh
# Builds what the page needs: the renderer compiled to WebAssembly and its JavaScript bindings,
# into web/pkg/ (not committed).
set -eu
cd "$(dirname "$0")"
target_dir="${CARGO_TARGET_DIR:-$(cd .. && pwd)/target}"
cargo build --release -p glint-wasm --target wasm32-unknown-unknown
wasm-bindgen --target web --no-typescript --out-dir pkg \
    "$target_dir/wasm32-unknown-unknown/release/glint_wasm.wasm"
