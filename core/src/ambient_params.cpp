// Parameter table of the ambient filters (MeshLab dialog and CLI flags).
#include <cmath>

#include "gi/ambient.h"
#include "gi/color.h"

namespace gi {

namespace {
// Obscurance needs hit distances: the strata estimator (visibility only) is
// not among its choices (a script could choose it, and the run refused it).
std::vector<std::string> estimatorChoices(AmbientMode mode) {
  std::vector<std::string> c = kAOEstimators.choices();
  if (mode == AmbientMode::Obscurance) c.resize(size_t(kAOEstimators.index(AOEstimator::Strata)));
  return c;
}
}  // namespace

std::vector<ParamSpec> AmbientOptions::specs(AmbientMode mode) {
  std::vector<ParamSpec> s;
  s.push_back({.name = "rays_per_vertex", .label = "Rays per vertex",
               .help = "Number of rays cast from each vertex when no target error is set. The error falls roughly as "
                       "N^-3/4 with our scrambled Sobol directions (plain random sampling: N^-1/2). Powers of two "
                       "are best.",
               .type = ParamType::Int, .def = 256, .min = 1, .max = 1 << 20});
  s.push_back({.name = "target_error", .label = "Target standard error",
               .help = mode == AmbientMode::Sky
                           ? "Adaptive sampling: if > 0, a pilot (sky rays of its own, in rounds of 32 until the "
                             "estimated standard error of its sky light (W/m^2) is below twice this value, at most "
                             "min_rays or a quarter of max_rays, whichever is more) predicts the rays each vertex "
                             "needs for this value, and the vertex casts that many. The pilot is left out of the "
                             "result: a count decided from the rays it keeps biases the mean low where the sky is "
                             "seen through small openings. So the target holds at most vertices, not all. The sun's "
                             "shadow rays are a fixed count (sun_rays). 0 = fixed ray count."
                           : "Adaptive sampling: if > 0, a pilot (rays of its own, in rounds of 32 until its "
                             "estimated standard error is below twice this value, at most min_rays or a quarter of "
                             "max_rays, whichever is more) predicts the rays each vertex needs for this value, and "
                             "the vertex casts that many (adaptive strata: the pilot's grids, the first of about "
                             "min_rays strata, each next with every stratum cut into four, predict how many such "
                             "rounds the result's grids take). The pilot is left out of the result: a count decided "
                             "from the rays it keeps biases the mean low where light comes through small openings. "
                             "So the target holds at most vertices, not all. The shared estimator instead doubles the "
                             "rays of the vertices whose pooled error is above the target, round by round. 0 = fixed "
                             "ray count.",
               .type = ParamType::Float, .def = 0.0, .min = 0.0, .max = mode == AmbientMode::Sky ? 1e9 : 0.5});
  s.push_back({.name = "min_rays", .label = "Minimum rays (adaptive)",
               .help = "Adaptive sampling: the fewest rays of the pilot and of the result.",
               .type = ParamType::Int, .def = 32, .min = 1, .max = 1 << 20});
  s.push_back({.name = "max_rays", .label = "Maximum rays (adaptive)",
               .help = "Adaptive sampling never casts more than this many rays from a vertex's side, the pilot's "
                       "included, where it is at least twice min_rays (the pilot and the result cast min_rays each "
                       "at least; a two-sided surface casts from both sides, sky lighting adds sun_rays; adaptive "
                       "strata: a round starts only if it stays within this count with every stratum split; the "
                       "first round, cast for the pilot and the result, must fit twice).",
               .type = ParamType::Int, .def = 4096, .min = 1, .max = 1 << 22});
  const bool obscurance = mode == AmbientMode::Obscurance;
  s.push_back({.name = "max_distance", .label = obscurance ? "Maximum distance" : "Maximum ray distance",
               .help = obscurance
                           ? "Hits farther than this count as fully open (obscurance 1); nearer hits count "
                             "min(1, d/d_max)^k. Absolute length or % of the bounding-box diagonal; above 0 "
                             "(0 is refused: every hit would count as fully open)."
                           : mode == AmbientMode::Sky
                           ? "Geometry farther than this does not occlude the sky or the sun (0 = infinite): the "
                             "rays, the sun's too, stop there."
                           : "Geometry farther than this does not occlude (0 = infinite). Rays stop there, and "
                             "vertices with no geometry above their tangent plane within this distance get 1 without "
                             "casting rays (with 'Light from a cone only' off).",
               .type = ParamType::Distance, .def = obscurance ? 0.1 : 0.0, .min = 0.0, .max = 10.0});
  s.push_back(seedSpec("sampling sequences"));
  if (mode == AmbientMode::Occlusion) {
    s.push_back({.name = "bent_normals", .label = "Write bent normals",
                 .help = "Store the mean unoccluded direction of each vertex in the per-vertex attribute "
                         "'BentNormal'.",
                 .type = ParamType::Bool, .def = false});
    s.push_back({.name = "bent_normals_to_vertex_normals", .label = "Bent normals into vertex normals",
                 .help = "Also overwrite the vertex normals with the bent normals (for shading with them).",
                 .type = ParamType::Bool, .def = false});
    s.push_back({.name = "use_cone", .label = "Light from a cone only",
                 .help = "Directional bias: only directions inside the cone below count, normalised by the "
                         "unoccluded cosine-weighted part of the cone (a vertex facing away from the cone gets 0).",
                 .type = ParamType::Bool, .def = false});
    s.push_back({.name = "cone_direction", .label = "Cone direction",
                 .help = "Axis of the cone (towards the light).",
                 .type = ParamType::Direction, .defVec = glm::vec3(0.f, 1.f, 0.f)});
    s.push_back({.name = "cone_angle", .label = "Cone half-angle (deg)",
                 .help = "Half-angle of the cone in degrees.",
                 .type = ParamType::Float, .def = 45, .min = 0.5, .max = 180,
                 .usedWhen = {{"use_cone", {1}}}});
    s.push_back({.name = "color_mapping", .label = "Colour output",
                 .help = "'Grey': vertex colour = AO x 255 as grey (the usual AO display). 'Multiply colour': the "
                         "existing vertex colour times AO (in linear light). 'Keep colour': only the quality is "
                         "written.",
                 .type = ParamType::Enum, .def = kAOColorMappings.index(AOColorMapping::Grey),
                 .choices = kAOColorMappings.choices()});
  }
  if (mode == AmbientMode::Obscurance)
    s.push_back({.name = "falloff_exponent", .label = "Falloff exponent k",
                 .help = "rho(d) = min(1, d/d_max)^k: 1 is linear, smaller values darken only very near geometry.",
                 .type = ParamType::Float, .def = 1.0, .min = 0.01, .max = 16});
  if (mode == AmbientMode::Sky) {
    s.push_back({.name = "sky_color", .label = "Sky colour",
                 .help = "Colour of the uniform sky (sRGB, converted to linear light: 128 grey is 0.216 of "
                         "white's irradiance).",
                 .type = ParamType::Color, .defVec = glm::vec3(1.f)});
    s.push_back({.name = "sky_irradiance", .label = "Sky irradiance (W/m^2)",
                 .help = "Irradiance the uniform sky gives an unoccluded surface (pi x sky radiance).",
                 .type = ParamType::Float, .def = 1.0, .min = 0.0, .max = 1e9});
    s.push_back({.name = "sun_direction", .label = "Sun direction",
                 .help = "Direction towards the sun, in the mesh's coordinates (the default assumes y is up; "
                         "for a z-up scan give e.g. 0.3,0.2,1). Faces turned away from it get no sun.",
                 .type = ParamType::Direction, .defVec = glm::vec3(0.3f, 1.f, 0.2f)});
    s.push_back({.name = "sun_color", .label = "Sun colour",
                 .help = "Colour of the sun (sRGB): scales each channel of its irradiance (linear colour). White "
                         "(the default, as in the other filters) gives the irradiance below in every channel.",
                 .type = ParamType::Color, .defVec = glm::vec3(1.f)});
    s.push_back({.name = "sun_irradiance", .label = "Sun irradiance (W/m^2)",
                 .help = "Irradiance of a white sun on a surface facing it (times the linear sun colour per "
                         "channel); 0 = sky only.",
                 .type = ParamType::Float, .def = 3.0, .min = 0.0, .max = 1e9});
    s.push_back({.name = "sun_angular_radius", .label = "Sun angular radius (deg)",
                 .help = "Soft shadows: shadow rays go to points spread over the sun's disk of this angular radius "
                         "(the real sun: 0.27).",
                 .type = ParamType::Float, .def = 0.27, .min = 0.0, .max = 45});
    s.push_back({.name = "sun_rays", .label = "Sun rays per vertex",
                 .help = "Shadow rays towards the sun's disk per vertex.",
                 .type = ParamType::Int, .def = 64, .min = 1, .max = 1 << 20});
  }
  if (mode != AmbientMode::Sky) {
    s.push_back({.name = "estimator", .label = "Estimator",
                 .help = "'Per vertex': each vertex averages its own rays only (independent, unbiased estimates). "
                         "'Shared with neighbours': each vertex also counts the rays of the vertices around it whose "
                         "normals are within the tolerance below (a first-order fit over their positions, so a "
                         "gradient does not bias it), as far as (Lepski's rule) the fitted value agrees with the "
                         "smaller neighbourhoods' within one standard error: on dense meshes neighbours see almost "
                         "the same hemisphere, so the same error needs fewer rays; at creases, contact shadows and "
                         "thin features the neighbourhood stays small. The standard error counts every ray pooled. "
                         "Which to choose (measured, README): from about 100k vertices, shared with a target error "
                         "(e.g. 0.02, minimum rays 8) reaches a given error with 6 to 8 times fewer rays and about "
                         "a third of the time; on meshes of a few thousand to 30k vertices, or where the occlusion "
                         "changes from vertex to vertex, per vertex is as fast or faster" +
                         std::string(mode == AmbientMode::Obscurance
                                         ? ". (Occlusion also has 'Adaptive strata', which tests visibility only: "
                                           "obscurance needs the hit distances.)"
                                         : ", and adaptive strata faster still. "
                         "'Adaptive strata' (occlusion): each vertex's hemisphere is cut into about "
                         "rays_per_vertex strata (R rows of elevation by 2R of azimuth), one jittered ray each, "
                         "and a stratum is split into four where its neighbours disagree (an occlusion edge "
                         "crosses it), so rays go where the shadows' edges are; still unbiased (a stratum's split "
                         "never depends on its own ray) and still per vertex; with a target error, rounds of "
                         "ever finer grids until it is met. It casts about 1.6 times "
                         "rays_per_vertex on occluded vertices and reached MeshLab's errors 1.4 to 1.6 times "
                         "sooner than the per-vertex estimator on the two bunnies (README). "
                         "The cone option is always per vertex."),
                 .type = ParamType::Enum, .def = kAOEstimators.index(AOEstimator::PerVertex),
                 .choices = estimatorChoices(mode)});
    s.push_back({.name = "share_rings", .label = "Sharing: largest neighbourhood (rings)",
                 .help = "Shared estimator: how far a vertex may pool, in mesh rings (1 = its direct neighbours, "
                         "about 7 vertices; 3 = about 37; 5 = about 91). Larger pools more rays where the occlusion "
                         "varies slowly; the cost of pooling grows with the square of it.",
                 .type = ParamType::Int, .def = 3, .min = 1, .max = 16,
                 .usedWhen = {{"estimator", {kAOEstimators.index(AOEstimator::Shared)}}}});
    s.push_back({.name = "share_normal_angle", .label = "Sharing: normal tolerance (deg)",
                 .help = "Shared estimator: only neighbours whose normal is within this angle of the vertex's pool "
                         "their rays (AO depends on the normal: its cosine lobe), and the neighbourhood grows only "
                         "through them, so it stops at creases and never reaches the other side of a thin sheet.",
                 .type = ParamType::Float, .def = 10.0, .min = 0.0, .max = 90.0,
                 .usedWhen = {{"estimator", {kAOEstimators.index(AOEstimator::Shared)}}}});
  }
  s.push_back({.name = "ray_batching", .label = "Ray batching",
               .help = "How rays are handed to Embree: single rays sharing the vertex as origin (fastest in our "
                       "benchmarks: the rays of one vertex diverge too much for packets), 8-wide packets, or "
                       "streams. Results are identical.",
               .type = ParamType::Enum, .def = kBatchModes.index(BatchMode::Single), .choices = kBatchModes.choices()});
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
  o.batch = kBatchModes.get(v, "ray_batching");
  if (mode != AmbientMode::Sky) {
    o.estimator = kAOEstimators.get(v, "estimator");
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
