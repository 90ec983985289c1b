#!/usr/bin/env bash
# The whole test suite, from a fresh Debian 12 machine: installs what is
# missing, checks formatting and lints, runs every test with Embree (both
# backends are compared), then builds and tests the library once more
# without Embree to prove the BVH-only build works, and the BVH tests once
# more on its portable (non-SSE) path.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-deps.sh

cargo fmt --all -- --check
cargo clippy --all-targets -- -D warnings
# Broken intra-doc links are bugs in the docs the module headers promise.
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps
cargo test --all-targets

# The BVH's portable box and triangle tests, which other architectures
# run, forced on x86_64 (only lucent is rebuilt).
echo "--- BVH portable path (--features bvh-portable) ---"
cargo test --lib --test bvh_brute_force --features bvh-portable

# Same target dir: only lucent itself is rebuilt (build.rs reruns when
# LUCENT_NO_EMBREE changes), the dependencies are reused.
echo "--- BVH-only build (LUCENT_NO_EMBREE=1) ---"
LUCENT_NO_EMBREE=1 cargo test --lib --test furnace --test cli
