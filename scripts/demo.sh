#!/usr/bin/env bash
# One command from a fresh Debian 12 machine: installs what is needed, builds,
# and runs radiosity on the shipped Cornell box through the real meshlabserver
# (staged, headless). Writes build/demo/cornell_radiosity.ply (vertex colour + quality).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${GI_BUILD_DIR:-$root/build}"
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
out="$build/demo"
mkdir -p "$out"
mesh="$root/test_meshes/cornell_box.ply"
"$build/tools/gi" script radiosity --mesh "$mesh" --emitter_source "Face quality above threshold" \
  --light_samples 256 -o "$out/radiosity.mlx"
"$build/mlx-run" -i "$mesh" -o "$out/cornell_radiosity.ply" -m vc vq -s "$out/radiosity.mlx" 2>&1 \
  | grep -E "^GI: |emitter faces|saved as" || true
[[ -s "$out/cornell_radiosity.ply" ]] || { echo "[demo] FAILED: meshlabserver wrote no output" >&2; exit 1; }
echo "[demo] wrote $out/cornell_radiosity.ply (per-vertex colour and quality); open it with: meshlab $out/cornell_radiosity.ply"
