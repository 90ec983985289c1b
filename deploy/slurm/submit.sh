#!/bin/bash
# Submits a frame or a frame sequence to Slurm: one job array of every
# frame's parts (render-array.sbatch) and one merge job per frame
# (merge.sbatch) that starts once that frame's parts succeeded. Prints the
# array's job id and each merge's. deploy/slurm/README.md has examples.
#
#   [VAR=...] deploy/slurm/submit.sh [sbatch options for the parts...]
#
# Environment, besides render-array.sbatch's (LUCENT, SCENE, OUT, SPLIT,
# SPP, ARGS, MAX_REQUEUES; exported to every job):
#   PARTS    parts per frame (default 4)
#   FRAMES   A-B: the frames of a sequence (SCENE holds a printf pattern,
#            e.g. shot.%04d.toml); default: SCENE is one frame
#   BASE     the array's first index (default 0; any base works)
#   MEM      memory per part, sbatch's --mem syntax (default: deploy/memory.sh,
#            from the scene's resolution, the split and the passes)
#   MERGE_MEM  memory of each merge (default: derived the same way)
# The options given go to the array's sbatch (e.g. --time=8:00:00
# --cpus-per-task=4 --partition=render); SBATCH_* variables work too.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
: "${SCENE:?SCENE is required}" "${OUT:?OUT is required}"
PARTS=${PARTS:-4}
BASE=${BASE:-0}
SPLIT=${SPLIT:-tiles}
if [ -n "${FRAMES:-}" ]; then
  case "$SCENE" in *%*) ;; *) echo "FRAMES needs a printf pattern in SCENE (shot.%04d.toml)" >&2; exit 2 ;; esac
  FIRST=${FRAMES%-*}
  last=${FRAMES#*-}
else
  case "$SCENE" in *%*) echo "SCENE is a pattern: give FRAMES=A-B" >&2; exit 2 ;; esac
  FIRST=1
  last=1
fi
frames=$((last - FIRST + 1))
[ "$frames" -ge 1 ] || { echo "FRAMES=$FRAMES is empty" >&2; exit 2; }
mkdir -p "$OUT"
export SCENE OUT PARTS FIRST SPLIT

# Memory: deploy/memory.sh (from docs/farm.md's figures); one frame's
# resolution stands for the sequence's.
if [ -z "${MEM:-}" ] || [ -z "${MERGE_MEM:-}" ]; then
  # shellcheck disable=SC2059 # SCENE may be a pattern
  sizes=$("$here/../memory.sh" "$(printf "$SCENE" "$FIRST")" "$PARTS" "$SPLIT")
  MEM=${MEM:-${sizes% *}M}
  MERGE_MEM=${MERGE_MEM:-${sizes#* }M}
fi

tasks=$((frames * PARTS))
array=$(sbatch --parsable --export=ALL --mem="$MEM" \
  --array="$BASE-$((BASE + tasks - 1))" "$@" "$here/render-array.sbatch")
array=${array%%;*}
echo "parts: job array $array ($frames frame(s) x $PARTS parts, --mem=$MEM each)"
for ((f = 0; f < frames; f++)); do
  n=$((FIRST + f))
  deps=afterok
  for ((i = 0; i < PARTS; i++)); do deps+=":${array}_$((BASE + f * PARTS + i))"; done
  if [ -n "${FRAMES:-}" ]; then
    # shellcheck disable=SC2059
    name=$(basename "$(printf "$SCENE" "$n")" .toml)
    dir="$OUT/$name" frame="$OUT/$name.exr"
  else
    dir="$OUT" frame="${FRAME:-$OUT/frame.exr}"
  fi
  # a part that fails for good cancels the merge rather than leaving it
  # pending forever
  merge=$(PARTS_DIR=$dir FRAME=$frame sbatch --parsable --export=ALL \
    --mem="$MERGE_MEM" --dependency="$deps" --kill-on-invalid-dep=yes \
    "$here/merge.sbatch")
  echo "frame $n: merge job ${merge%%;*} -> $frame"
done
