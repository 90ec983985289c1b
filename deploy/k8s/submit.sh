#!/bin/bash
# Fills in render-parts.yaml and merge-frame.yaml and applies them: an
# Indexed Job of PARTS parts and a merge Job that starts itself once they
# are all written. Every value has one home, here.
#
#   NAME=bunny IMAGE=registry.example/lucent:0.1.0 SCENE=/data/scenes/marble-bunny.toml \
#     deploy/k8s/submit.sh [--print]
#
# Environment:
#   NAME     the frame's name: the Jobs' names and OUT/NAME.exr (lowercase
#            letters, digits and '-')
#   IMAGE    an image built from deploy/k8s/Containerfile
#   SCENE    the scene's path inside the pods (on the shared volume)
#   PARTS    parts (default 8); PARALLELISM pods at once (default PARTS)
#   THREADS  CPUs per part: the pod's CPU request and limit, and --threads
#            (default 2)
#   MEM      memory per part (default: deploy/memory.sh on SCENE_FILE, a
#            local copy of the scene, else SCENE if readable here), in Mi
#   MERGE_MEM  memory of the merge (default: the same way)
#   ARGS     more render options, split at spaces, replacing the defaults
#            they name (--threads, --checkpoint, --quiet); no quotes
#   OUT      the frames' directory in the pods (default /data/frames)
#   CLAIM    the ReadWriteMany PersistentVolumeClaim mounted at /data
#            (default lucent-data)
#   BACKOFF  failed pods the part Job tolerates (default 2 x PARTS;
#            evictions and preemptions are not counted)
#   MERGE_DEADLINE  seconds the merge Job waits and runs at most (default
#            604800, a week)
# --print writes the manifests to stdout instead of `kubectl apply`.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
: "${NAME:?NAME is required}" "${IMAGE:?IMAGE is required}" "${SCENE:?SCENE is required}"
PARTS=${PARTS:-8}
PARALLELISM=${PARALLELISM:-$PARTS}
THREADS=${THREADS:-2}
OUT=${OUT:-/data/frames}
CLAIM=${CLAIM:-lucent-data}
BACKOFF=${BACKOFF:-$((2 * PARTS))}
MERGE_DEADLINE=${MERGE_DEADLINE:-604800}
ARGS=${ARGS:-}
if [ -z "${MEM:-}" ] || [ -z "${MERGE_MEM:-}" ]; then
  local_scene=${SCENE_FILE:-$SCENE}
  [ -r "$local_scene" ] || { echo "set MEM and MERGE_MEM, or SCENE_FILE to a copy of the scene to size them from" >&2; exit 2; }
  sizes=$("$here/../memory.sh" "$local_scene" "$PARTS" tiles)
  MEM=${MEM:-${sizes% *}Mi}
  MERGE_MEM=${MERGE_MEM:-${sizes#* }Mi}
fi
[[ $NAME =~ ^[a-z0-9]([-a-z0-9]{0,40}[a-z0-9])?$ ]] || { echo "NAME must be lowercase letters, digits and '-' (at most 42): $NAME" >&2; exit 2; }
for v in PARTS PARALLELISM THREADS BACKOFF MERGE_DEADLINE; do
  [[ ${!v} =~ ^[1-9][0-9]*$ ]] || { echo "$v must be a positive integer: ${!v}" >&2; exit 2; }
done
vars=(NAME IMAGE SCENE PARTS PARALLELISM THREADS MEM MERGE_MEM ARGS OUT CLAIM BACKOFF MERGE_DEADLINE)
for v in "${vars[@]}"; do
  [[ ${!v} != *[\"\\$'\n']* ]] || { echo "$v must not hold quotes, backslashes or newlines" >&2; exit 2; }
done
fill() {
  local t v
  t=$(<"$1")
  for v in "${vars[@]}"; do t=${t//"\${$v}"/${!v}}; done
  printf '%s\n' "$t"
}
manifests() {
  fill "$here/render-parts.yaml"
  echo ---
  fill "$here/merge-frame.yaml"
}
if [ "${1:-}" = --print ]; then
  manifests
else
  manifests | kubectl apply -f -
fi
