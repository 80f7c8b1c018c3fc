#!/usr/bin/env bash
# Installs saxi 0.15.0 (an AxiDraw driver, from npm) under
# ${CARGO_TARGET_DIR:-target}/saxi, unless it is there already, and prints the
# path of its executable as the last line on stdout (all else goes to stderr).
# tests/saxi.rs reads it from PIXELPIE_SAXI:
#
#     export PIXELPIE_SAXI="$(bash .ci/saxi.sh | tail -n 1)"
#
# saxi is AGPL: a test tool only (it times our SVGs with its motion planner);
# nothing of it ships. `saxi plot` plans and times a plot before it looks for
# a device; it loads its serial-port bindings first, which npm builds with
# node-gyp. Needs Node.js, npm, g++ and make: installed from Debian's apt when
# missing.
set -euo pipefail
cd "$(dirname "$0")/.."

SAXI_VERSION=0.15.0
target=${CARGO_TARGET_DIR:-target}
mkdir -p "$target/saxi"
dir="$(cd "$target/saxi" && pwd)"
saxi="$dir/node_modules/.bin/saxi"

if [ -x "$saxi" ] && grep -q "\"version\": \"$SAXI_VERSION\"" "$dir/node_modules/saxi/package.json" 2>/dev/null; then
    echo "$saxi"
    exit 0
fi
missing=()
command -v npm >/dev/null 2>&1 || missing+=(nodejs npm)
command -v g++ >/dev/null 2>&1 || missing+=(g++)
command -v make >/dev/null 2>&1 || missing+=(make)
if [ ${#missing[@]} -gt 0 ]; then
    export DEBIAN_FRONTEND=noninteractive
    {
        apt-get update -q
        apt-get install -y -q --no-install-recommends "${missing[@]}"
    } >&2
fi
npm install --prefix "$dir" --no-audit --no-fund "saxi@$SAXI_VERSION" >&2
"$saxi" --version >&2
echo "$saxi"
