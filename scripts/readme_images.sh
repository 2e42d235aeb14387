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
# The caustic Cornell box: three layers (box, glass sphere, mirror) photon-mapped
# by meshlabserver; each layer saved, then merged for one picture with the
# glass and the mirror painted (they carry no diffuse radiosity).
caustic() {
  local l=("$root"/test_meshes/caustic_cornell_{box,glass_sphere,mirror}.ply)
  "$gi" script photonmap --mesh "${l[0]}" --scene_extent "All visible layers" --emitter_source 1 --photons 4000000 \
    --caustic_k 256 --k_nearest 200 --light_samples 1024 --exposure 0.7 -o "$tmp/caustic.mlx"
  for k in 0 1 2; do
    "$build/mlx-run" -i "${l[0]}" -i "${l[1]}" -i "${l[2]}" -o "$tmp/caustic$k.ply" -l "$k" -m vc vq -s "$tmp/caustic.mlx" \
      >"$tmp/log.txt" 2>&1 || { cat "$tmp/log.txt"; exit 1; }
  done
  "$py" "$root/scripts/merge_ply.py" "$tmp/caustic_all.ply" "$tmp/caustic0.ply" "$tmp/caustic1.ply=150,170,190" \
    "$tmp/caustic2.ply=205,210,220"
  "$py" "$root/scripts/turn_ply.py" "$tmp/caustic_all.ply" "$tmp/caustic_view.ply" 16
  GUI_NO_CHECK=1 GUI_SETTLE=5 bash "$root/tests/integration/gui_screenshot.sh" "$build/stage/bin" "$tmp/caustic_view.ply" "$tmp/caustic.png"
  convert "$tmp/caustic.png" -crop 860x860+0+60 +repage -resize 480x480 "$img/cornell_caustic.png"
  echo "wrote $img/cornell_caustic.png"
}
# The picture at the top: the caustic Cornell box with its glossy block, computed by our
# renderer through the staged meshlabserver: photon mapping over the four layers (the first
# pass, left on the meshes as the attribute Radiosity), then GI: Ray Traced View in two-pass
# mode in the same script (direct light ray traced, caustics from its caustic map, glossy
# reflection by sampling the block's GGX lobe, mirror and glass followed), written as PNG.
raytraced() {
  local l=("$root"/test_meshes/caustic_cornell_{box,glass_sphere,mirror,glossy_block}.ply)
  local glossy=(--glossy_color 255,200,120 --glossy_roughness 0.15)
  "$gi" script photonmap --mesh "${l[0]}" --scene_extent "All visible layers" --emitter_source 1 --photons 1000000 \
    "${glossy[@]}" -o "$tmp/pm.mlx"
  "$gi" script render --mesh "${l[0]}" --scene_extent "All visible layers" --emitter_source 1 --mode Two-pass \
    --width 480 --height 480 --samples_per_pixel 16 --caustic_photons 1000000 "${glossy[@]}" \
    --image_path "$img/cornell_raytraced.png" -o "$tmp/view.mlx"
  # One script: the photon-mapping step, then the view's (its header dropped).
  { sed '$d' "$tmp/pm.mlx"; tail -n +3 "$tmp/view.mlx"; } >"$tmp/pm_view.mlx"
  "$build/mlx-run" -i "${l[0]}" -i "${l[1]}" -i "${l[2]}" -i "${l[3]}" -o "$tmp/raytraced.ply" -s "$tmp/pm_view.mlx" \
    >"$tmp/log.txt" 2>&1 || { cat "$tmp/log.txt"; exit 1; }
  grep -q "mode Two-pass" "$tmp/log.txt" || { cat "$tmp/log.txt"; exit 1; }
  grep -E "seconds" "$tmp/log.txt" | cut -c1-600  # the filters' log lines: what was computed, in how long
  rm -f "$img/cornell_raytraced.pfm"  # the linear image beside the PNG: not shipped
  echo "wrote $img/cornell_raytraced.png"
}
raytraced
[[ "${ONLY:-}" == raytraced ]] && exit 0
caustic
[[ "${ONLY:-}" == caustic ]] && exit 0
# Cornell box: radiosity after 0, 1, 3 bounces and converged; photon mapping.
fine="$root/test_meshes/cornell_box_fine.ply"
for b in 0 1 3 -1; do
  "$gi" script radiosity --mesh "$fine" --emitter_source 1 --rays_per_patch 1024 --bounces "$b" --exposure 0.7 -o "$tmp/rad$b.mlx"
  run_mlx "$fine" "$tmp/cornell_bounces$b.ply" "$tmp/rad$b.mlx"
done
cp "$tmp/cornell_bounces-1.ply" "$tmp/cornell_radiosity.ply"
"$gi" script ao --rays_per_vertex 1024 -o "$tmp/ao.mlx"
run_mlx "$root/test_meshes/bunny.ply" "$tmp/bunny_ao.ply" "$tmp/ao.mlx"
# The Cornell box opens towards -z; MeshLab's default camera looks from +z:
# turn the copies 180 degrees about y for the picture.
for f in cornell_radiosity cornell_bounces0 cornell_bounces1 cornell_bounces3; do
  "$py" "$root/scripts/turn_ply.py" "$tmp/$f.ply" "$tmp/${f}_view.ply"
done
cp "$tmp/bunny_ao.ply" "$tmp/bunny_ao_view.ply"
for f in cornell_radiosity bunny_ao cornell_bounces0 cornell_bounces1 cornell_bounces3; do
  GUI_NO_CHECK=1 GUI_SETTLE=5 bash "$root/tests/integration/gui_screenshot.sh" "$build/stage/bin" "$tmp/${f}_view.ply" "$tmp/$f.png"
  convert "$tmp/$f.png" -crop 860x860+0+60 +repage -resize 480x480 "$img/$f.png"
done
convert "$img/cornell_bounces0.png" "$img/cornell_bounces1.png" "$img/cornell_bounces3.png" "$img/cornell_radiosity.png" \
  -resize 300x300 +append "$img/cornell_bounce_sequence.png"
rm -f "$img"/cornell_bounces?.png
echo "wrote $img/{cornell_radiosity,bunny_ao,cornell_bounce_sequence}.png"
