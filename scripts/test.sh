#!/usr/bin/env bash
# The whole test suite, from a fresh Debian 12 machine: installs what is
# missing, checks formatting, lints and rust-version, runs every test with
# the default features (Embree 3, Embree 4 and our BVH, compared), then the BVH tests on
# its portable (non-SSE) path, and lints and tests the build with no default
# feature (`--no-default-features`: our BVH only, no subsurface support) too.
# Every step covers the whole workspace: the library (crates/lucent), the
# measuring tools (crates/lucent-tools) and the command line (the root).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-deps.sh

# The Embree 4 backend's tests run against the 4.4.0 library install-deps.sh
# unpacked (Debian 12 has no Embree 4), and must not skip for want of it.
export LUCENT_EMBREE4="$PWD/.cache/embree4/libembree4.so.4"
export LUCENT_REQUIRE_EMBREE4=1
# The denoise tests run against the Open Image Denoise 2.5.1 it unpacked,
# and must not skip for want of it either.
export LUCENT_OIDN="$PWD/.cache/oidn/lib/libOpenImageDenoise.so.2"
export LUCENT_REQUIRE_OIDN=1

cargo fmt --all -- --check
# rust-version covers every locked dependency; clippy's incompatible_msrv
# (all targets, tests included: clippy.toml) holds our own code to it.
scripts/check-msrv.sh
cargo clippy --workspace --all-targets -- -D warnings
cargo clippy --workspace --no-default-features --all-targets -- -D warnings
# Broken intra-doc links are bugs in the docs the module headers promise.
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps
cargo test --workspace --all-targets

# deploy/ without a cluster: shellcheck, the Kubernetes manifests parsed and
# checked against themselves, their pods' scripts run with the binary just
# built (a 3-part frame, bitwise), hadolint when installed (a few seconds).
LUCENT=$PWD/target/debug/lucent scripts/check-deploy.sh

# A real Slurm cluster of one node (this machine): one frame, a 3-frame
# sequence and a task past its time limit that requeues itself, each frame
# checked bitwise against one process. Needs root and starts daemons, so
# only when asked; .ci/run asks when it runs as root (about 2 min with
# the test binary, plus installing slurm-wlm; docs/farm.md). tests/cli/farm.rs runs a multi-process
# split + merge always.
if [ "${LUCENT_SLURM_TEST:-}" = 1 ]; then
  echo "--- Slurm, one node (LUCENT_SLURM_TEST=1) ---"
  LUCENT=$PWD/target/debug/lucent scripts/slurm-local.sh
fi

# The BVH's portable box and triangle tests, which other architectures
# run, forced on x86_64 (only the workspace's packages are rebuilt).
echo "--- BVH portable path (--features bvh-portable) ---"
cargo test --workspace --features bvh-portable --lib
cargo test --features bvh-portable --test accel -- bvh_brute_force::

# Same target dir: only the workspace's packages are rebuilt, the
# dependencies are reused. The libraries' own tests, and the command-line tests whose
# expectations depend on the features the binary has (`info`, `--accel
# embree` refused with exit 2, a subsurface scene refused with exit 2); the
# Embree and subsurface tests are not built here (required-features), the
# rest test our BVH exactly as above. One build turns off both features:
# no code depends on the two together, so the default build and this one
# compile every gated item both ways (the cheapest addition: no third build).
echo "--- No default features: BVH only, no subsurface (--no-default-features) ---"
cargo test --workspace --no-default-features --lib
cargo test --no-default-features --test cli -- cli:: subsurface_feature::
