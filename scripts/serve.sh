#!/usr/bin/env bash
# The page: installs what is missing (scripts/setup.sh), builds the npm
# package into pkg/, then serves www/ (with pkg/ and three.js) on
# http://127.0.0.1:8080/ — PORT=N picks another port, PORT=0 a free one.
# The 50-face sample is meshed on load; open a JSON, IGES or STEP file from
# the page. Ctrl-C stops the server.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"

scripts/setup.sh
node scripts/build-wasm.mjs
echo
echo "== serve: open the URL below in a browser (Ctrl-C stops the server)"
exec node scripts/serve.mjs --port "${PORT:-8080}" --quiet
