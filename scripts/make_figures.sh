#!/usr/bin/env bash
# Makes every figure of docs/course.md and of the README into docs/img/,
# with the command-line tool (the same engine calls as the MeshLab filters)
# from fixed cameras, or through the staged meshlabserver and a screenshot of
# the real MeshLab GUI under Xvfb (the README's pictures, the error map and
# the photon cloud: vertex colours and points as MeshLab shows them).
# Groups (ONLY=group makes one; without ONLY, all of them):
#   hemicube     the hemicube of a Cornell box floor patch: cells by patch, by
#                delta form factor, Nusselt's disk (GI: Hemicube of Selected Face)
#   artefacts    shadow_leak.ply and staircase.ply solved with patch averages,
#                final gather and refinement, seen through the two-pass view's
#                "First pass alone" (the per-vertex B the mesh carries)
#   progressive  progressive refinement of the Cornell box after 1, 10, 100 shots
#   raytraced    the README's top picture: photon mapping + two-pass view of the
#                caustic box through meshlabserver (480 x 480; minutes)
#   caustic      the README's caustic box, photon-mapped by meshlabserver (GUI)
#   bounces      the README's radiosity after 0, 1, 3 bounces and converged (GUI)
#   ao           the README's bunny with ambient occlusion (GUI)
#   reference    the path-traced reference per vertex at 16 and 256 paths
#   raytracing   Whitted beside distributed ray tracing on the caustic box
#   twopass      first pass alone, ray-traced direct + stored indirect, final
#                gather, path traced (Cornell box, radiosity as the first pass)
#   photons      the photon-mapped caustic box as the mesh carries it, and its
#                photons as a point cloud (GUI)
#   lightpaths   the four light_path_split attributes of the caustic box
#   errormap     z-scores of radiosity against the path-traced reference (GUI)
# Needs build/tools/gi, build/mlx-run, the staged MeshLab (build/stage/bin),
# Xvfb and ImageMagick's convert.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${GI_BUILD_DIR:-$root/build}"
gi="$build/tools/gi"
img="$root/docs/img"
m="$root/test_meshes"
py=/usr/bin/python3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$img"

# Side by side with a 4-pixel white gap; PNG, small.
row() {  # out in...
  local out=$1
  shift
  convert "$@" -bordercolor white -border 2 +append -strip "$out"
  echo "wrote $out ($(stat -c %s "$out") bytes)"
}

# The per-vertex B a mesh carries (its attribute Radiosity), as the two-pass
# view's "First pass alone" shows it: size x size pixels, 4 samples each.
first_pass() {  # ply png size exposure [more gi render options...]
  local ply=$1 png=$2 size=$3 exposure=$4
  shift 4
  "$gi" render "$ply" --emitter_source 1 --mode Two-pass --two_pass_diffuse "First pass alone" "$@" \
    --width "$size" --height "$size" --samples_per_pixel 4 --exposure "$exposure" --image_path "$png" -q
}

# Face 49 of cornell_box.ply: a floor patch at (435, 0, 136), in front of the
# tall block; its hemicube sees the ceiling, the walls, both blocks and (black)
# the open front. 64 cells across the top face show the cells themselves.
hemicube() {
  "$gi" hemicube "$m/cornell_box.ply" --face_index 49 --hemicube_resolution 64 --nusselt_resolution 256 \
    --image_path "$tmp/hc.png" -q
  convert "$tmp/hc.png" -filter point -resize 256x256 "$tmp/hc_big.png"
  convert "$tmp/hc_dff.png" -filter point -resize 256x256 "$tmp/hc_dff_big.png"
  row "$img/hemicube_cornell.png" "$tmp/hc_big.png" "$tmp/hc_dff_big.png" "$tmp/hc_nusselt.png"
}

# One scene three ways: patch average, final gather, refined (patch averages
# on the refined mesh), each rendered from the same camera with the
# same exposure (the lit side's light at the same grey in all three).
artefact() {  # name refinement-depth exposure camera-args...
  local name=$1 depth=$2 exposure=$3
  shift 3
  local mesh="$m/$name.ply" k=0
  local -a pics=()
  for fix in "--vertex_output 'Patch average'" "--vertex_output 'Final gather'" \
             "--vertex_output 'Patch average' --refine true --refine_max_depth $depth"; do
    eval "\"$gi\" radiosity \"$mesh\" --emitter_source 1 $fix -o \"$tmp/$name$k.ply\" -q"
    first_pass "$tmp/$name$k.ply" "$tmp/$name$k.png" 240 "$exposure" --camera "Look at" "$@"
    pics+=("$tmp/$name$k.png")
    k=$((k + 1))
  done
  row "$img/${name}_fixes.png" "${pics[@]}"
}

