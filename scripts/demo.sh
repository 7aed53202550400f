#!/usr/bin/env bash
# The main job: builds the command line (release) and meshes the bundled
# freeform sample at a relative tolerance of 1e-3, writing out/sample.stl and
# the measured report out/report.json.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"

mkdir -p out
cargo run --release --bin surfmesh -- mesh tests/data/js_freeform.json --tol-rel 0.001 \
  -o out/sample.stl --report out/report.json
echo
echo "wrote out/sample.stl ($(wc -c <out/sample.stl) bytes) and out/report.json:"
cat out/report.json
