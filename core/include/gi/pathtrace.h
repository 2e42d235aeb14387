// A per-vertex path tracer: the reference solution of the rendering equation
// (Kajiya 1986), against which the other filters are measured. At each
// vertex (on diffuse faces) it estimates the incident irradiance
//   H(x) = ∫ L_i(x, w) cos(theta) dw,   and   B(x) = E(x) + rho(x) H(x)
// (outgoing radiance B / pi). The estimator is the eye pass's path
// integrator (core/src/path_integrator.h), started at the vertex as on a
// white Lambertian surface (H = pi x the radiance it reflects): next-event
// estimation at every diffuse and glossy vertex combined with the BSDF-
// sampled hits by multiple importance sampling (power heuristic, Veach
// 1997), cosine-weighted continuation at diffuse faces, the GGX lobe
// (gi/glossy.h) importance-sampled at glossy ones, mirror and glass faces
// (gi/specular.h) followed in their sampled specular direction (emitters seen
// through them count fully: light sampling cannot reach them, and shadow
// rays stop at them), Russian roulette on the path throughput, paths traced
// in a loop (never recursion). Lights: area emitters, a uniform sky, a sun
// disk and a point or spot light. Radiance is scaled by eta^2 across glass
// (cancelling on paths that enter and leave). Random numbers are independent
// per (vertex, sample, seed), so the reported standard error is an honest
// Monte Carlo error bar and the result does not depend on threads; the
// variance behind it is the larger of the vertex's own and its mesh ring's
// (core/src/pathtrace.cpp: light that only rare paths find leaves a vertex's
// own sample variance near 0 where its paths missed it). Vertices
// with no diffuse face (only on mirror, glass or glossy faces) have no
// diffuse radiosity: they get 0, and the log says how many.
// On a large mesh the reference may trace a random sample of its vertices
// (tracedVertices, drawn by randomVertexSubset from its own seed): the
// others get 0 and traced = 0 (the filter's per-vertex attribute
// ReferenceTraced), never a value borrowed from a neighbour, so that an
// error measured against the reference is measured where it was traced.
// Or it traces the vertices the user selected (tracedSelected: the mesh's
// vertex selection, which the filter turns into selectedVertices).
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "gi/emitters.h"
#include "gi/light_paths.h"
#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/scene.h"
#include "gi/sky.h"
#include "gi/vertex_part.h"

namespace gi {

struct PathTraceOptions {
  int samplesPerVertex = 256;      // fixed count when targetRelativeError == 0
  double targetRelativeError = 0;  // adaptive: counts sized by a pilot (left out) for stderr(B) / B below this
  int minSamples = 64, maxSamples = 65536;
  int maxDepth = -1;               // scattering events (diffuse, glossy, mirror, glass) that continue a
                                   // path (0 = direct light only); -1: no fixed limit (Russian roulette
                                   // alone ends paths: unbiased; a safety cap of 100,000)
  uint32_t seed = 0;
  glm::vec3 skyRadiance{0.f};      // uniform sky over the whole sphere, W/(m^2 sr)
  glm::vec3 sunDirection = *unitDirection({0.3f, 1.f, 0.2f});  // towards the sun, unit length
  glm::vec3 sunIrradiance{0.f};    // on a surface facing the sun, W/m^2
  float sunAngularRadiusDeg = 0.27f;
  // The sky and the sun above as gi/sky.h's settings (fromParams reads them so).
  SkySun outside() const { return {skyRadiance, sunDirection, sunIrradiance, sunAngularRadiusDeg}; }
  PointLight point;                // optional point or spot light (relative to the scene origin, world units)
  VertexPart vertices;             // which vertices to compute (a split run); the others are left 0
  size_t tracedVertices = 0;       // > 0: only a random sample of this many vertices (the others 0)
  uint32_t tracedVertexSeed = 0;   // which sample
  bool tracedSelected = false;     // only the vertices marked 1 in selectedVertices (the others 0)
  std::shared_ptr<const std::vector<uint8_t>> selectedVertices;  // per vertex; set by the filter from the mesh
  bool lightPathSplit = false;     // also B per light-path kind (light_paths.h)
  static std::vector<ParamSpec> specs();
  static PathTraceOptions fromParams(const ParamValues& v, const glm::dvec3& sceneOrigin);
};

// The per-vertex attribute the reference filter writes from `traced` below
// (1 traced, 0 not), which the error map reads.
inline constexpr const char* kReferenceTracedAttribute = "ReferenceTraced";

struct PathTraceResult {
  std::vector<glm::vec3> B;       // per vertex, W/m^2
  std::vector<glm::vec3> H;       // incident irradiance per vertex
  std::vector<float> stdError;    // standard error of luminance(B)
  std::vector<float> stdErrorH;   // standard error of luminance(H)
  std::vector<int> samples;       // per vertex
  std::vector<uint8_t> traced;    // per vertex: 1 if it was traced (in the part and the sample, on a diffuse face)
  LightPathSplit split;           // B per light-path kind, when asked for
  RunStats stats;
};

PathTraceResult pathTrace(const Scene& s, const RayCaster& caster, const PathTraceOptions& opt,
                          const Progress& progress = Progress(nullptr));

}  // namespace gi
