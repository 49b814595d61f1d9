#!/usr/bin/env bash
# The browser suite. `web/ci.sh install` installs what it needs (idempotent): Debian's chromium,
# the wasm32 target, wasm-bindgen-cli of the version glint-wasm pins, and the npm packages.
# `web/ci.sh test` builds the page (wasm + bindings) and the CLI, runs the end-to-end tests in
# headless Chromium, and ends with `web: N passed, N failed`.
set -euo pipefail
cd "$(dirname "$0")"

bindgen_version() {
    sed -n 's/^wasm-bindgen = "=\(.*\)"$/\1/p' glint-wasm/Cargo.toml
}

install() {
    if ! command -v chromium >/dev/null 2>&1; then
        sudo=$([ "$(id -u)" = 0 ] || echo sudo)
        $sudo apt-get update
        $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends chromium
    fi
    rustup target add wasm32-unknown-unknown
    version=$(bindgen_version)
    if [ "$(wasm-bindgen --version 2>/dev/null || true)" != "wasm-bindgen $version" ]; then
        # --locked first; the registry mirror may lack a locked dependency, then cargo resolves.
        cargo install --locked wasm-bindgen-cli --version "$version" \
            || cargo install wasm-bindgen-cli --version "$version"
    fi
    npm ci
}

run_tests() {
    missing=""
    command -v chromium >/dev/null 2>&1 || missing="$missing chromium"
    command -v wasm-bindgen >/dev/null 2>&1 || missing="$missing wasm-bindgen"
    [ -d node_modules/playwright-core ] || missing="$missing node_modules"
    if [ -n "$missing" ]; then
        echo "web: missing:$missing (run web/ci.sh install)"
        if [ -n "${CI:-}" ]; then
            echo "web: 0 passed, 1 failed"
            exit 1
        fi
        echo "web: SKIPPED"
        exit 0
    fi
    log=$(mktemp)
    status=0
    npm test 2>&1 | tee "$log" || status=$?
    # node --test ends with "# pass N" / "# fail N" (TAP); a build failure leaves neither.
    passed=$(sed -n 's/^# pass \([0-9]*\)$/\1/p' "$log" | tail -n 1)
    failed=$(sed -n 's/^# fail \([0-9]*\)$/\1/p' "$log" | tail -n 1)
    rm -f "$log"
    if [ -z "$passed" ] || [ -z "$failed" ]; then
        passed=${passed:-0}
        failed=$((${failed:-0} + 1))
    fi
    [ "$status" -eq 0 ] || [ "$failed" -gt 0 ] || failed=1
    echo "web: $passed passed, $failed failed"
    [ "$failed" -eq 0 ]
}

case "${1:-}" in
    install) install ;;
    test) run_tests ;;
    *) echo "usage: web/ci.sh install|test" >&2; exit 2 ;;
esac
