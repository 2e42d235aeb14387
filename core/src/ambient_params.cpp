// Parameter table of the ambient filters (MeshLab dialog and CLI flags).
#include <cmath>

#include "gi/ambient.h"
#include "gi/color.h"

namespace gi {

std::vector<ParamSpec> AmbientOptions::specs(AmbientMode mode) {
  std::vector<ParamSpec> s;
  s.push_back({"rays_per_vertex", "Rays per vertex",
               "Number of rays cast from each vertex when no target error is set. The error falls roughly as "
               "N^-3/4 with our scrambled Sobol directions (plain random sampling: N^-1/2). Powers of two are best.",
               ParamType::Int, 256, 1, 1 << 20});
  s.push_back({"target_error", "Target standard error",
               "Adaptive sampling: if > 0, each vertex casts rays in rounds of 32 until its own estimated standard "
               "error is below this value (between the minimum and maximum ray counts). 0 = fixed ray count.",
               ParamType::Float, 0.0, 0.0, 0.5});
  s.push_back({"min_rays", "Minimum rays (adaptive)", "Adaptive sampling never stops before this many rays.",
               ParamType::Int, 32, 1, 1 << 20});
  s.push_back({"max_rays", "Maximum rays (adaptive)", "Adaptive sampling never casts more than this many rays.",
               ParamType::Int, 4096, 1, 1 << 22});
  s.push_back({"max_distance", mode == AmbientMode::Obscurance ? "Maximum distance" : "Maximum ray distance",
               mode == AmbientMode::Obscurance
                   ? "Hits farther than this count as fully open (obscurance 1); nearer hits count "
                     "min(1, d/d_max)^k. Absolute length or % of the bounding-box diagonal."
                   : "Geometry farther than this does not occlude (0 = infinite). Rays stop there, and vertices "
                     "with no geometry above their tangent plane within this distance get 1 without casting rays.",
               ParamType::Distance, mode == AmbientMode::Obscurance ? 0.1 : 0.0, 0.0, 10.0});
  s.push_back(seedSpec("sampling sequences"));
  if (mode == AmbientMode::Occlusion) {
    s.push_back({"bent_normals", "Write bent normals",
                 "Store the mean unoccluded direction of each vertex in the per-vertex attribute 'BentNormal'.",
                 ParamType::Bool, 0});
    s.push_back({"bent_normals_to_vertex_normals", "Bent normals into vertex normals",
                 "Also overwrite the vertex normals with the bent normals (for shading with them).",
                 ParamType::Bool, 0});
    s.push_back({"use_cone", "Light from a cone only",
                 "Directional bias: only directions inside the cone below count, normalised by the unoccluded "
                 "cosine-weighted part of the cone (a vertex facing away from the cone gets 0).",
                 ParamType::Bool, 0});
    s.push_back({"cone_direction", "Cone direction", "Axis of the cone (towards the light).", ParamType::Direction,
                 0, 0, 0, {}, glm::vec3(0.f, 1.f, 0.f)});
    s.push_back({"cone_angle", "Cone half-angle (deg)", "Half-angle of the cone in degrees.", ParamType::Float, 45,
                 0.5, 180});
    s.push_back({"color_mapping", "Colour output",
                 "'Grey': vertex colour = AO x 255 as grey (the usual AO display). 'Multiply colour': the existing "
                 "vertex colour times AO (in linear light). 'Keep colour': only the quality is written.",
                 ParamType::Enum, 0, 0, 0, {"Grey", "Multiply colour", "Keep colour"}});
  }
  if (mode == AmbientMode::Obscurance)
    s.push_back({"falloff_exponent", "Falloff exponent k",
                 "rho(d) = min(1, d/d_max)^k: 1 is linear, smaller values darken only very near geometry.",
                 ParamType::Float, 1.0, 0.01, 16});
  if (mode == AmbientMode::Sky) {
    s.push_back({"sky_color", "Sky colour", "Colour of the uniform sky (sRGB).", ParamType::Color, 0, 0, 0, {},
                 glm::vec3(1.f)});
    s.push_back({"sky_irradiance", "Sky irradiance (W/m^2)",
                 "Irradiance the uniform sky gives an unoccluded surface (pi x sky radiance).", ParamType::Float, 1.0,
                 0.0, 1e9});
    s.push_back({"sun_direction", "Sun direction", "Direction towards the sun.", ParamType::Direction, 0, 0, 0, {},
                 glm::vec3(0.3f, 1.f, 0.2f)});
    s.push_back({"sun_color", "Sun colour", "Colour of the sun (sRGB).", ParamType::Color, 0, 0, 0, {},
                 glm::vec3(1.f, 244.f / 255.f, 214.f / 255.f)});
    s.push_back({"sun_irradiance", "Sun irradiance (W/m^2)",
                 "Irradiance of the sun on a surface facing it; 0 = sky only.", ParamType::Float, 3.0, 0.0, 1e9});
    s.push_back({"sun_angular_radius", "Sun angular radius (deg)",
                 "Soft shadows: shadow rays go to points spread over the sun's disk of this angular radius "
                 "(the real sun: 0.27).",
                 ParamType::Float, 0.27, 0.0, 45});
    s.push_back({"sun_rays", "Sun rays per vertex", "Shadow rays towards the sun's disk per vertex.",
                 ParamType::Int, 64, 1, 1 << 20});
  }
  if (mode != AmbientMode::Sky) {
    s.push_back({"estimator", "Estimator",
                 "'Per vertex': each vertex averages its own rays only (independent, unbiased estimates). 'Shared "
                 "with neighbours': each vertex also counts the rays of the vertices around it whose normals are "
                 "within the tolerance below, as far as (Lepski's rule) their pooled value agrees with its own "
                 "within one standard error: on dense meshes neighbours see almost the same hemisphere, so the same "
                 "error needs several times fewer rays; at creases, contact shadows and thin features the "
                 "neighbourhood stays small. The standard error counts every ray pooled. The cone option is always "
                 "per vertex.",
                 ParamType::Enum, 0, 0, 0, {"Per vertex", "Shared with neighbours"}});
    s.push_back({"share_rings", "Sharing: largest neighbourhood (rings)",
                 "Shared estimator: how far a vertex may pool, in mesh rings (1 = its direct neighbours, about 7 "
                 "vertices; 3 = about 37; 5 = about 91). Larger pools more rays where the occlusion varies slowly; "
                 "the cost of pooling grows with the square of it.",
                 ParamType::Int, 3, 1, 16});
    s.push_back({"share_normal_angle", "Sharing: normal tolerance (deg)",
                 "Shared estimator: only neighbours whose normal is within this angle of the vertex's pool their "
                 "rays (AO depends on the normal: its cosine lobe), and the neighbourhood grows only through them, "
                 "so it stops at creases and never reaches the other side of a thin sheet.",
                 ParamType::Float, 10.0, 0.0, 90.0});
  }
  s.push_back({"ray_batching", "Ray batching",
               "How rays are handed to Embree: single rays sharing the vertex as origin (fastest in our "
               "benchmarks: the rays of one vertex diverge too much for packets), 8-wide packets, or streams. "
               "Results are identical.",
               ParamType::Enum, 0, 0, 0, {"Single", "Packet8", "Stream"}});
  return s;
}

AmbientOptions AmbientOptions::fromParams(AmbientMode mode, const ParamValues& v) {
  AmbientOptions o;
  o.mode = mode;
  o.raysPerVertex = v.getInt("rays_per_vertex");
  o.targetError = v.getFloat("target_error");
  o.minRays = v.getInt("min_rays");
  o.maxRays = v.getInt("max_rays");
  o.maxDistance = v.getFloat("max_distance");
  o.seed = uint32_t(v.getInt("seed"));
  const int b = v.getInt("ray_batching");
  o.batch = b == 0 ? BatchMode::Single : b == 1 ? BatchMode::Packet8 : BatchMode::Stream;
  if (mode != AmbientMode::Sky) {
    o.estimator = v.getInt("estimator") == 1 ? AOEstimator::Shared : AOEstimator::PerVertex;
    o.shareRings = v.getInt("share_rings");
    o.shareNormalAngleDeg = float(v.getFloat("share_normal_angle"));
  }
  auto lin = [](glm::vec3 c) { return glm::vec3(srgbToLinear(c.r), srgbToLinear(c.g), srgbToLinear(c.b)); };
  if (mode == AmbientMode::Occlusion) {
    o.bentNormals = v.getBool("bent_normals") || v.getBool("bent_normals_to_vertex_normals");
    o.useCone = v.getBool("use_cone");
    o.coneDirection = v.getDirection("cone_direction");
    o.coneAngleDeg = float(v.getFloat("cone_angle"));
  }
  if (mode == AmbientMode::Obscurance) o.falloffExponent = float(v.getFloat("falloff_exponent"));
  if (mode == AmbientMode::Sky) {
    o.skyRadiantColor = lin(v.getVec("sky_color"));
    o.skyIrradiance = float(v.getFloat("sky_irradiance"));
    o.sunDirection = v.getDirection("sun_direction");
    o.sunColor = lin(v.getVec("sun_color"));
    o.sunIrradiance = float(v.getFloat("sun_irradiance"));
    o.sunAngularRadiusDeg = float(v.getFloat("sun_angular_radius"));
    o.sunRays = v.getInt("sun_rays");
  }
  return o;
}

}  // namespace gi
