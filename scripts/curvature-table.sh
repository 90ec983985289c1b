#!/usr/bin/env bash
# Regenerates crates/lucent/src/bssrdf/curvature_table.csv, the curvature table of
# docs/bssrdf.md §10 (what a sphere absorbs against the half-space of the
# same medium, by the random walk's physics). Deterministic for any thread
# count: the same seed gives the same file.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --example curvature_table
target/release/examples/curvature_table crates/lucent/src/bssrdf/curvature_table.csv "$@"
