#!/usr/bin/env bash
# What a feature that is off costs: two or more lucent binaries on one
# scene, (1) instructions in the tile loop under callgrind (repeatable) and
# (2) wall time, the binaries alternated ROUNDS times in one run (the load
# of a shared machine then falls on all of them alike). docs/performance.md,
# "Zero cost for what is off", quotes its output.
#
#   bash scripts/zero-cost.sh SCENE WIDTH HEIGHT SPP ROUNDS BIN...
#
# Callgrind renders the scene at WIDTH×HEIGHT, SPP samples, 1 thread, on
# the BVH (the backend every build has); the timed renders use the same
# size, both threads and the default backend. Needs valgrind, python3 and
# release builds (their debug info names the tile loop).
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 6 ] || { sed -n 2,14p "$0" >&2; exit 2; }
SCENE=$1 W=$2 H=$3 SPP=$4 ROUNDS=$5
shift 5
BINS=("$@")
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
# KEEP=DIR keeps the callgrind profiles there (0.cg, 1.cg, ... in BIN order).
KEEP=${KEEP:-}
dir=$(cd "$(dirname "$SCENE")" && pwd)
sed -e "s/^resolution = .*/resolution = [$W, $H]/" \
    -e "s|file = \"meshes/|file = \"$dir/meshes/|" \
    "$SCENE" >"$OUT/scene.toml"

echo "scene $SCENE at ${W}x${H}, $SPP spp"
for i in "${!BINS[@]}"; do
  b=${BINS[$i]}
  valgrind --tool=callgrind --dump-instr=no --compress-strings=no --compress-pos=no \
    --callgrind-out-file="$OUT/$i.cg" \
    "$b" render "$OUT/scene.toml" -o "$OUT/cg$i.exr" --spp "$SPP" --threads 1 --accel bvh -q \
    >/dev/null 2>"$OUT/err" || { cat "$OUT/err" >&2; exit 1; }
  [ -z "$KEEP" ] || cp "$OUT/$i.cg" "$KEEP/"
  n=$(python3 scripts/cg_inclusive.py "$OUT/$i.cg" "lucent::render::render_tile" | cut -f1)
  echo "callgrind tile loop: $n instructions  $b"
done

declare -A total
for r in $(seq "$ROUNDS"); do
  line="round $r:"
  for i in "${!BINS[@]}"; do
    t0=$(date +%s.%N)
    "${BINS[$i]}" render "$OUT/scene.toml" -o "$OUT/t$i.exr" --spp "$SPP" -q >/dev/null 2>&1
    t=$(echo "$(date +%s.%N) - $t0" | bc)
    total[$i]=$(echo "${total[$i]:-0} + $t" | bc)
    line+=" $(printf %.3f "$t")"
  done
  echo "$line"
done
for i in "${!BINS[@]}"; do
  echo "wall time, sum of $ROUNDS: $(printf %.2f "${total[$i]}") s  ${BINS[$i]}"
done
