#!/usr/bin/env bash
# Diffusion against the random walk under one key light, per region of the
# sphere (docs/accuracy.md, "Key light"): renders scenes/keylight-sphere.toml
# (or SCENE) K times with independent seeds each way and prints per region
# (lit half, far half, far rim, whole) and channel diffusion/walk − 1 in
# per cent with its standard error from the seeds' spread, then the same in
# eight bands from the lit limb to the far one.
#
#   scripts/keylight-report.sh [SCENE [K [WALK_SPP [DIFF_SPP]]]]
#
# Defaults: K = 4, 256 spp each way, 1 thread, `--profile quick`; the
# walk is most of the time (~25 s per render at 48² on one core).
# Extra flags for the diffusion renders go in DIFF_FLAGS (e.g.
# `--rmax-quantile 0.9999`). REGIONS="CX CY R" says where the body is
# (default "24 24 20.9", the sphere's disk in the scene's 48² camera;
# "24 17 0" for scenes/keylight-bunny.toml: every lit pixel, the ears
# above row 17).
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/keylight-sphere.toml}
k=${2:-4}
walk_spp=${3:-256}
diff_spp=${4:-256}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cargo build --profile quick --bin lucent --example keylight_regions >&2
diff=() walk=()
for s in $(seq 1 "$k"); do
    # shellcheck disable=SC2086
    target/quick/lucent render "$scene" --spp "$diff_spp" --seed "$s" --threads 1 \
        ${DIFF_FLAGS:-} -o "$out/diff$s.exr" >&2
    target/quick/lucent render "$scene" --integrator randomwalk --spp "$walk_spp" \
        --seed "$s" --threads 1 -o "$out/walk$s.exr" >&2
    diff+=("$out/diff$s.exr") walk+=("$out/walk$s.exr")
done
# shellcheck disable=SC2086
target/quick/examples/keylight_regions ${REGIONS:-24 24 20.9} "${diff[@]}" -- "${walk[@]}"
