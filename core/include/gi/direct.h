// Direct illumination from area emitters at every vertex — the zero-bounce
// radiosity solution B = E + rho H_direct, with
//   H_direct(x) = ∫_A E_e/pi cos(theta_x) cos(theta_e) / r^2 V(x, y) dA_y
// estimated by sampling emitter points in proportion to power, with shadow rays.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "gi/light_paths.h"
#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/ao_shared.h"
#include "gi/scene.h"
#include "gi/vertex_part.h"

namespace gi {

struct SkyOpenings;  // gi/sky.h

struct DirectOptions {
  int lightSamples = 64;  // shadow rays per vertex
  uint32_t seed = 0;
};

struct VertexRadiometry {
  std::vector<glm::vec3> B;        // radiosity per vertex (W/m^2, RGB)
  std::vector<glm::vec3> Bdirect;  // its direct part E + rho H_direct, where computed apart (else empty)
  std::vector<glm::vec3> H;        // incident irradiance per vertex
  std::vector<float> stdError;     // standard error of luminance(B)
  LightPathSplit split;            // B per light-path kind, when asked for (photon mapping)
  RunStats stats;
};

// Per-vertex reflectance, emission and normal from the incident diffuse faces
// (area-weighted); a vertex with none (isolated, or on mirror/glass only) is not valid.
struct VertexMaterial {
  std::vector<glm::vec3> rho, E, n;
  std::vector<uint8_t> valid;    // on a usable diffuse face, with a normal
  std::vector<uint8_t> diffuse;  // on a usable diffuse face (valid, or without a normal: a two-sided surface)
};
VertexMaterial vertexMaterial(const Scene& s);

// The two sides of the vertices on a two-sided surface (each face with a
// reversed copy: their normals cancel, so the vertex has none): the faces
// that turn the way of the first incident diffuse face (by index) form side
// A, the others side B; each side's normal is its faces' area-weighted
// normal sum, normalised, and its reflectance and emission their area-
// weighted means. A vertex whose two sums do not both give a normal, or do
// not cancel (not two-sided), is left out. slot[v] is the vertex's index in
// the lists, or -1.
struct VertexSides {
  std::vector<int32_t> slot;
  std::vector<uint32_t> vertex;
  std::vector<glm::vec3> n[2], rho[2], E[2];
  std::vector<glm::dvec3> ref;  // the first face's unit normal: a face turned its way (dot > 0) is on side A
};
// The candidates' sides over the faces `faces` marks (usable ones only).
VertexSides vertexSides(const Scene& s, const std::vector<uint8_t>& candidate, const std::vector<uint8_t>& faces);
// Over the diffuse faces, for the vertices on one without a normal.
VertexSides twoSidedVertices(const Scene& s, const VertexMaterial& m);
// The scene with each of those vertices split in two: the vertex keeps the
// usable faces that turn its side A's way (n[0]), and a copy at the same
// place, appended (index vertexCount() + slot), takes the others; given
// vertex normals become the sides'. Each side then is an ordinary vertex
// with a normal, for an estimator that has no two-sided case of its own
// (the faces, and so any ray caster built on the scene, are unchanged).
Scene splitSides(const Scene& s, const VertexSides& sides);
// Results per vertex of splitSides's scene back to the scene's vertices: a
// two-sided vertex takes the mean of its sides (the copies are removed).
void mergeSides(std::vector<glm::vec3>& value, const VertexSides& sides);
// Standard errors: of the mean of the two sides' independent estimates.
void mergeSideErrors(std::vector<float>& error, const VertexSides& sides);

// Direct irradiance per face from the emitters: with up to
// Luminaires::kMaxLuminaires luminaires (gi/luminaires.h), per luminaire L,
//   H_i = E_L Fbar_iL V_iL,  V_iL = sum_k F_L(x_k) V_L(x_k) / sum_k F_L(x_k),
// Fbar_iL the exact unoccluded factor averaged over the patch
// (meanOverTriangle, gi/form_factor_analytic.h) and V_iL the visibility
// found at up to P = max(1, lightSamples / 64) points x_k of the patch
// (fewer where the patch is small against its distance to the luminaires,
// unless its first points disagree: a shadow edge across it),
// each with up to lightSamples / P shadow rays per luminaire in penumbra
// (16 and the corners elsewhere): the ratio estimator of Heitz, Hill and
// McGuire 2018, "Combining Analytic Direct Illumination and Stochastic
// Shadows", exact wherever the points agree; with more, lightSamples
// power-proportional light samples with MIS. *stats (if given) gets the
// luminaires found, the method and the shadow rays. With `portals`
// (findSkyOpenings), the light of the sky through its portals instead, the
// portals taken as luminaires (what patchSkySunIrradiance adds).
std::vector<glm::vec3> patchDirectIrradiance(const Scene& s, const RayCaster& caster, int lightSamples, uint32_t seed,
                                             const Progress& progress = Progress(nullptr), RunStats* stats = nullptr,
                                             const SkyOpenings* portals = nullptr);

// The mean direct irradiance from the emitters over given points of each face
// (points[f] on face f, not lifted; faces without points get 0): the seen
// part of a partly buried patch (PatchSeen::seenPoints), whose light is the
// mean over its own points, so no larger than at its brightest point. Every
// point of a face (PatchSeen keeps up to 64), each with the shadow rays a
// point of patchDirectIrradiance gets: with the first 16 alone, the floor
// patches partly inside a box standing through the floor, under a lamp,
// read 24% low to 13% high against a fine mesh's mean over their seen
// parts; with every point, 10% low to 2% high (the light changes fast
// beside the box). With `portals`, the light of the sky through them
// instead (as patchDirectIrradiance).
std::vector<glm::vec3> seenPartDirectIrradiance(const Scene& s, const RayCaster& caster, int lightSamples, uint32_t seed,
                                                const std::vector<std::vector<glm::vec3>>& points,
                                                const SkyOpenings* portals = nullptr);

// The same at every vertex (used for the per-vertex output), or at the
// vertices of one part (the others 0); with luminaires, one point with up
// to lightSamples shadow rays per luminaire in penumbra.
// `stdError` (if given): each vertex's standard error of the luminance of
// rho H (its reflected direct light, the luminance of B less E) where the light is sampled (more luminaires than Luminaires::
// kMaxLuminaires: power sampling with MIS, the sample variance of its
// light_samples estimates); 0 with luminaires (exact form factors, shadow
// rays in penumbra only).
std::vector<glm::vec3> vertexDirectIrradiance(const Scene& s, const RayCaster& caster, int lightSamples, uint32_t seed,
                                              const Progress& progress = Progress(nullptr),
                                              const VertexPart& part = VertexPart(),
                                              const SkyOpenings* portals = nullptr,
                                              std::vector<float>* stdError = nullptr);

// One gather ray's hit on a face's front: the face, the point and its
// distance, which vertex cast it as its how-manyth ray (so that what the
// hit samples in turn can be stratified with the vertex's other rays), and
// the ray (origin, unit direction) and the hit's barycentrics (where rays
// leaving the hit start: hit_origin.h).
struct GatherHit {
  uint32_t face;
  glm::vec3 point;
  float t;
  uint32_t vertex, ray;
  glm::vec3 origin, dir;
  float u, v;
};

// Final gather at every vertex: the mean over `rays` cosine-weighted rays of
// value(hit), for hits on a face's front (0 otherwise) — an irradiance
// estimate when value is the radiosity leaving the hit point. Only the
// vertices of `part` (the others 0). `lum` (if given) receives each
// vertex's rays for pooling (poolMeans): their count, the sum of their
// values' luminance and its sample variance per ray.
std::vector<glm::vec3> finalGather(const Scene& s, const RayCaster& caster, const VertexMaterial& mat, int rays,
                                   uint32_t key, const std::function<glm::vec3(const GatherHit&)>& value,
                                   const VertexPart& part = VertexPart(), const Progress& progress = Progress(nullptr),
                                   std::vector<VertexRays>* lum = nullptr);

namespace detail {
class DirectLight;
}
// The direct light at any point by `samples` power-proportional light
// samples combined with cosine-weighted directions by MIS (one shadow ray
// each: cheap where many points each need a rough value), random numbers
// keyed by `key`.
class DirectLightAt {
 public:
  DirectLightAt(const Scene& s, const RayCaster& caster, int samples);
  ~DirectLightAt();
  // x on a face, n its unit normal (the lit side); the ray origin is lifted by the scene's offset.
  glm::vec3 operator()(const glm::vec3& x, const glm::vec3& n, uint32_t key) const;
  // The same with the shadow rays leaving from `from` (a hit's origin on
  // the free segment its ray came along: hit_origin.h).
  glm::vec3 operator()(const glm::vec3& x, const glm::vec3& from, const glm::vec3& n, uint32_t key) const;

 private:
  std::unique_ptr<detail::DirectLight> impl_;
  int samples_ = 1;
};

VertexRadiometry computeDirect(const Scene& s, const RayCaster& caster, const DirectOptions& opt,
                               const Progress& progress = Progress(nullptr));

}  // namespace gi
