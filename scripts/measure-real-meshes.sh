#!/usr/bin/env bash
# relMSE×spp and ms/spp of the default estimator at 16, 64 and 256 spp on
# scenes/smooth-sphere.toml, scenes/smooth-bunny.toml and
# scenes/thin-shapes.toml (docs/accuracy.md, "Real meshes"): each scene at
# WIDTH² against a reference of the same binary and options at REF_SPP
# (seed 99; the test renders use seed 7), relMSE = mean over pixels and
# channels of (I − R)²/(R² + 0.01). Also prints the share of the error in
# the 5 worst pixels (a heavy tail puts most of it there).
#
# Usage: scripts/measure-real-meshes.sh [--lucent PATH] [--out DIR]
#        [--width N] [--ref-spp N] [--threads N] [-- render options]
# Needs oiiotool (to read the EXRs) and python3. Defaults: the release
# binary (built), out/measure-real-meshes, 128, 4096, 2 threads.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/out/measure-real-meshes"
width=128
ref_spp=4096
threads=2
lucent=""
pass=()
need() { [[ $# -ge 2 ]] || { echo "$1 needs a value" >&2; exit 2; }; }
while [[ $# -gt 0 ]]; do
    case "$1" in
    --lucent) need "$@"; lucent=$2; shift 2 ;;
    --out) need "$@"; out=$2; shift 2 ;;
    --width) need "$@"; width=$2; shift 2 ;;
    --ref-spp) need "$@"; ref_spp=$2; shift 2 ;;
    --threads) need "$@"; threads=$2; shift 2 ;;
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

# relMSE of TEST against REF, and the 5 worst pixels' share of it.
relmse() { # ref test
    python3 - "$1" "$2" <<'PY'
import re, subprocess, sys
def load(p):
    out = subprocess.run(["oiiotool", "-v", "--dumpdata", p], capture_output=True, text=True, check=True).stdout
    return {(int(m[1]), int(m[2])): [float(m[i]) for i in (3, 4, 5)]
            for m in re.finditer(r"Pixel \((\d+), (\d+)\): (\S+) (\S+) (\S+)", out)}
ref, test = load(sys.argv[1]), load(sys.argv[2])
e = sorted((sum((t - r) ** 2 / (r * r + 0.01) for t, r in zip(test[k], ref[k])) / 3 for k in ref), reverse=True)
print(f"{sum(e) / len(e):.6g} {sum(e[:5]) / sum(e):.3f}")
PY
}

echo "| scene | spp | relMSE×spp | top-5 share | ms/spp |"
echo "|---|---|---|---|---|"
for s in smooth-sphere smooth-bunny thin-shapes; do
    # the scene at WIDTH², meshes found from the copy
    sed -e "s/resolution = \[256, 256\]/resolution = [$width, $width]/" \
        -e "s#\"meshes/#\"$root/scenes/meshes/#" "$root/scenes/$s.toml" >"$out/$s.toml"
    ref="$out/ref-$s.exr"
    [[ -f $ref ]] || "$lucent" render "$out/$s.toml" --spp "$ref_spp" --seed 99 \
        --threads "$threads" -q -o "$ref" ${pass[@]+"${pass[@]}"}
    for n in 16 64 256; do
        t0=$(date +%s%N)
        "$lucent" render "$out/$s.toml" --spp "$n" --seed 7 --threads "$threads" -q \
            -o "$out/$s-$n.exr" ${pass[@]+"${pass[@]}"}
        t1=$(date +%s%N)
        read -r rel top < <(relmse "$ref" "$out/$s-$n.exr")
        awk -v s="$s" -v n="$n" -v rel="$rel" -v top="$top" -v ns=$((t1 - t0)) \
            'BEGIN { printf "| %s | %d | %.4f | %.2f | %.1f |\n", s, n, rel * n, top, ns / 1e6 / n }'
    done
done
