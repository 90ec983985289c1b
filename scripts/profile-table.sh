#!/usr/bin/env bash
# Regenerates crates/lucent/src/bssrdf/profile_table.csv, the tabulated
# diffusion profile of docs/bssrdf.md §10 (where light entering the
# half-space leaves it, by the random walk's physics). Deterministic for
# any thread count: the same seed gives the same file.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --example profile_table
target/release/examples/profile_table crates/lucent/src/bssrdf/profile_table.csv "$@"
