#!/usr/bin/env bash
# relMSE×spp and ms/spp on scenes/smooth-sphere.toml (docs/accuracy.md,
# "Smooth sphere"): the default probe-axis rule, the old default (mis3),
# normal-only probes, and the random walk, each against a converged
# reference of its own model (diffusion rows against a diffusion reference,
# the random walk against a random-walk reference), relMSE with ε = 0.01.
# Every figure comes from `lucent study` (results.csv of the runs below).
#
# Usage: scripts/measure-smooth-sphere.sh [options] [-- study options]
#   --out DIR          where the studies go (default: out/measure-smooth-sphere)
#   --width N          image width (default 128; the scene's is 256)
#   --spp N            the ladder's top sample count, where the figures are
#                      read (default 64)
#   --ref-spp N        diffusion reference samples per pixel (default 8192)
#   --rw-ref-spp N     random-walk reference samples per pixel (default 512)
#   --rw-width N       image width of the random-walk rows (default 64: the
#                      walk costs ~50× a diffusion sample per pixel here)
#   --threads N        (default 2)
#   --lucent PATH      the binary (default: target/release/lucent, built)
#   --diffusion NAME 'TOML'
#                      one more diffusion row: the scene with the line(s)
#                      TOML added to its subsurface material (e.g.
#                      'roughness = 0.3'), against its own reference
#   --randomwalk NAME 'TOML'
#                      one more random-walk row, the same way (e.g. a
#                      boundary mode); repeat either option for more rows
#   -- ARGS            passed to every `lucent study` run
#
# The defaults are the run in docs/accuracy.md (about 20 minutes on 2
# busy cores, most of it the two references).
# Prints a Markdown table; the studies' reports and images stay in --out.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
scene="$root/scenes/smooth-sphere.toml"
out="$root/out/measure-smooth-sphere"
width=128
spp=64
ref_spp=8192
rw_ref_spp=512
rw_width=64
threads=2
lucent=""
extra_diff=()
extra_rw=()
pass=()

need() { [[ $# -ge 2 ]] || { echo "$1 needs a value" >&2; exit 2; }; }
while [[ $# -gt 0 ]]; do
    case "$1" in
    --out) need "$@"; out=$2; shift 2 ;;
    --width) need "$@"; width=$2; shift 2 ;;
    --spp) need "$@"; spp=$2; shift 2 ;;
    --ref-spp) need "$@"; ref_spp=$2; shift 2 ;;
    --rw-ref-spp) need "$@"; rw_ref_spp=$2; shift 2 ;;
    --rw-width) need "$@"; rw_width=$2; shift 2 ;;
    --threads) need "$@"; threads=$2; shift 2 ;;
    --lucent) need "$@"; lucent=$2; shift 2 ;;
    --diffusion | --randomwalk)
        [[ $# -ge 3 ]] || { echo "$1 needs NAME and 'TOML'" >&2; exit 2; }
        if [[ $1 == --diffusion ]]; then extra_diff+=("$2" "$3"); else extra_rw+=("$2" "$3"); fi
        shift 3 ;;
    --) shift; pass=("$@"); break ;;
    -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1' "$0"; exit 0 ;;
    *) echo "unknown option $1 (see --help)" >&2; exit 2 ;;
    esac
done

if [[ -z $lucent ]]; then
    (cd "$root" && cargo build --release --quiet)
    lucent="$root/target/release/lucent"
fi
mkdir -p "$out"

# The scene with extra lines in its subsurface material, as DIR/scene.toml
# (the mesh-free scene needs no neighbouring files).
variant() { # dir toml
    mkdir -p "$1"
    awk -v add="$2" '{ print } /^\[materials\.marble\]/ { print add }' "$scene" >"$1/scene.toml"
}

study() { # width scene dir study-args...
    local w=$1 s=$2 d=$3
    shift 3
    "$lucent" study "$s" -o "$d" --threads "$threads" --width "$w" \
        --max-spp "$spp" -q "$@" ${pass[@]+"${pass[@]}"} >&2
}

# One table row from DIR/results.csv: relMSE×spp and ms/spp at the top rung.
row() { # label dir config
    awk -F, -v cfg="$3" -v spp="$spp" -v label="$1" '
        $1 == cfg && $6 == spp {
            printf "| %s | %.4f | %.2f |\n", label, $9 * $6, 1000 * $7 / $6; found = 1
        }
        END { if (!found) printf "| %s | (no row %s at %s spp) | |\n", label, cfg, spp }
    ' "$2/results.csv"
}

rows=()
study "$width" "$scene" "$out/axes" --only axes --reference-spp "$ref_spp"
rows+=("$(row "default (curvature)" "$out/axes" baseline)")
rows+=("$(row "old default (mis3)" "$out/axes" axes=mis3)")
rows+=("$(row "normal only" "$out/axes" axes=normal)")
study "$rw_width" "$scene" "$out/randomwalk" --only integrator --reference randomwalk --reference-spp "$rw_ref_spp"
rows+=("$(row "random walk" "$out/randomwalk" integrator=randomwalk)")

i=0
while [[ $i -lt ${#extra_diff[@]} ]]; do
    name=${extra_diff[$i]}
    d="$out/diffusion-$(echo "$name" | tr -c 'A-Za-z0-9_-' _)"
    variant "$d" "${extra_diff[$((i + 1))]}"
    study "$width" "$d/scene.toml" "$d" --only axes --reference-spp "$ref_spp"
    rows+=("$(row "$name" "$d" baseline)")
    i=$((i + 2))
done
i=0
while [[ $i -lt ${#extra_rw[@]} ]]; do
    name=${extra_rw[$i]}
    d="$out/randomwalk-$(echo "$name" | tr -c 'A-Za-z0-9_-' _)"
    variant "$d" "${extra_rw[$((i + 1))]}"
    study "$rw_width" "$d/scene.toml" "$d" --only integrator --reference randomwalk --reference-spp "$rw_ref_spp"
    rows+=("$(row "$name" "$d" integrator=randomwalk)")
    i=$((i + 2))
done

echo "smooth sphere, ${width} px wide (random walk: ${rw_width}), ${spp} spp, $threads threads (one run; times are wall time of the renders)"
echo
echo "| configuration | relMSE×spp (ε = 0.01) | ms/spp |"
echo "|---|---|---|"
printf '%s\n' "${rows[@]}"
