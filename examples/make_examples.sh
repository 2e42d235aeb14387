#!/usr/bin/env bash
# Regenerates the example scripts with `gi script` (complete parameter lists,
# as MeshLab 2020.09's meshlabserver needs). Run after changing a filter's
# parameters; the meshlabserver_examples test runs every script.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
gi="${GI:-$root/build/tools/gi}"
ex="$root/examples"
m="$root/test_meshes"
"$gi" script ao --rays_per_vertex 512 -o "$ex/ambient_occlusion.mlx"
"$gi" script ao --target_error 0.005 --max_rays 8192 -o "$ex/ambient_occlusion_adaptive.mlx"
"$gi" script ao --estimator "Shared with neighbours" --target_error 0.01 --min_rays 8 \
  -o "$ex/ambient_occlusion_shared.mlx"
"$gi" script ao --estimator "Adaptive strata" --rays_per_vertex 128 -o "$ex/ambient_occlusion_strata.mlx"
"$gi" script ao --estimator "Adaptive strata" --target_error 0.01 -o "$ex/ambient_occlusion_strata_adaptive.mlx"
"$gi" script thickness --rays_per_vertex 64 -o "$ex/thickness.mlx"
"$gi" script obscurance --mesh "$m/bunny.ply" --max_distance 20% -o "$ex/obscurance_bunny.mlx"
"$gi" script sky --sun_direction 0.4,1,0.3 --sun_angular_radius 2 -o "$ex/sky_lighting.mlx"
"$gi" script radiosity --mesh "$m/cornell_box.ply" --emitter_source 1 -o "$ex/radiosity_cornell.mlx"
"$gi" script radiosity --mesh "$m/cornell_box.ply" --bounces 1 --emitter_source 1 --vertex_output "Patch average" \
  -o "$ex/radiosity_cornell_one_bounce.mlx"
# Progressive refinement as the course shows it: the ambient term on, the patch-average B after 0, 10, 100
# and 1000 shots kept as the attributes Radiosity_step_0 ... Radiosity_step_1000.
"$gi" script radiosity --mesh "$m/cornell_box.ply" --emitter_source 1 --solver "Progressive refinement" \
  --ambient_term true --snapshot_steps "0, 10, 100, 1000" --vertex_output "Patch average" \
  -o "$ex/radiosity_cornell_progressive.mlx"
"$gi" script radiosity --mesh "$m/cornell_box.ply" --emitter_source "Selected faces" -o "$ex/radiosity_selected_faces.mlx"
"$gi" script radiosity --mesh "$m/cornell_box.ply" --emitter_source 1 --refine true --refine_max_depth 2 \
  -o "$ex/radiosity_cornell_refined.mlx"
"$gi" script photonmap --mesh "$m/cornell_box.ply" --emitter_source 1 --photons 1000000 --k_nearest 128 \
  -o "$ex/photonmap_cornell.mlx"
"$gi" script reference --mesh "$m/cornell_box.ply" --emitter_source 1 --target_relative_error 0.02 \
  -o "$ex/reference_cornell.mlx"
# The caustic Cornell box: open caustic_cornell_box.ply, caustic_cornell_glass_sphere.ply and
# caustic_cornell_mirror.ply as three layers (the glass and the mirror are found by their names).
"$gi" script photonmap --mesh "$m/caustic_cornell_box.ply" --scene_extent "All visible layers" --emitter_source 1 \
  --photons 1000000 --caustic_k 32 -o "$ex/photonmap_caustic.mlx"
"$gi" script photonmap --mesh "$m/caustic_cornell_box.ply" --scene_extent "All visible layers" --emitter_source 1 \
  --photons 250000 --progressive true --passes 16 -o "$ex/photonmap_caustic_progressive.mlx"
# The light-path split (Heckbert 1990 notation): Radiosity_emitted (L E), Radiosity_direct (L D E),
# Radiosity_caustic (L S+ D E) and Radiosity_indirect (the rest) as per-vertex attributes.
"$gi" script photonmap --mesh "$m/caustic_cornell_box.ply" --scene_extent "All visible layers" --emitter_source 1 \
  --photons 1000000 --caustic_k 32 --light_path_split true -o "$ex/photonmap_caustic_paths.mlx"
"$gi" script formfactors --face_index 0 --form_factor_method Hemicube -o "$ex/form_factors_face0.mlx"
# The hemicube of a Cornell box floor patch (face 49, in front of the tall block) as three raster layers.
"$gi" script hemicube --face_index 49 --hemicube_resolution 64 -o "$ex/hemicube_cornell_floor.mlx"
# The artefact pack: each scene with patch averages (the artefact), final gather and adaptive refinement.
# Refinement: 2 levels end the shadow leak's patches at the partition, 4 follow the staircase's edge.
for s in shadow_leak:2 staircase:4; do
  depth=${s#*:}
  s=${s%:*}
  "$gi" script radiosity --mesh "$m/$s.ply" --emitter_source 1 --vertex_output "Patch average" \
    -o "$ex/${s}_patch_average.mlx"
  "$gi" script radiosity --mesh "$m/$s.ply" --emitter_source 1 --vertex_output "Final gather" \
    -o "$ex/${s}_final_gather.mlx"
  "$gi" script radiosity --mesh "$m/$s.ply" --emitter_source 1 --vertex_output "Patch average" --refine true \
    --refine_max_depth "$depth" -o "$ex/${s}_refined.mlx"
done
# The photons of the caustic box as a point-cloud layer (global map orange, caustic map blue).
"$gi" script photonmap --mesh "$m/caustic_cornell_box.ply" --scene_extent "All visible layers" --emitter_source 1 \
  --photons 200000 --photon_layer true -o "$ex/photonmap_caustic_photons.mlx"
# The error map, three filters in one script: the path-traced reference (it leaves Reference and
# ReferenceStdError), radiosity on the same layer (it overwrites quality), then the z-score of the radiosity
# against the reference. gi script writes one filter: the three are joined without their inner
# <FilterScript> lines.
{
  "$gi" script reference --mesh "$m/cornell_box.ply" --emitter_source 1 --samples_per_vertex 64 | sed '$d'
  "$gi" script radiosity --mesh "$m/cornell_box.ply" --emitter_source 1 | sed '1,2d;$d'
  "$gi" script errormap --mesh "$m/cornell_box.ply" --error_measure 2 | sed '1,2d'
} > "$ex/errormap_radiosity_cornell.mlx"
echo "examples written to $ex"
