#!/bin/sh
# Converts the Stanford bunny of the npm package "bunny" (Stanford Computer
# Graphics Laboratory data, as JS arrays) to a binary little-endian PLY.
# Usage: test_meshes/bunny_from_npm.sh [OUT.ply]   (default: next to this script)
set -eu
VERSION=1.0.1
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-$here/bunny.ply}
case $out in /*) ;; *) out=$(pwd)/$out ;; esac
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
npm pack --silent "bunny@$VERSION" >/dev/null
tar xzf "bunny-$VERSION.tgz"
node - "$tmp/package/index.js" "$out" <<'JS'
const [src, out] = process.argv.slice(2);
const { positions, cells } = require(src);
const header = "ply\nformat binary_little_endian 1.0\n" +
  "comment Stanford bunny (Stanford Computer Graphics Laboratory), npm package bunny@1.0.1\n" +
  `element vertex ${positions.length}\nproperty float x\nproperty float y\nproperty float z\n` +
  `element face ${cells.length}\nproperty list uchar int vertex_indices\nend_header\n`;
const body = Buffer.alloc(positions.length * 12 + cells.length * 13);
let o = 0;
for (const p of positions) for (const c of p) { body.writeFloatLE(c, o); o += 4; }
for (const t of cells) {
  if (t.length !== 3) throw new Error("non-triangle cell");
  body.writeUInt8(3, o); o += 1;
  for (const i of t) { body.writeInt32LE(i, o); o += 4; }
}
require("fs").writeFileSync(out, Buffer.concat([Buffer.from(header, "ascii"), body]));
console.log(`${out}: ${positions.length} vertices, ${cells.length} faces`);
JS
