#!/usr/bin/env bash
# Every test of the project, from a fresh clone: installs what is missing
# (scripts/setup.sh), then native tests, the no_std build check, docs, the
# benches (built, each run once), the wasm-bindgen-test suite in Node, the npm package build,
# the package's own tests in Node, and a smoke run of the benchmark. Stops at
# the first failure.
set -euo pipefail
cd "$(dirname "$0")/.."
# No step reads input. cargo lets the rustc it runs to probe a target read
# the caller's stdin; text waiting there became the probe's source and a
# failure cargo then cached in target/.rustc_info.json.
exec </dev/null
export PATH="$HOME/.cargo/bin:$PATH"

scripts/setup.sh

step() {
  local name=$1
  shift
  printf '\n== test: %s\n+ %s\n' "$name" "$*"
  local start=$SECONDS
  "$@"
  printf '== test: %s: ok (%d s)\n' "$name" $((SECONDS - start))
}

total=$SECONDS
step "native tests" cargo test
step "no-std core (wasm32v1-none)" cargo rustc --lib --no-default-features --target wasm32v1-none --crate-type rlib
step "docs" env RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --lib
# The criterion benches built in the test profile (reusing the native tests'
# dependencies; an optimized bench build takes minutes on 2 cores) and each
# run once in criterion's test mode, so a bench that breaks fails here.
step "benches (each run once)" cargo test --bench '*'
# The wasm suite runs the mesher for real; unoptimized wasm is ~20x slower.
step "wasm tests in Node" env CARGO_PROFILE_TEST_OPT_LEVEL=2 \
  cargo test --target wasm32-unknown-unknown --test wasm_node
step "npm package build" node scripts/build-wasm.mjs
step "npm package tests in Node" node --test scripts/pkg.test.mjs
# One small surface, one run, the debug runners `cargo test` built: that the benchmark still runs.
step "benchmark smoke run" node --test bench/compare.test.mjs
step "browser tests (page, Vite and Node consumers)" node --test --test-concurrency=1 tests/browser/page.test.mjs tests/browser/consumer.test.mjs
printf '\n== test: all passed (%d s)\n' $((SECONDS - total))
