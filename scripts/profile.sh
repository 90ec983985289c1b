#!/usr/bin/env bash
# Where `lucent render` spends its instructions on the marble bunny: ray
# queries, BSSRDF sampling outside its probe query, and the rest of the
# integrator (shading, light sampling, RNG, path bookkeeping), per backend,
# as quoted in docs/performance.md. Callgrind counts instructions
# (repeatable; not time: cache misses and SIMD width weigh differently).
#
#   bash scripts/profile.sh [path/to/lucent] [spp]
#
# Renders a 160×120 copy of scenes/marble-bunny.toml (8 spp, 1 thread)
# under valgrind --tool=callgrind, ~15 s per backend. Needs valgrind,
# python3 and a release build (its debug info names the functions).
set -euo pipefail
cd "$(dirname "$0")/.."
LUCENT=$(realpath "${1:-target/release/lucent}")
SPP=${2:-8}
[ -x "$LUCENT" ] || { echo "no lucent binary at $LUCENT (cargo build --release)" >&2; exit 2; }
command -v valgrind >/dev/null || { echo "needs valgrind (apt-get install valgrind)" >&2; exit 2; }

OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
sed -e 's/^resolution = .*/resolution = [160, 120]/' \
    -e "s|file = \"meshes/|file = \"$PWD/scenes/meshes/|" \
    scenes/marble-bunny.toml >"$OUT/scene.toml"

backends=$("$LUCENT" info | sed -n 's/^backends: //p' | tr ',' '\n' | awk '{print $1}')
printf '| | %s |\n|---|%s\n' "$(echo $backends | sed 's/ / | /g')" \
  "$(for _ in $backends; do printf -- '---:|'; done)"
declare -A row
for b in $backends; do
  valgrind --tool=callgrind --dump-instr=no --compress-strings=no --compress-pos=no \
    --callgrind-out-file="$OUT/$b.cg" \
    "$LUCENT" render "$OUT/scene.toml" -o "$OUT/$b.exr" --spp "$SPP" --threads 1 --accel "$b" -q \
    >/dev/null 2>&1
  case $b in embree3) ty=EmbreeAccel ;; embree4) ty=Embree4Accel ;; *) ty=Bvh ;; esac
  pats=("lucent::render::render_tile"
        "$ty as lucent::accel::Accel>::intersect"
        "$ty as lucent::accel::Accel>::occluded"
        "$ty as lucent::accel::Accel>::hits_on_segment"
        "lucent::integrator::probe::sample_entry")
  mapfile -t v < <(python3 scripts/cg_inclusive.py "$OUT/$b.cg" "${pats[@]}" | cut -f1)
  # A function the compiler inlined has no cost of its own in the profile;
  # its share would silently land in "the rest".
  for k in "${!pats[@]}"; do
    [ "${v[$k]}" -gt 0 ] || { echo "profile.sh: no function matching '${pats[$k]}' in the $b profile (inlined in this build?)" >&2; exit 1; }
  done
  total=${v[0]} q=$((v[1] + v[2] + v[3])) bssrdf=$((v[4] - v[3]))
  pct() { awk -v a="$1" -v t="$total" 'BEGIN { printf "%.1f %%", 100 * a / t }'; }
  row[total]+=" | ${total}"
  row[q]+=" | **$(pct $q)**"
  row[i]+=" | $(pct ${v[1]})"
  row[o]+=" | $(pct ${v[2]})"
  row[p]+=" | $(pct ${v[3]})"
  row[s]+=" | $(pct $bssrdf)"
  row[r]+=" | $(pct $((total - q - bssrdf)))"
done
echo "| instructions in the tile loop${row[total]} |"
echo "| ray queries, total${row[q]} |"
echo "| — intersect${row[i]} |"
echo "| — occluded${row[o]} |"
echo "| — hits_on_segment (probe)${row[p]} |"
echo "| BSSRDF sampling outside its probe query${row[s]} |"
echo "| the rest of the integrator${row[r]} |"
