#!/usr/bin/env bash
# Installs what the build and the tests need, each step skipped when already
# there, so it is cheap to run again: rustup targets and components, the
# wasm-bindgen CLI at the exact version Cargo.lock pins, twiggy (the build's
# size report) at a pinned version, the npm dev
# dependencies (binaryen's wasm-opt, verb-nurbs, playwright-core) and Debian's
# chromium + chromium-driver for the browser tests. Only crates.io, npm,
# Debian and rustup are contacted.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"

say() { printf '== setup: %s\n' "$*"; }

# cargo probes each target by running rustc with its input on /dev/null. A
# /dev/null that some program renamed a plain file over holds whatever was
# last written to it, the probe fails, and cargo caches that failure in
# target/.rustc_info.json. Put the device back (as root) or stop and say so.
if [ ! -c /dev/null ]; then
  if [ "$(id -u)" = 0 ]; then
    say "/dev/null is not the null device: recreating it"
    rm -f /dev/null && mknod -m 666 /dev/null c 1 3
    rm -f target/.rustc_info.json
  else
    echo "== setup: /dev/null is a plain file, not the null device; cargo's target probes will fail" >&2
    exit 1
  fi
fi

installed_targets=$(rustup target list --installed)
for target in wasm32-unknown-unknown wasm32v1-none; do
  if ! grep -qx "$target" <<<"$installed_targets"; then
    say "rustup target add $target"
    rustup target add "$target"
  fi
done

installed_components=$(rustup component list --installed)
for component in rustfmt clippy; do
  if ! grep -q "^$component" <<<"$installed_components"; then
    say "rustup component add $component"
    rustup component add "$component"
  fi
done

# wasm-bindgen CLI: must match the wasm-bindgen crate in Cargo.lock exactly.
bindgen_version=$(awk '$0 == "name = \"wasm-bindgen\"" { getline; gsub(/version = |"/, ""); print; exit }' Cargo.lock)
if [[ -z "$bindgen_version" ]]; then
  echo "setup: no wasm-bindgen in Cargo.lock" >&2
  exit 1
fi
if [[ "$(wasm-bindgen --version 2>/dev/null || true)" != "wasm-bindgen $bindgen_version" ]]; then
  say "cargo install wasm-bindgen-cli $bindgen_version (a few minutes)"
  cargo install wasm-bindgen-cli --version "$bindgen_version" --locked \
    || cargo install wasm-bindgen-cli --version "$bindgen_version" --force
fi

# twiggy: the 20 largest items of each build in the build script's size report.
twiggy_version=0.8.0
if [[ "$(twiggy --version 2>/dev/null || true)" != "twiggy-opt $twiggy_version" ]]; then
  say "cargo install twiggy $twiggy_version (a few minutes)"
  cargo install twiggy --version "$twiggy_version" --locked \
    || cargo install twiggy --version "$twiggy_version" --force
fi

# npm dev dependencies: reinstall only when package-lock.json changed since the last install.
if [[ ! -f node_modules/.package-lock.json || package-lock.json -nt node_modules/.package-lock.json ]]; then
  say "npm ci"
  npm ci --no-audit --no-fund
fi

# Debian's chromium and its driver (browser tests; never a downloaded browser).
if ! command -v chromium >/dev/null || ! command -v chromedriver >/dev/null; then
  say "apt-get install chromium chromium-driver"
  sudo=""
  if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends chromium chromium-driver
fi
say "ready"
