#!/usr/bin/env bash
# Regenerates the README's pictures: results of our filters computed by the
# staged meshlabserver, shown in the real MeshLab GUI under Xvfb.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${GI_BUILD_DIR:-$root/build}"
img="$root/docs/img"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$img"
gi="$build/tools/gi"
py=/usr/bin/python3
cornell="$root/test_meshes/cornell_box.ply"
run_mlx() {  # mesh out script
  "$build/mlx-run" -i "$1" -o "$2" -m vc vq -s "$3" >"$tmp/log.txt" 2>&1 || { cat "$tmp/log.txt"; exit 1; }
}
# Cornell box: direct light (radiosity, zero bounces) and photon mapping (all bounces).
"$gi" script radiosity --mesh "$cornell" --emitter_source 1 --light_samples 256 -o "$tmp/rad.mlx"
run_mlx "$cornell" "$tmp/cornell_radiosity.ply" "$tmp/rad.mlx"
"$gi" script photonmap --mesh "$root/test_meshes/cornell_box_fine.ply" --emitter_source 1 --photons 2000000 --k_nearest 200 -o "$tmp/pm.mlx"
run_mlx "$root/test_meshes/cornell_box_fine.ply" "$tmp/cornell_photonmap.ply" "$tmp/pm.mlx"
"$gi" script ao --rays_per_vertex 1024 -o "$tmp/ao.mlx"
run_mlx "$root/test_meshes/bunny.ply" "$tmp/bunny_ao.ply" "$tmp/ao.mlx"
# The Cornell box opens towards -z; MeshLab's default camera looks from +z:
# turn the copies 180 degrees about y for the picture.
for f in cornell_radiosity cornell_photonmap; do
  "$py" "$root/scripts/turn_ply.py" "$tmp/$f.ply" "$tmp/${f}_view.ply"
done
cp "$tmp/bunny_ao.ply" "$tmp/bunny_ao_view.ply"
for f in cornell_radiosity cornell_photonmap bunny_ao; do
  GUI_NO_CHECK=1 GUI_SETTLE=5 bash "$root/tests/integration/gui_screenshot.sh" "$build/stage/bin" "$tmp/${f}_view.ply" "$tmp/$f.png"
  convert "$tmp/$f.png" -crop 860x860+0+60 +repage -resize 480x480 "$img/$f.png"
done
echo "wrote $img/{cornell_radiosity,cornell_photonmap,bunny_ao}.png"
