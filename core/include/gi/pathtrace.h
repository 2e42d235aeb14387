// A per-vertex path tracer: the reference solution of the rendering equation
// (Kajiya 1986) for diffuse surfaces, against which the other filters are
// measured. At each vertex it estimates the incident irradiance
//   H(x) = ∫ L_i(x, w) cos(theta) dw,   and   B(x) = E(x) + rho(x) H(x)
// (outgoing radiance B / pi). Paths continue by cosine-weighted sampling with
// Russian roulette; at every diffuse vertex the lights are sampled too
// (next-event estimation) and combined with the BSDF-sampled hits by multiple
// importance sampling (power heuristic, Veach 1997). Lights: area emitters,
// a uniform sky, a sun disk and a point or spot light. Mirror and glass faces
// (gi/specular.h) are followed in their sampled specular direction (paths are
// traced in a loop with a throughput, never by recursion); emitters
// seen through them count fully (next-event estimation cannot sample them)
// and shadow rays stop at them. Radiance is scaled by eta^2 across glass
// (cancelling on paths that enter and leave). Random numbers are
// independent per (vertex, sample, seed), so the reported standard error is
// an honest Monte Carlo error bar and the result does not depend on threads.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/emitters.h"
#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/scene.h"
#include "gi/vertex_part.h"

namespace gi {

struct PathTraceOptions {
  int samplesPerVertex = 256;      // fixed count when targetRelativeError == 0
  double targetRelativeError = 0;  // adaptive: stop when stderr(B) / B is below this
  int minSamples = 64, maxSamples = 65536;
  int maxDepth = -1;               // bounces (0 = direct light only); -1: no fixed limit (Russian
                                   // roulette alone ends paths: unbiased; a safety cap of 100,000)
  uint32_t seed = 0;
  glm::vec3 skyRadiance{0.f};      // uniform sky over the whole sphere, W/(m^2 sr)
  glm::vec3 sunDirection = *unitDirection({0.3f, 1.f, 0.2f});  // towards the sun, unit length
  glm::vec3 sunIrradiance{0.f};    // on a surface facing the sun, W/m^2
  float sunAngularRadiusDeg = 0.27f;
  PointLight point;                // optional point or spot light (relative to the scene origin, world units)
  VertexPart vertices;             // which vertices to compute (a split run); the others are left 0
  static std::vector<ParamSpec> specs();
  static PathTraceOptions fromParams(const ParamValues& v, const glm::dvec3& sceneOrigin);
};

struct PathTraceResult {
  std::vector<glm::vec3> B;       // per vertex, W/m^2
  std::vector<glm::vec3> H;       // incident irradiance per vertex
  std::vector<float> stdError;    // standard error of luminance(B)
  std::vector<float> stdErrorH;   // standard error of luminance(H)
  std::vector<int> samples;       // per vertex
  RunStats stats;
};

PathTraceResult pathTrace(const Scene& s, const RayCaster& caster, const PathTraceOptions& opt,
                          const Progress& progress = Progress(nullptr));

}  // namespace gi