artefacts() {
  # Inside the dark half, looking at the partition's foot: the light there leaked.
  artefact shadow_leak 2 10 --eye 1.95,0.15,0.85 --target 1.1,0.7,0.1 --up 0,0,1 --fov 75
  # From above the light side, past the occluder's edge: the diagonal shadow edge on the coarse floor.
  artefact staircase 4 300 --eye -0.7,-0.1,1.9 --target 0.45,0.05,0 --up 0,1,0 --fov 55
}

# Progressive refinement: patch average after 1, 10 and 100 shots, the
# ambient term on (early pictures as bright as the converged one).
progressive() {
  "$gi" radiosity "$m/cornell_box.ply" --emitter_source 1 --solver "Progressive refinement" --ambient_term true \
    --snapshot_steps "1, 10, 100" --vertex_output "Patch average" -o "$tmp/prog.ply" -q
  local -a pics=()
  for step in 1 10 100; do
    # The snapshot as the first pass: rename its attribute to Radiosity.
    "$py" "$root/scripts/rename_ply_attribute.py" "$tmp/prog.ply" "$tmp/prog$step.ply" "Radiosity_step_$step" Radiosity
    first_pass "$tmp/prog$step.ply" "$tmp/prog$step.png" 200 2.5
    pics+=("$tmp/prog$step.png")
  done
  row "$img/progressive_cornell.png" "${pics[@]}"
}


# ---- Through meshlabserver and the MeshLab GUI --------------------------------

run_mlx() {  # mesh out script
  "$build/mlx-run" -i "$1" -o "$2" -m vc vq -s "$3" >"$tmp/log.txt" 2>&1 || { cat "$tmp/log.txt"; exit 1; }
}

# A screenshot of the real MeshLab GUI showing a PLY (its vertex colours, or
# its points), cropped to the view and scaled to size x size.
shot() {  # ply out size
  GUI_NO_CHECK=1 GUI_SETTLE=5 bash "$root/tests/integration/gui_screenshot.sh" "$build/stage/bin" "$1" "$tmp/shot.png"
  convert "$tmp/shot.png" -crop 860x860+0+60 +repage -resize "$3x$3" -strip "$2"
  echo "wrote $2 ($(stat -c %s "$2") bytes)"
}

# The caustic Cornell box: three layers (box, glass sphere, mirror) photon-mapped
# by meshlabserver; each layer saved, then merged for one picture with the
# glass and the mirror painted (they carry no diffuse radiosity).
caustic() {
  local l=("$m"/caustic_cornell_{box,glass_sphere,mirror}.ply)
  "$gi" script photonmap --mesh "${l[0]}" --scene_extent "All visible layers" --emitter_source 1 --photons 4000000 \
    --caustic_k 256 --k_nearest 200 --light_samples 1024 --exposure 0.7 -o "$tmp/caustic.mlx"
  for k in 0 1 2; do
    "$build/mlx-run" -i "${l[0]}" -i "${l[1]}" -i "${l[2]}" -o "$tmp/caustic$k.ply" -l "$k" -m vc vq -s "$tmp/caustic.mlx" \
      >"$tmp/log.txt" 2>&1 || { cat "$tmp/log.txt"; exit 1; }
  done
  "$py" "$root/scripts/merge_ply.py" "$tmp/caustic_all.ply" "$tmp/caustic0.ply" "$tmp/caustic1.ply=150,170,190" \
    "$tmp/caustic2.ply=205,210,220"
  "$py" "$root/scripts/turn_ply.py" "$tmp/caustic_all.ply" "$tmp/caustic_view.ply" 16
  shot "$tmp/caustic_view.ply" "$img/cornell_caustic.png" 480
}

