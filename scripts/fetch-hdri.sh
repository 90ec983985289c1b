#!/usr/bin/env bash
# Writes the CC0 environment maps of the npm package `@pmndrs/assets` 1.7.0
# (Poly Haven HDRIs, 512×256 half-float OpenEXR, stored as base64 data URLs
# in `hdri/<name>.exr.js`; license CC0-1.0) to scenes/hdri/<name>.exr.
# `npm pack` only downloads the tarball: nothing is installed and no package
# scripts run. The maps are not committed (scenes/hdri/.gitignore).
# Usage: scripts/fetch-hdri.sh [NAME...]   (default: all of them)
set -euo pipefail

version=1.7.0
repo_root=$(cd "$(dirname "$0")/.." && pwd)
out_dir="$repo_root/scenes/hdri"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cd "$work"
npm pack --ignore-scripts --silent "@pmndrs/assets@$version" >/dev/null
tar xzf "pmndrs-assets-$version.tgz"
node -e 'const p = require("./package/package.json"); console.error(`package ${p.name}@${p.version}, license: ${p.license}`);'

mkdir -p "$out_dir"
node - "$work/package/hdri" "$out_dir" "$@" <<'JS'
const fs = require("fs");
const path = require("path");
const [dir, out, ...wanted] = process.argv.slice(2);
const names = fs.readdirSync(dir)
  .filter((f) => f.endsWith(".exr.js"))
  .map((f) => f.slice(0, -".exr.js".length))
  .filter((n) => wanted.length === 0 || wanted.includes(n));
for (const w of wanted) {
  if (!names.includes(w)) throw new Error(`no map named ${w}`);
}
const prefix = "data:application/exr;base64,";
for (const name of names) {
  const text = fs.readFileSync(path.join(dir, `${name}.exr.js`), "utf8");
  const m = text.match(/'([^']*)'/);
  if (!m || !m[1].startsWith(prefix)) throw new Error(`${name}: no EXR data URL`);
  const bytes = Buffer.from(m[1].slice(prefix.length), "base64");
  // The OpenEXR magic number 20000630, little-endian.
  if (bytes.readUInt32LE(0) !== 20000630) throw new Error(`${name}: not an OpenEXR file`);
  const file = path.join(out, `${name}.exr`);
  fs.writeFileSync(`${file}.tmp`, bytes);
  fs.renameSync(`${file}.tmp`, file);
  console.error(`${file}: ${bytes.length} bytes`);
}
JS
