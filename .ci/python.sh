#!/usr/bin/env bash
# Builds the Python package (python/, PyO3 + maturin, an abi3 wheel) into a
# wheel (${CARGO_TARGET_DIR:-target}/wheels/pixelpie-*.whl), installs it in a
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
"${pip[@]}" install --quiet --only-binary=:all: "maturin>=1.9,<2" numpy scipy pytest pillow mypy
# The wheel is built once, into $target/wheels (the only pixelpie wheel
# there), and installed from there: here, and with the vpype extra into the
# vpype venv by .ci/vpype-plugin.sh.
wheels="$target/wheels"
mkdir -p "$wheels"
rm -f "$wheels"/pixelpie-*.whl
PATH="$venv/bin:$PATH" CARGO_TARGET_DIR="$target" "$venv/bin/maturin" build --quiet --release \
    -m python/Cargo.toml -i "$venv/bin/python" -o "$wheels"
wheel=("$wheels"/pixelpie-*.whl)
[ ${#wheel[@]} -eq 1 ] && [ -f "${wheel[0]}" ] || { echo "python.sh: expected one wheel in $wheels, found: ${wheel[*]}" >&2; exit 1; }
"${pip[@]}" install --quiet --force-reinstall --no-deps "${wheel[0]}"
# The vpype plugin's tests run in the vpype venv (.ci/vpype-plugin.sh).
PIXELPIE_BIN="$target/release/pixelpie" "$venv/bin/python" -m pytest -q python/tests \
    --ignore=python/tests/test_vpype_plugin.py
