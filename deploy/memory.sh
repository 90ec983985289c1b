#!/bin/bash
# Prints the memory, in MB, that one part and one merge of a frame need:
#
#   [ARGS="render options"] deploy/memory.sh SCENE PARTS [tiles|samples]
#   -> "PART_MB MERGE_MB"
#
# The per-pixel figures and where they come from: docs/farm.md, "Memory on
# a scheduler". A part: 144 B a pixel of its region for the beauty alone,
# 2700 B with passes; a merge: 200 B and 1300 B a pixel of the frame. Plus
# 256 MB for the scene, its BVH and the process, and a quarter more.
# Passes count as on when ARGS has --aov (but not --aov none) or the scene
# has a non-empty `aovs` list; a band (tiles) holds ceil(H / PARTS) rows.
set -euo pipefail
scene=$1 parts=$2 split=${3:-tiles}
read -r w h < <(sed -n 's/^[[:space:]]*resolution[[:space:]]*=[[:space:]]*\[[[:space:]]*\([0-9]*\)[[:space:]]*,[[:space:]]*\([0-9]*\).*/\1 \2/p' "$scene" | head -1) || true
if [ -z "${w:-}" ] || [ -z "${h:-}" ]; then
  echo "$scene: no 'resolution = [W, H]' line to size memory from" >&2
  exit 2
fi
passes=0
case " ${ARGS:-} " in
  *" --aov none "* | *" --aov=none "*) ;;
  *" --aov"*) passes=1 ;;
  *) if grep -Eq '^[[:space:]]*aovs[[:space:]]*=[[:space:]]*\[[[:space:]]*"' "$scene"; then passes=1; fi ;;
esac
pixels=$((w * h))
[ "$split" = tiles ] && pixels=$((w * ((h + parts - 1) / parts)))
if [ "$passes" = 1 ]; then part_b=2700 merge_b=1300; else part_b=144 merge_b=200; fi
mb() { echo $(((256 + $1 / 1000000) * 5 / 4)); }
echo "$(mb $((pixels * part_b))) $(mb $((w * h * merge_b)))"