# The picture at the top of the README: the caustic Cornell box with its glossy block, computed by our
# renderer through the staged meshlabserver: photon mapping over the four layers (the first
# pass, left on the meshes as the attribute Radiosity), then GI: Ray Traced View in two-pass
# mode in the same script (direct light ray traced, caustics from its caustic map, glossy
# reflection by sampling the block's GGX lobe, mirror and glass followed), written as PNG.
raytraced() {
  local l=("$m"/caustic_cornell_{box,glass_sphere,mirror,glossy_block}.ply)
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

# Cornell box: radiosity after 0, 1, 3 bounces and converged. The box opens
# towards -z; MeshLab's default camera looks from +z: turn the copies 180
# degrees about y for the picture.
bounces() {
  local fine="$m/cornell_box_fine.ply" b
  for b in 0 1 3 -1; do
    "$gi" script radiosity --mesh "$fine" --emitter_source 1 --rays_per_patch 1024 --bounces "$b" --exposure 0.7 -o "$tmp/rad$b.mlx"
    run_mlx "$fine" "$tmp/bounces$b.ply" "$tmp/rad$b.mlx"
    "$py" "$root/scripts/turn_ply.py" "$tmp/bounces$b.ply" "$tmp/bounces${b}_view.ply"
  done
  shot "$tmp/bounces-1_view.ply" "$img/cornell_radiosity.png" 480
  for b in 0 1 3 -1; do
    shot "$tmp/bounces${b}_view.ply" "$tmp/bounces$b.png" 300
  done
  convert "$tmp/bounces0.png" "$tmp/bounces1.png" "$tmp/bounces3.png" "$tmp/bounces-1.png" +append -strip \
    "$img/cornell_bounce_sequence.png"
  echo "wrote $img/cornell_bounce_sequence.png"
}

ao() {
  "$gi" script ao --rays_per_vertex 1024 -o "$tmp/ao.mlx"
  run_mlx "$m/bunny.ply" "$tmp/bunny_ao.ply" "$tmp/ao.mlx"
  shot "$tmp/bunny_ao.ply" "$img/bunny_ao.png" 480
}

# ---- Course figures through the command-line tool -------------------------------

caustic_layers=(--layer "$m/caustic_cornell_glass_sphere.ply" --layer "$m/caustic_cornell_mirror.ply")

# Whitted (sharp shadows from the light's centre, the glossy block without
# its blurred reflection) beside distributed ray tracing (the light, the lobe
# and the pixel sampled: soft shadows, glossy reflection).
raytracing() {
  local mode spp
  for mode in Whitted Distributed; do
    spp=4
    [[ $mode == Distributed ]] && spp=32
    "$gi" render "$m/caustic_cornell_box.ply" "${caustic_layers[@]}" --layer "$m/caustic_cornell_glossy_block.ply" \
      --emitter_source 1 --glossy_color 255,200,120 --glossy_roughness 0.15 --mode "$mode" --width 240 --height 240 \
      --samples_per_pixel "$spp" --image_path "$tmp/rt_$mode.png" -q
  done
  row "$img/raytracing_cornell.png" "$tmp/rt_Whitted.png" "$tmp/rt_Distributed.png"
}

# Radiosity (patch averages on the coarse box) as the first pass, then the
# view: the first pass alone, ray-traced direct + stored indirect, final
# gather; and the path-traced yardstick. Same camera and exposure.
twopass() {
  "$gi" radiosity "$m/cornell_box.ply" --emitter_source 1 --vertex_output "Patch average" -o "$tmp/tp.ply" -q
  local view=(--emitter_source 1 --width 180 --height 180 --exposure 2.5)
  local k=0 how
  local -a pics=()
  for how in "First pass alone" "Ray-traced direct + stored indirect" "Direct + caustic map + final gather"; do
    "$gi" render "$tmp/tp.ply" "${view[@]}" --mode Two-pass --two_pass_diffuse "$how" --first_pass_caustics false \
      --samples_per_pixel 16 --image_path "$tmp/tp$k.png" -q
    pics+=("$tmp/tp$k.png")
    k=$((k + 1))
  done
  "$gi" render "$m/cornell_box.ply" "${view[@]}" --mode "Path traced" --samples_per_pixel 256 --image_path "$tmp/tp_pt.png" -q
  row "$img/twopass_cornell.png" "${pics[@]}" "$tmp/tp_pt.png"
}

# Photon mapping on the caustic box (-o writes all layers into one PLY; the
# sphere and mirror carry no diffuse light and show black), seen through
# "First pass alone"; its photons (OUT.Photons.ply: global map orange, caustic
# map blue) as MeshLab shows the point cloud, from the open side.
photons() {
  "$gi" photonmap "$m/caustic_cornell_box.ply" "${caustic_layers[@]}" --emitter_source 1 --photons 200000 \
    --photon_layer true --photon_layer_max 60000 -o "$tmp/pm.ply" -q
  first_pass "$tmp/pm.ply" "$tmp/pm.png" 240 0.7
  "$py" "$root/scripts/turn_ply.py" "$tmp/pm.Photons.ply" "$tmp/photons_view.ply"
  shot "$tmp/photons_view.ply" "$tmp/photons.png" 240
  row "$img/photonmap_caustic.png" "$tmp/pm.png" "$tmp/photons.png"
}

# The light-path split of photon mapping on the caustic box: each of the four
# attributes renamed to Radiosity and seen through "First pass alone".
lightpaths() {
  "$gi" photonmap "$m/caustic_cornell_box.ply" "${caustic_layers[@]}" --emitter_source 1 --photons 400000 \
    --light_path_split true -o "$tmp/lp.ply" -q
  local part
  local -a pics=()
  for part in emitted direct indirect caustic; do
    "$py" "$root/scripts/rename_ply_attribute.py" "$tmp/lp.ply" "$tmp/lp_$part.ply" "Radiosity_$part" Radiosity
    first_pass "$tmp/lp_$part.ply" "$tmp/lp_$part.png" 180 1
    pics+=("$tmp/lp_$part.png")
  done
  row "$img/light_paths_caustic.png" "${pics[@]}"
}

# The path-traced reference (the rendering equation per vertex) of the Cornell
# box at 16 and 256 paths per vertex, seen through "First pass alone": the
# noise falls as N^-1/2 (sixteen times the paths, a quarter of the noise).
reference() {
  local n
  local -a pics=()
  for n in 16 256; do
    "$gi" reference "$m/cornell_box.ply" --emitter_source 1 --samples_per_vertex "$n" -o "$tmp/ref$n.ply" -q
    first_pass "$tmp/ref$n.ply" "$tmp/ref$n.png" 200 2.5
    pics+=("$tmp/ref$n.png")
  done
  row "$img/reference_cornell.png" "${pics[@]}"
}

# Radiosity on the coarse Cornell box against the path-traced reference
# (256 paths per vertex), final gather beside patch averages: z-scores
# (blue below, white on, red above the reference; range +-3) as MeshLab
# shows the vertex colours, from the open side.
errormap() {
  "$gi" reference "$m/cornell_box.ply" --emitter_source 1 --samples_per_vertex 256 -o "$tmp/ref.ply" -q
  local k=0 vo
  local -a pics=()
  for vo in "Final gather" "Patch average"; do
    "$gi" radiosity "$m/cornell_box.ply" --emitter_source 1 --vertex_output "$vo" -o "$tmp/rad$k.ply" -q
    "$gi" errormap "$tmp/rad$k.ply" --reference_source "PLY file" --reference_file "$tmp/ref.ply" \
      --error_measure "z-score ((value - reference) / standard error)" -o "$tmp/err$k.ply" 2>&1 | grep -o "|z| > 3 at [0-9]* of [0-9]* vertices"
    "$py" "$root/scripts/turn_ply.py" "$tmp/err$k.ply" "$tmp/err${k}_view.ply"
    shot "$tmp/err${k}_view.ply" "$tmp/err$k.png" 240
    pics+=("$tmp/err$k.png")
    k=$((k + 1))
  done
  row "$img/errormap_cornell.png" "${pics[@]}"
}

groups="hemicube artefacts progressive raytraced caustic bounces ao reference raytracing twopass photons lightpaths errormap"
if [[ -z "${ONLY:-}" ]]; then
  for g in $groups; do
    SECONDS=0
    "$g"
    echo "group $g: $SECONDS s"
  done
elif [[ " $groups " == *" $ONLY "* ]]; then
  "$ONLY"
else
  echo "ONLY must be one of: $groups" >&2
  exit 2
fi
