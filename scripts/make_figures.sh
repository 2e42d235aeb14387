#!/usr/bin/env bash
# Makes the figures of docs/course.md into docs/img/ with the command-line
# tool (the same engine calls as the MeshLab filters), from fixed cameras:
#   - the hemicube of a Cornell box floor patch: the cells by patch, by delta
#     form factor, and Nusselt's disk (GI: Hemicube of Selected Face);
#   - the artefact pack (test_meshes/shadow_leak.ply, staircase.ply) solved
#     with patch averages, final gather and adaptive refinement, each seen
#     through GI: Ray Traced View in two-pass mode with "First pass alone"
#     (the per-vertex radiosity as the mesh carries it), side by side;
#   - the progressive-refinement sequence of the Cornell box (the patch
#     average after 1, 10 and 100 shots with the ambient term).
# Needs build/tools/gi and ImageMagick's convert. ONLY=hemicube|artefacts|progressive
# makes one group. About a minute on two cores.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${GI_BUILD_DIR:-$root/build}"
gi="$build/tools/gi"
img="$root/docs/img"
m="$root/test_meshes"
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
    "$gi" render "$tmp/$name$k.ply" --emitter_source 1 --mode Two-pass --two_pass_diffuse "First pass alone" \
      --camera "Look at" "$@" --width 240 --height 240 --samples_per_pixel 4 --exposure "$exposure" \
      --image_path "$tmp/$name$k.png" -q
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
    python3 "$root/scripts/rename_ply_attribute.py" "$tmp/prog.ply" "$tmp/prog$step.ply" "Radiosity_step_$step" Radiosity
    "$gi" render "$tmp/prog$step.ply" --emitter_source 1 --mode Two-pass --two_pass_diffuse "First pass alone" \
      --width 200 --height 200 --samples_per_pixel 4 --exposure 2.5 --image_path "$tmp/prog$step.png" -q
    pics+=("$tmp/prog$step.png")
  done
  row "$img/progressive_cornell.png" "${pics[@]}"
}

case "${ONLY:-all}" in
  hemicube) hemicube ;;
  artefacts) artefacts ;;
  progressive) progressive ;;
  all) hemicube; artefacts; progressive ;;
  *) echo "ONLY must be hemicube, artefacts or progressive" >&2; exit 2 ;;
esac
