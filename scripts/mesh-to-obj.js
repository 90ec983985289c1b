// Shared by scripts/fetch-meshes.sh: checks a triangle mesh given as
// `positions` ([x, y, z] arrays) and `cells` ([a, b, c] 0-based indices),
// prints its topology report and writes it as an OBJ with the vertices
// unchanged (the scene files place and scale the mesh).
//
// The report: boundary edges, non-manifold edges (more than two faces),
// inconsistently wound edges (two faces using an edge in the same
// direction), signed volume and bounds, so a changed upstream mesh is
// noticed. Loops rather than spread arguments: the dragon has 437k vertices.
const fs = require("fs");

// `header(counts)` gives the OBJ's leading comment lines (without "# ")
// from { vertices, triangles, boundary }.
function writeObj(positions, cells, header, out) {
  const n = positions.length;
  for (const p of positions) {
    if (p.length !== 3 || !p.every(Number.isFinite)) throw new Error(`bad vertex ${p}`);
  }
  // In a closed, consistently wound mesh every undirected edge has exactly
  // two faces, using it in opposite directions. Key: a·n + b (exact below 2^53).
  // Per edge: faces using it as (lo → hi) + 65536 × faces using it as (hi → lo).
  const edges = new Map();
  for (const c of cells) {
    if (c.length !== 3) throw new Error(`non-triangle cell of length ${c.length}`);
    for (const i of c) {
      if (!Number.isInteger(i) || i < 0 || i >= n) throw new Error(`bad index ${i}`);
    }
    for (let k = 0; k < 3; k++) {
      const a = c[k], b = c[(k + 1) % 3];
      const key = a < b ? a * n + b : b * n + a;
      edges.set(key, (edges.get(key) || 0) + (a < b ? 1 : 65536));
    }
  }
  let boundary = 0, nonManifold = 0, misWound = 0;
  for (const e of edges.values()) {
    const f = e % 65536, r = Math.floor(e / 65536), faces = f + r;
    if (faces === 1) boundary++;
    else if (faces > 2) nonManifold++;
    else if (f !== 1) misWound++;
  }
  // Signed volume by the divergence theorem: positive when faces wind
  // counter-clockwise seen from outside (meaningful only if nearly closed).
  let vol = 0;
  for (const [a, b, c] of cells) {
    const [p, q, r] = [positions[a], positions[b], positions[c]];
    vol += (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) + p[2] * (q[0] * r[1] - q[1] * r[0])) / 6;
  }
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const p of positions) {
    for (let i = 0; i < 3; i++) {
      lo[i] = Math.min(lo[i], p[i]);
      hi[i] = Math.max(hi[i], p[i]);
    }
  }
  console.error(`vertices ${n}, triangles ${cells.length}, edges ${edges.size}`);
  console.error(`boundary edges ${boundary}, non-manifold edges ${nonManifold}, inconsistently wound edges ${misWound}`);
  console.error(`signed volume ${vol.toPrecision(4)} (${vol > 0 ? "outward" : "inward"}), bounds [${lo}] .. [${hi}]`);

  const lines = header({ vertices: n, triangles: cells.length, boundary }).map(h => `# ${h}`);
  for (const p of positions) lines.push(`v ${p[0]} ${p[1]} ${p[2]}`);
  for (const c of cells) lines.push(`f ${c[0] + 1} ${c[1] + 1} ${c[2] + 1}`);
  // Written beside the target and renamed: a failed run leaves no half file.
  fs.writeFileSync(out + ".tmp", lines.join("\n") + "\n");
  fs.renameSync(out + ".tmp", out);
  console.error(`wrote ${out}`);
}

// The ASCII PLY of the Stanford scans (`element vertex N` with x y z first,
// `element face M` as `3 a b c`), gzipped.
function readAsciiPlyGz(path) {
  const text = require("zlib").gunzipSync(fs.readFileSync(path)).toString("latin1");
  const lines = text.split("\n");
  if (lines[0].trim() !== "ply" || !/^format ascii /.test(lines[1])) throw new Error(`${path}: not an ASCII PLY`);
  let nv = -1, nf = -1, at = 0;
  while (lines[at].trim() !== "end_header") {
    const m = lines[at].match(/^element (vertex|face) (\d+)/);
    if (m && m[1] === "vertex") nv = +m[2];
    if (m && m[1] === "face") nf = +m[2];
    at++;
  }
  if (nv < 0 || nf < 0) throw new Error(`${path}: no vertex or face element`);
  at++;
  const positions = [], cells = [];
  for (let i = 0; i < nv; i++) positions.push(lines[at++].trim().split(/\s+/).slice(0, 3).map(Number));
  for (let i = 0; i < nf; i++) {
    const w = lines[at++].trim().split(/\s+/).map(Number);
    if (w[0] !== 3 || w.length < 4) throw new Error(`${path}: face ${i} is not a triangle`);
    cells.push(w.slice(1, 4));
  }
  return { positions, cells };
}

module.exports = { writeObj, readAsciiPlyGz };
