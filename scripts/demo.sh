#!/usr/bin/env bash
# Installs what is missing, builds lucent and renders the demo scene to
# out/ (EXR + PNG preview). Extra arguments go to `lucent render`.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-deps.sh
cargo build --release
mkdir -p out
./target/release/lucent render scenes/lookdev.toml -o out/lookdev.exr "$@"
