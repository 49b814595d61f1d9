#!/usr/bin/env bash
# Glint's Python suite.
#   python/ci.sh install   idempotent: Debian packages (python3, venv) and a virtual environment
#                          in python/.venv with maturin, numpy, pytest, dask[distributed], ruff,
#                          OpenEXR (the tests' EXR reader), mypy (stubtest) and pyoidn (Open
#                          Image Denoise 2's library, for glint.denoise and, through
#                          scripts/test-all.sh, the Rust denoise tests)
#   python/ci.sh test      builds the wheel once (pip install ./python: maturin, release), builds
#                          the `glint` CLI for the equality tests, runs pytest, ruff, rustfmt and
#                          clippy on the module and ruff on bench/ and scripts/; ends with
#                          `python: N passed, N failed` (the pytest tests and the six lint checks)
# With CI set, anything missing is a failure, never a skip.
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
REPO="$(dirname "$HERE")"
VENV="$HERE/.venv"
REQUIREMENTS=(
    "maturin>=1.16,<2" "numpy>=1.21" "pytest>=7" "dask[distributed]>=2023.1"
    "ruff>=0.6" "OpenEXR>=3.2" "mypy>=1.11" "pyoidn>=2.5,<3"
)

install() {
    if ! command -v python3 >/dev/null || ! python3 -c 'import venv, ensurepip' 2>/dev/null; then
        if command -v apt-get >/dev/null; then
            apt-get update -qq
            DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3 python3-venv python3-pip
        else
            echo "python/ci.sh: need python3 with venv and ensurepip" >&2
            exit 1
        fi
    fi
    if [ ! -x "$VENV/bin/python" ]; then
        python3 -m venv "$VENV"
    fi
    "$VENV/bin/python" -m pip install -q --upgrade pip
    "$VENV/bin/python" -m pip install -q "${REQUIREMENTS[@]}"
    echo "python/ci.sh: installed into $VENV"
}

test_suite() {
    if [ ! -x "$VENV/bin/python" ]; then
        echo "python/ci.sh: no virtual environment in $VENV: run 'python/ci.sh install' first" >&2
        exit 1
    fi
    export PATH="$VENV/bin:$PATH"
    export PYO3_PYTHON="$VENV/bin/python"
    local failed=0

    # The wheel, once, with maturin from the venv (no download: --no-build-isolation).
    pip install -q --no-build-isolation "$HERE"
    # The CLI the equality tests compare with (cached when `cargo test` built it already).
    (cd "$REPO" && cargo build -q -p glint)
    # Where cargo put it: CARGO_TARGET_DIR when set, as cargo itself reads it.
    export GLINT_CLI="${CARGO_TARGET_DIR:-$REPO/target}/debug/glint"

    local report="$HERE/target/pytest-report.txt"
    mkdir -p "$HERE/target"
    # From the tests folder, so `import glint` is the installed wheel, not the source folder.
    (cd "$HERE/tests" && python -m pytest -p no:cacheprovider -q -rs 2>&1) | tee "$report" \
        || failed=1
    # The summary is pytest's last line: "3 failed, 38 passed, 2 skipped in 8.40s".
    local summary passed=0 pytest_failed=0 count
    summary="$(tail -n 1 "$report")"
    passed="$(grep -oE '[0-9]+ passed' <<<"$summary" | grep -oE '[0-9]+' || true)"
    passed="${passed:-0}"
    for count in $(grep -oE '[0-9]+ (failed|errors?)' <<<"$summary" | grep -oE '^[0-9]+' || true); do
        pytest_failed=$((pytest_failed + count))
    done

    local lint_failed=0
    ruff check "$HERE" || lint_failed=$((lint_failed + 1))
    ruff format --check "$HERE" || lint_failed=$((lint_failed + 1))
    # The repository's other Python (bench scripts, scripts/), with ruff's defaults.
    ruff check "$HERE/../bench" "$HERE/../scripts" || lint_failed=$((lint_failed + 1))
    ruff format --check "$HERE/../bench" "$HERE/../scripts" || lint_failed=$((lint_failed + 1))
    cargo fmt --manifest-path "$HERE/Cargo.toml" --check || lint_failed=$((lint_failed + 1))
    cargo clippy -q --manifest-path "$HERE/Cargo.toml" --all-targets -- -D warnings \
        || lint_failed=$((lint_failed + 1))

    local total_failed=$((pytest_failed + lint_failed))
    if [ "$failed" -ne 0 ] && [ "$total_failed" -eq 0 ]; then
        total_failed=1 # pytest failed without a count (collection or usage error)
    fi
    echo "python: $((passed + 6 - lint_failed)) passed, $total_failed failed"
    [ "$total_failed" -eq 0 ]
}

case "${1:-}" in
    install) install ;;
    test) test_suite ;;
    *)
        echo "usage: python/ci.sh install|test" >&2
        exit 2
        ;;
esac
