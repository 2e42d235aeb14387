// Ambient occlusion, obscurance and sky lighting per vertex by ray casting.
//   AO(p)  = 1/pi ∫_H V(p, w) cos(theta) dw           (1 = open, 0 = closed)
//   W(p)   = 1/pi ∫_H rho(d(p, w)) cos(theta) dw      (obscurance, Zhukov et al. 1998;
//            rho(d) = min(1, d / d_max)^k, Iones et al. 2003 use a similar falloff)
//   E(p)   = E_sky AO(p) + E_sun <V(p, w) max(0, n.w)>_{w in sun disk}
//   B(p)   = b / |b|, b = 1/pi ∫_H V(p, w) w cos(theta) dw   (bent normal: the cosine-weighted mean
//            unoccluded direction, Landis 2002; with obscurance V is replaced by rho)
// Estimators: cosine-weighted directions from an Owen-scrambled Sobol
// sequence per vertex (pbrt-v4's AOIntegrator estimator V cos / (pi pdf) = V).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/color.h"
#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/scene.h"
#include "gi/vertex_part.h"

namespace gi {

enum class AmbientMode { Occlusion = 0, Obscurance = 1, Sky = 2 };
enum class AOColorMapping { Grey, MultiplyColor, KeepColor };
inline constexpr auto kAOColorMappings = makeEnumTable<AOColorMapping>({
    {AOColorMapping::Grey, "Grey", "grey"},
    {AOColorMapping::MultiplyColor, "Multiply colour", "multiply colour"},
    {AOColorMapping::KeepColor, "Keep colour", "keep colour"},
});
// The "ray_batching" parameter (BatchMode is the ray caster's).
inline constexpr auto kBatchModes = makeEnumTable<BatchMode>({
    {BatchMode::Single, "Single", "single rays"},
    {BatchMode::Packet8, "Packet8", "8-wide packets"},
    {BatchMode::Stream, "Stream", "streams"},
});
// PerVertex: each vertex's own rays only (independent estimates, the
// estimator above). Shared: neighbours' rays pooled where they agree
// (gi/ao_shared.h). Strata: each vertex's own rays, one per stratum of its
// hemisphere, the strata at occlusion edges split (gi/ao_strata.h;
// occlusion only).
enum class AOEstimator { PerVertex, Shared, Strata };
inline constexpr auto kAOEstimators = makeEnumTable<AOEstimator>({
    {AOEstimator::PerVertex, "Per vertex", "per vertex"},
    {AOEstimator::Shared, "Shared with neighbours", "shared with neighbours"},
    {AOEstimator::Strata, "Adaptive strata", "adaptive strata"},
});

struct AmbientOptions {
  AmbientMode mode = AmbientMode::Occlusion;
  AOEstimator estimator = AOEstimator::PerVertex;
  int raysPerVertex = 256;       // fixed count when targetError == 0
  double targetError = 0.0;      // adaptive: stop at this standard error per vertex
  int minRays = 32, maxRays = 4096;
  double maxDistance = 0.0;      // 0 = infinite
  uint32_t seed = 0;
  bool bentNormals = false;      // also compute the mean unoccluded direction
  bool useCone = false;          // light from a cone only (directional bias)
  glm::vec3 coneDirection{0.f, 1.f, 0.f};
  float coneAngleDeg = 45.f;     // half-angle
  float falloffExponent = 1.f;   // obscurance
  glm::vec3 skyRadiantColor{1.f};  // linear
  glm::vec3 sunColor{1.f};       // linear; white, as in every filter with a sun
  float skyIrradiance = 1.f;     // W/m^2 on an unoccluded surface
  float sunIrradiance = 3.f;     // W/m^2 on a surface facing the sun
  glm::vec3 sunDirection = *unitDirection({0.3f, 1.f, 0.2f});  // towards the sun, unit length
  float sunAngularRadiusDeg = 0.27f;
  int sunRays = 64;
  BatchMode batch = BatchMode::Single;
  bool skipOpenVertices = true;  // prove-and-skip vertices with nothing within maxDistance
  bool mergeDuplicates = true;   // same position and normal computed once
  int shareRings = 3;            // Shared: largest neighbourhood in mesh rings
  float shareNormalAngleDeg = 10.f;  // Shared: neighbours' normals within this angle
  // Shared: memory for each vertex's rings kept across adaptive rounds (about
  // 150 bytes per vertex at 3 rings); above it they are searched again each
  // round (same results, slower).
  size_t shareRingBytes = size_t(1) << 30;
  VertexPart vertices;           // which vertices to compute (a split run); the others are left 0

  static std::vector<ParamSpec> specs(AmbientMode mode);
  static AmbientOptions fromParams(AmbientMode mode, const ParamValues& v);
};

struct AmbientResult {
  std::vector<float> value;          // AO / obscurance in [0,1], or luminance of E (Sky)
  std::vector<glm::vec3> rgb;        // Sky: linear irradiance; else empty
  std::vector<float> stdError;       // estimated standard error of value
  std::vector<int> rays;             // rays cast per vertex (0 = skipped)
  std::vector<glm::vec3> bentNormal; // if requested
  RunStats stats;
};

// Vertex normals: scene.vertexNormals if given, else computed from faces.
AmbientResult computeAmbient(const Scene& scene, const RayCaster& caster, const AmbientOptions& opt,
                             const Progress& progress = Progress(nullptr));

}  // namespace gi
