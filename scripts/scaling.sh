#!/usr/bin/env bash
# How render time grows with pixels, samples and threads, on the marble
# bunny (scenes/marble-bunny.toml): prints markdown tables of wall time,
# time per pixel-sample and Mrays/s, as quoted in docs/performance.md.
#
#   bash scripts/scaling.sh [path/to/lucent] [--accel bvh|embree]
#
# Each configuration is rendered twice and the faster run kept (the other
# run absorbs page-cache and frequency warm-up). Needs a release build.
set -euo pipefail
cd "$(dirname "$0")/.."
LUCENT=${1:-target/release/lucent}
shift || true
EXTRA=("$@")
[ -x "$LUCENT" ] || { echo "no lucent binary at $LUCENT (cargo build --release)" >&2; exit 2; }

OUT=$(mktemp -d)
# Scenes are written next to the original (its mesh path is relative),
# named by this shell's pid so that the cleanup removes only ours.
trap 'rm -rf "$OUT"; rm -f scenes/.scaling-$$-*.toml' EXIT

scene_at() { # width height -> path of a copy of the bunny scene at that size
  local f="scenes/.scaling-$$-$1x$2.toml"
  sed "s/^resolution = .*/resolution = [$1, $2]/" scenes/marble-bunny.toml >"$f"
  echo "$f"
}

# Prints "seconds mrays" of the faster of two renders.
run() { # scene spp threads
  local best="" line s
  for _ in 1 2; do
    line=$("$LUCENT" render "$1" -o "$OUT/x.exr" --spp "$2" --threads "$3" "${EXTRA[@]}" 2>&1 | tail -1)
    s=$(sed -E 's/.*: ([0-9.]+) s wall.*/\1/' <<<"$line")
    m=$(sed -E 's/.* ([0-9.]+) Mrays\/s.*/\1/' <<<"$line")
    if [ -z "$best" ] || awk "BEGIN{exit !($s < ${best% *})}"; then best="$s $m"; fi
  done
  echo "$best"
}

row() { # label scene w h spp threads
  read -r s m < <(run "$2" "$5" "$6")
  awk -v l="$1" -v s="$s" -v m="$m" -v n="$(($3 * $4 * $5))" \
    'BEGIN { printf "| %s | %.3f | %.1f | %.2f |\n", l, s, s / n * 1e9, m }'
}

echo "Pixels (spp 4, 1 thread):"
echo "| resolution | s | ns per pixel-sample | Mrays/s |"
echo "|---|---:|---:|---:|"
for wh in "160 120" "320 240" "640 480" "1280 960"; do
  set -- $wh
  row "$1×$2" "$(scene_at "$1" "$2")" "$1" "$2" 4 1
done

echo
echo "Samples (320×240, 1 thread):"
echo "| spp | s | ns per pixel-sample | Mrays/s |"
echo "|---|---:|---:|---:|"
S=$(scene_at 320 240)
for spp in 1 4 16 64; do
  row "$spp" "$S" 320 240 "$spp" 1
done

echo
echo "Threads (640×480, spp 8):"
echo "| threads | s | ns per pixel-sample | Mrays/s |"
echo "|---|---:|---:|---:|"
S=$(scene_at 640 480)
for t in 1 2; do
  row "$t" "$S" 640 480 8 "$t"
done
