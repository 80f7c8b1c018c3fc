#!/usr/bin/env bash
# Builds the Python package (python/, PyO3 + maturin, an abi3 wheel) into a
# virtual environment at ${CARGO_TARGET_DIR:-target}/py-venv and runs its
# pytest suite, which compares with the release binary
# (${CARGO_TARGET_DIR:-target}/release/pixelpie, built by `cargo test
# --release` before this runs).
#
# The wheel is built with the workspace's target directory, so the lean
# library and the dependencies it shares with the binary are not compiled
# again from scratch. numpy, scipy, pytest and maturin come from PyPI wheels.
set -euo pipefail
cd "$(dirname "$0")/.."

python=${PYTHON:-python3}
target=${CARGO_TARGET_DIR:-target}
mkdir -p "$target"
target="$(cd "$target" && pwd)"
venv="$target/py-venv"

if [ -d "$venv" ] && ! "$venv/bin/python" -c '' >/dev/null 2>&1; then
    rm -rf "$venv"
fi
if [ ! -d "$venv" ]; then
    "$python" -m venv "$venv"
fi
pip=("$venv/bin/python" -m pip --disable-pip-version-check)
"${pip[@]}" install --quiet --only-binary=:all: "maturin>=1.9,<2" numpy scipy pytest
PATH="$venv/bin:$PATH" CARGO_TARGET_DIR="$target" "${pip[@]}" install --quiet --no-build-isolation --force-reinstall --no-deps ./python
PIXELPIE_BIN="$target/release/pixelpie" "$venv/bin/python" -m pytest -q python/tests
