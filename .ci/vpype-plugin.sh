#!/usr/bin/env bash
# The vpype plugin (`vpype pixelpie`, python/pixelpie/vpype_plugin.py) and the
# G-code and HPGL pipelines through vpype, tested with vpype from PyPI:
#
# * installs the wheel that .ci/python.sh built (${CARGO_TARGET_DIR:-target}/
#   wheels/pixelpie-*.whl) with its `vpype` extra into the vpype venv that
#   .ci/vpype.sh made (${CARGO_TARGET_DIR:-target}/vpype-venv), with
#   vpype-gcode (G-code through vpype) and pytest;
# * runs python/tests/test_vpype_plugin.py there, against the release binary
#   (PIXELPIE_BIN), with PIXELPIE_EXPECT_VPYPE=1 so that a missing vpype or
#   vpype-gcode fails the tests instead of skipping them.
#
# Run after .ci/vpype.sh and .ci/python.sh (.ci/run does). Only PyPI wheels.
set -euo pipefail
cd "$(dirname "$0")/.."

VPYPE_GCODE_VERSION=0.13.0
target=${CARGO_TARGET_DIR:-target}
mkdir -p "$target"
target="$(cd "$target" && pwd)"
venv="$target/vpype-venv"

"$(bash .ci/vpype.sh | tail -n 1)" --version >&2
wheel=("$target"/wheels/pixelpie-*.whl)
if [ ${#wheel[@]} -ne 1 ] || [ ! -f "${wheel[0]}" ]; then
    echo "vpype-plugin.sh: expected one pixelpie wheel in $target/wheels (bash .ci/python.sh builds it), found: ${wheel[*]}" >&2
    exit 1
fi
pip=("$venv/bin/python" -m pip --disable-pip-version-check)
"${pip[@]}" install --quiet --only-binary=:all: "vpype-gcode==$VPYPE_GCODE_VERSION" pytest
# The extra's dependency (vpype) is already there at the pinned version; the
# wheel itself is put in anew even when its version number is unchanged.
"${pip[@]}" install --quiet --only-binary=:all: "${wheel[0]}[vpype]"
"${pip[@]}" install --quiet --force-reinstall --no-deps "${wheel[0]}"
PIXELPIE_BIN="$target/release/pixelpie" PIXELPIE_EXPECT_VPYPE=1 \
    "$venv/bin/python" -m pytest -q python/tests/test_vpype_plugin.py
