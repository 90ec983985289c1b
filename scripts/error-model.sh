#!/usr/bin/env bash
# Regenerates crates/lucent/src/bssrdf/error_model.csv, the accuracy
# budget's error and cost model (docs/bssrdf.md §14): Jensen's marble on
# spheres of radius R (scenes/keylight-sphere.toml with units_per_mm =
# 1/R mm) under the key light of that scene ("key") or a constant
# environment alone ("uniform"), rendered by each candidate estimator and
# by the random walk, K seeds each; the error is examples/error_model.rs's
# band error against the walk, the cost the user CPU time per sample
# relative to diffusion with the Burley profile on the same scene.
#
#   scripts/error-model.sh [K [SPP]]      # defaults 4 seeds × 256 spp
#
# 1 thread, niced; about 12 minutes on one core, the walk nearly all of it.
set -euo pipefail
cd "$(dirname "$0")/.."
k=${1:-4}
spp=${2:-256}
radii=${RADII:-"3 10 30 100 300"}
# ℓd of marble's widest channel (red), mm; a test checks it against the preset
ld=8.509
table=crates/lucent/src/bssrdf/error_model.csv
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cargo build --profile quick --bin lucent --example error_model >&2
# a copy: a build while the renders run does not change the binary measured
cp target/quick/lucent "$out/lucent"
bin="$out/lucent"
scene() { # light radius_mm → scene file
    local f="$out/$1-$2.toml"
    local upm
    upm=$(awk "BEGIN { print 1 / $2 }")
    sed -e "s/^units_per_mm = .*/units_per_mm = $upm/" scenes/keylight-sphere.toml >"$f"
    if [ "$1" = uniform ]; then
        # the lamp out, a constant environment in
        awk '/^\[\[shapes\]\]/ { n++ } !(n == 1) { print }' "$f" >"$f.tmp"
        printf '\n[environment]\nradiance = [1.0, 1.0, 1.0]\n' >>"$f.tmp"
        mv "$f.tmp" "$f"
    fi
    echo "$f"
}
render() { # scene name flags… → user seconds summed over the seeds
    local s=$1 name=$2 total=0 t
    shift 2
    for seed in $(seq 1 "$k"); do
        t=$( { TIMEFORMAT=%U; time nice -n 5 "$bin" render "$s" --spp "$spp" --seed "$seed" \
            --threads 1 "$@" -o "$out/$name-$seed.exr" >/dev/null 2>&1; } 2>&1)
        total=$(awk "BEGIN { print $total + $t }")
    done
    echo "$total"
}
{
    echo "# lucent error model: the band error (examples/error_model.rs) of each candidate"
    echo "# estimator's image of a marble sphere against the random walk's, and its cost"
    echo "# per sample relative to diffusion with the Burley profile (user CPU time)."
    echo "# Made by scripts/error-model.sh: scenes/keylight-sphere.toml scaled to radius"
    echo "# radius_mm, light 'key' (its lamp, no environment) or 'uniform' (a constant"
    echo "# environment, no lamp); $k seeds x $spp spp, 48x48, 1 thread; $(date -u +%F)."
    echo "# size_ld = radius / ld of the widest channel ($ld mm); sigma: error's standard error."
    echo "light,radius_mm,size_ld,estimator,error,sigma,cost"
} >"$table.tmp"
for light in key uniform; do
    for r in $radii; do
        s=$(scene "$light" "$r")
        tw=$(render "$s" walk --integrator randomwalk)
        walks=$(for i in $(seq 1 "$k"); do echo "$out/walk-$i.exr"; done)
        tb=$(render "$s" burley --profile burley)
        size=$(awk "BEGIN { printf \"%.4f\", $r / $ld }")
        for est in burley tabulated walk; do
            case $est in
                burley) t=$tb ;;
                tabulated) t=$(render "$s" tabulated --profile tabulated) ;;
                walk) t=$tw ;;
            esac
            if [ "$est" = walk ]; then
                # the walk against itself, half the seeds against the other
                # half: the measurement's noise floor
                half=$((k / 2))
                a=$(for i in $(seq 1 "$half"); do echo "$out/walk-$i.exr"; done)
                b=$(for i in $(seq $((half + 1)) "$k"); do echo "$out/walk-$i.exr"; done)
                # shellcheck disable=SC2086
                read -r e sg < <(target/quick/examples/error_model $a -- $b)
            else
                ests=$(for i in $(seq 1 "$k"); do echo "$out/$est-$i.exr"; done)
                # shellcheck disable=SC2086
                read -r e sg < <(target/quick/examples/error_model $ests -- $walks)
            fi
            cost=$(awk "BEGIN { printf \"%.3f\", $t / $tb }")
            echo "$light,$r,$size,$est,$e,$sg,$cost" | tee -a "$table.tmp" >&2
        done
    done
done
mv "$table.tmp" "$table"
