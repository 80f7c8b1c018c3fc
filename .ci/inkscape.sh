#!/usr/bin/env bash
# The Inkscape effect PixelPie ▸ Stipple (python/inkscape/pixelpie_stipple.inx
# and .py, docs/inkscape.md), tested without Inkscape through inkex, the
# extensions' library, from PyPI:
#
# * a venv at ${CARGO_TARGET_DIR:-target}/inkex-venv with inkex 1.4.1, installed
#   with --no-deps (it declares PyGObject, which has no wheel and which only
#   inkex.gui needs) plus what the rest of inkex imports, and pytest;
# * the pixelpie wheel that .ci/python.sh built (${CARGO_TARGET_DIR:-target}/
#   wheels/pixelpie-*.whl) unpacked in ${CARGO_TARGET_DIR:-target}/inkex-pixelpie,
#   not installed: the effect's tests run it with and without the package on
#   PYTHONPATH, so that "no Python package, the binary on PATH" is tested too;
# * inkex's .inx check (python -m inkex.tester.test_inx_file), then
#   python/inkscape/tests against the release binary (PIXELPIE_BIN), with
#   PIXELPIE_EXPECT_PACKAGE=1 so that a missing package fails the tests.
#
# Run after `cargo test --release` and .ci/python.sh (.ci/run does). Only
# PyPI wheels; needs python3 with its venv module (Debian: python3-venv).
set -euo pipefail
cd "$(dirname "$0")/.."

INKEX_VERSION=1.4.1
python=${PYTHON:-python3}
target=${CARGO_TARGET_DIR:-target}
mkdir -p "$target"
target="$(cd "$target" && pwd)"
venv="$target/inkex-venv"
package="$target/inkex-pixelpie"
binary="$target/release/pixelpie"

[ -x "$binary" ] || { echo "inkscape.sh: no $binary: cargo build --release (or cargo test --release) first" >&2; exit 1; }

# A venv left broken (e.g. its Python is gone) is made anew.
if [ -d "$venv" ] && ! "$venv/bin/python" -c '' >/dev/null 2>&1; then
    rm -rf "$venv"
fi
if [ ! -d "$venv" ]; then
    echo "inkscape.sh: creating $venv" >&2
    "$python" -m venv "$venv" >&2
fi
pip=("$venv/bin/python" -m pip --disable-pip-version-check)
if ! "$venv/bin/python" -c "import importlib.metadata as m, sys; sys.exit(m.version('inkex') != '$INKEX_VERSION')" >/dev/null 2>&1; then
    "${pip[@]}" install --quiet --no-deps "inkex==$INKEX_VERSION"
fi
"${pip[@]}" install --quiet --only-binary=:all: "lxml<6" numpy tinycss2 cssselect pyparsing packaging pillow pytest
"$venv/bin/python" -c "import inkex, inkex.tester; print('inkscape.sh: inkex', inkex.__version__)" >&2

# The package, unpacked (an abi3 wheel is a zip of the package's folder).
wheel=("$target"/wheels/pixelpie-*.whl)
if [ ${#wheel[@]} -ne 1 ] || [ ! -f "${wheel[0]}" ]; then
    echo "inkscape.sh: expected one pixelpie wheel in $target/wheels (bash .ci/python.sh builds it), found: ${wheel[*]}" >&2
    exit 1
fi
rm -rf "$package"
"$venv/bin/python" -c "import sys, zipfile; zipfile.ZipFile(sys.argv[1]).extractall(sys.argv[2])" "${wheel[0]}" "$package"

# inkex's own check of the .inx against the script's arguments, and its schema.
(cd python/inkscape && "$venv/bin/python" -m inkex.tester.test_inx_file pixelpie_stipple.inx)

PIXELPIE_BIN="$binary" PIXELPIE_INKEX_PACKAGE="$package" PIXELPIE_EXPECT_PACKAGE=1 \
    "$venv/bin/python" -m pytest -q -p no:cacheprovider python/inkscape/tests
