#!/usr/bin/env bash
# Installs vpype (the pen-plotter toolkit, from PyPI) in a virtual environment
# at ${CARGO_TARGET_DIR:-target}/vpype-venv, unless it is there already, and
# prints the path of its vpype executable as the last line on stdout (all else
# goes to stderr). tests/vpype.rs reads vpype from PIXELPIE_VPYPE:
#
#     export PIXELPIE_VPYPE="$(bash .ci/vpype.sh | tail -n 1)"
#
# Needs python3 3.11 to 3.13 (vpype 1.15's range; PYTHON=... picks another
# interpreter) with its venv module: on Debian `apt-get install -y python3-venv`.
# Every dependency installs from PyPI wheels (numpy, scipy, shapely, ...): no
# compiler is needed.
set -euo pipefail
cd "$(dirname "$0")/.."

VPYPE_VERSION=1.15.0
python=${PYTHON:-python3}
target=${CARGO_TARGET_DIR:-target}
mkdir -p "$target"
venv="$(cd "$target" && pwd)/vpype-venv"
vpype="$venv/bin/vpype"

# Already installed at the pinned version: nothing to do (no network).
if "$venv/bin/python" -c "import importlib.metadata as m, sys; sys.exit(m.version('vpype') != '$VPYPE_VERSION')" >/dev/null 2>&1 \
    && [ -x "$vpype" ]; then
    echo "$vpype"
    exit 0
fi

if ! command -v "$python" >/dev/null 2>&1; then
    echo "vpype.sh: no $python: install Python 3.11-3.13 (Debian: apt-get install -y python3 python3-venv)" >&2
    exit 1
fi
if ! "$python" -c 'import sys; sys.exit(not ((3, 11) <= sys.version_info[:2] <= (3, 13)))'; then
    echo "vpype.sh: vpype $VPYPE_VERSION needs Python 3.11 to 3.13, $python is $("$python" --version 2>&1); set PYTHON to another interpreter" >&2
    exit 1
fi
if ! "$python" -c 'import venv, ensurepip' >/dev/null 2>&1; then
    echo "vpype.sh: $python lacks the venv module: on Debian, apt-get install -y python3-venv" >&2
    exit 1
fi

# A venv left broken (e.g. its Python is gone) is made anew.
if [ -d "$venv" ] && ! "$venv/bin/python" -c '' >/dev/null 2>&1; then
    rm -rf "$venv"
fi
if [ ! -d "$venv" ]; then
    echo "vpype.sh: creating $venv" >&2
    "$python" -m venv "$venv" >&2
fi
echo "vpype.sh: installing vpype==$VPYPE_VERSION" >&2
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --only-binary=:all: "vpype==$VPYPE_VERSION" >&2
"$vpype" --version >&2
echo "$vpype"
