#!/usr/bin/env bash
# The GPU back end's suite on Mesa's software Vulkan (lavapipe): no GPU needed.
#
#   crates/gpu/ci.sh install   apt-get the Vulkan loader and Mesa's drivers (idempotent)
#   crates/gpu/ci.sh test      build and run glint-gpu's tests and the CLI's --device tests;
#                              ends with "gpu: N passed, N failed"
#
# Under CI=1 the tests FAIL when no Vulkan adapter is found (without it they print SKIPPED).
set -euo pipefail
cd "$(dirname "$0")/../.."

PACKAGES=(mesa-vulkan-drivers libvulkan1)

install() {
    local missing=()
    for package in "${PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" \
            || missing+=("$package")
    done
    if [ ${#missing[@]} -eq 0 ]; then
        echo "gpu: ${PACKAGES[*]} already installed"
        return
    fi
    local sudo=()
    [ "$(id -u)" -eq 0 ] || sudo=(sudo)
    "${sudo[@]}" apt-get update
    DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y --no-install-recommends \
        "${missing[@]}"
}

run_tests() {
    # Mesa warns when XDG_RUNTIME_DIR is unset or invalid; give it a private folder.
    if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -d "${XDG_RUNTIME_DIR}" ]; then
        XDG_RUNTIME_DIR="$(mktemp -d)"
        chmod 700 "$XDG_RUNTIME_DIR"
        export XDG_RUNTIME_DIR
    fi
    local log
    log="$(mktemp)"
    local status=0
    # glint-gpu's own tests (unit, agreement, pipeline) and the CLI's --device tests.
    cargo test -p glint-gpu -- --nocapture 2>&1 | tee "$log" || status=$?
    cargo test -p glint --test gpu_device -- --nocapture 2>&1 | tee -a "$log" || status=$?
    # libtest's summary lines: "test result: ok. 5 passed; 0 failed; ...".
    local passed failed
    passed=$(grep -Eo '[0-9]+ passed' "$log" | awk '{s += $1} END {print s + 0}')
    failed=$(grep -Eo '[0-9]+ failed' "$log" | awk '{s += $1} END {print s + 0}')
    rm -f "$log"
    if [ "$status" -ne 0 ] && [ "$failed" -eq 0 ]; then
        failed=1
    fi
    echo "gpu: $passed passed, $failed failed"
    [ "$status" -eq 0 ] && [ "$failed" -eq 0 ]
}

case "${1:-}" in
    install) install ;;
    test) run_tests ;;
    *)
        echo "usage: $0 install|test" >&2
        exit 2
        ;;
esac
