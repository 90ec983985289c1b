#!/usr/bin/env bash
# Regenerates crates/lucent/src/bssrdf/albedo_table.csv, the albedo table of
# docs/bssrdf.md §9 (total diffuse reflectance of a semi-infinite medium
# behind a smooth dielectric boundary, by the random walk's physics).
# Deterministic for any thread count: the same seed gives the same file.
# About 10-18 minutes on 2 shared cores. `--similarity` prints the
# similarity-theory check of §9 instead of writing the table.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --example albedo_table
if [[ "${1:-}" == "--similarity" ]]; then
    exec target/release/examples/albedo_table --similarity
fi
target/release/examples/albedo_table crates/lucent/src/bssrdf/albedo_table.csv "$@"
