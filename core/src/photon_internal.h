// Internal parts of photon mapping shared by its sources.
#pragma once
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "gi/direct.h"
#include "gi/photon.h"
#include "gi/sky.h"

namespace gi {

// A photon counts in a gather when the normal of the face it landed on is
// within 60 degrees of the gather point's normal (same side, same surface).
constexpr float kSameSide = 0.5f;

inline glm::i8vec3 packNormal(const glm::vec3& n) {
  return glm::i8vec3(int8_t(std::lround(n.x * 127.f)), int8_t(std::lround(n.y * 127.f)), int8_t(std::lround(n.z * 127.f)));
}
inline glm::vec3 unpackNormal(const glm::i8vec3& n) { return glm::vec3(n) * (1.f / 127.f); }

// What the estimators need to know of a run.
struct PhotonRun {
  const Scene& s;
  const RayCaster& caster;
  const PhotonOptions& opt;  // in local units
  const VertexMaterial& mat;
  const std::vector<glm::vec3>& origins;  // ray origins lifted off the vertices
  float eps;
  bool specular;          // the scene has mirror or glass faces
  bool projection;        // caustic photons aimed at them
  unsigned vertexPaths;   // the photon paths the vertex estimates read
  float r2max;            // squared gather radius cap
  const SkyOpenings& openings;  // the sky's openings (gi/sky.h; none without a sky)
};

// What a run's density estimates looked like, for the warnings below.
struct PhotonGatherCheck {
  double surfaceArea = 0;        // diffuse area photons land on
  size_t mapPhotons = 0;         // photons the vertex (or final-gather) estimates read; progressive: all passes
  size_t causticPhotons = 0;     // in the caustic map read with caustic_k (0: none)
  size_t estimates = 0;          // estimates that held at least one photon
  size_t fewEstimates = 0;       // of those, the ones with fewer than kFewPhotons
  bool kNearestEstimates = false;  // k-nearest estimates (not progressive)
  bool reflects = false;         // some diffuse face reflects light (so some belongs in the map)
  double lostPowerFraction = 0;  // of the emitted power, still carried by paths cut at max_depth
  double lostChannelShare = 0;   // the same in the channel that loses the largest share of its power
  int lostChannel = 0;           // which (0 red, 1 green, 2 blue)
};
// A handful: below it an estimate's relative noise exceeds 1 / sqrt(4) = 50%.
constexpr int kFewPhotons = 4;

// Warnings (RunStats::warn) for parameters that make the result meaningless:
// a gather radius cap below the photon spacing, estimates of a handful of
// photons, k below 3 (no finite mean or variance), k above the map's
// photons, and paths cut at max_depth carrying much of the power.
// unit: Scene::unit, for lengths said in the mesh's own units.
void warnMeaninglessPhotonParameters(const PhotonOptions& opt, const PhotonGatherCheck& c, double unit, RunStats& st);

// A final-gather ray's diffuse hit: the face, the point, its unit normal,
// the length of the ray's last leg, a key of its own (vertex, ray), that
// leg's origin and direction and a lower bound of the point's distance to
// its triangle's border (hitBorder), from which hitRayOrigin (hit_origin.h)
// finds where rays leaving the point start, where they are cast (near a
// corner it casts a ray itself).
struct PhotonGatherHit {
  uint32_t face;
  glm::vec3 point, normal;
  float t;
  uint32_t key;
  glm::vec3 legOrigin, legDir;
  float border;
};
// Final gather at every vertex through mirrors, glass and glossy faces:
// cosine-weighted rays from origins[v] follow them (up to 16 interactions;
// a glossy lobe by one sample of it) and, at the
// first diffuse face, add value(hit) if the ray hit its front (0 otherwise).
// `only` (one flag per vertex, or null for all): the vertices to gather at; the others get 0.
// *variance (if given): per vertex, the variance of the mean of the luminance
// of rho (the vertex's reflectance) times the rays' values, B's reflected light
// (their sample variance over the ray count; an upper bound for
// the stratified rays), 0 where nothing was gathered.
std::vector<glm::vec3> specularFinalGather(const Scene& s, const RayCaster& caster, const VertexMaterial& mat,
                                           const std::vector<glm::vec3>& origins, int rays, uint32_t key, float eps,
                                           const std::function<glm::vec3(const PhotonGatherHit&)>& value,
                                           const std::vector<uint8_t>* only = nullptr,
                                           const Progress& progress = Progress(nullptr),
                                           std::vector<double>* variance = nullptr);

// The photons' irradiance at the vertices.
struct PhotonEstimate {
  std::vector<glm::vec3> H;
  std::vector<double> noise;  // Poisson standard error of the luminance of rho H (B's reflected light)
  size_t verticesWithoutPhotons = 0;
  PhotonGatherCheck check;
  std::vector<glm::vec3> byPath[kPathKinds];  // H's terms by the photons' path kind (light_path_split, k nearest)
};

class PhotonMap;
class GatherSurface;
// The kd-trees of a k-nearest run over the traced photons (which must
// outlive them): the global map read at the vertices, or, with a final
// gather, `all` read where its rays land; and the caustic map.
struct PhotonMaps {
  std::unique_ptr<PhotonMap> global, caustics, all;
  unsigned globalPaths = 7u;
  size_t bytes = 0;  // the photons and the trees
  // The photons `all` reads when it is a thinned copy (the hand-over's map
  // of a run of more than kPpmGatherPaths paths), with their hits left.
  std::vector<Photon> thinned;
  std::vector<uint8_t> thinnedLeft;
  size_t thinnedStride = 1;
};

// Where the k-nearest mode gathered instead, and why.
struct HandOver {
  std::vector<uint8_t> at;  // per vertex
  size_t crease = 0, otherSurface = 0, nearHits = 0;
  double buildSeconds = 0, gatherSeconds = 0;
};

// Whether vertex i takes a final gather instead of its density estimate
// (of the given radius): at a crease (`crease`, from creaseVertices, or
// empty for none; *atCrease says so), or where another surface rises inside
// the radius (GatherSurface::otherSurfaceWithin).
bool handsOver(const PhotonRun& r, const GatherSurface& surface, const std::vector<uint8_t>& crease, size_t i,
               float radius, bool& atCrease);

// Density estimates at the vertices: the global map there with k_nearest
// photons (or the final gather reading `all` everywhere), plus the caustic
// map with caustic_k. With the direct light apart, the k-nearest mode hands
// a vertex over to the final gather where the density estimate tells
// another quantity than the vertex's value (photon_gather.cpp); `all` is
// built for them if needed.
PhotonEstimate estimateAtVertices(const PhotonRun& r, PhotonMaps& m, const std::vector<Photon>& photons,
                                  const GatherSurface& surface, const std::vector<uint8_t>& hitsLeft,
                                  const std::vector<uint8_t>& crease, HandOver& ho, const Progress& progress);
// `all`: the photons a final gather reads (without each path's last allowed hit).
std::unique_ptr<PhotonMap> gatherMap(const std::vector<Photon>& photons, const GatherSurface& surface,
                                     const std::vector<uint8_t>& hitsLeft);

// The final gather of `all` (the photons without each path's last allowed
// hit) at the vertices `only` marks (null: all), its near hits relit
// (photon_gather.cpp); count(photons) for each estimate read, *nearHits
// the hits relit.
std::vector<glm::vec3> gatherPhotonMap(const PhotonRun& r, const PhotonMap& all, const std::vector<uint8_t>* only,
                                       const std::function<void(int)>& count, size_t* nearHits,
                                       const Progress& progress, std::vector<double>* variance = nullptr);

// Progressive photon mapping (Hachisuka, Ogaki and Jensen 2008) with the
// vertices as the measurement points: per vertex a radius R, an accumulated
// photon count N and flux tau. After each pass of M new photons within R,
//   N' = N + alpha M,   R'^2 = R^2 (N + alpha M) / (N + M),   tau' = (tau + Phi_M) A(R') / A(R),
// and H = tau / (A(R) passes) (each pass's photons carry the full power / count),
// with A(R) the area of the counted surface within R (photon_surface.h): pi R^2
// on a plane, where the flux ratio is Hachisuka's R'^2 / R^2.
// The first radius is the distance to the k-th nearest photon of the first pass.
// With `projection`, each pass's caustic photons come from traceCausticPhotons
// (those of the global pass are dropped). With the direct light apart, the
// vertices where a density estimate tells another quantity than the
// vertex's value (a crease, another surface inside the first radius: as in
// the k-nearest mode, photon_gather.cpp) keep only their caustic photons
// and take a final gather of the first passes' photons for the rest: as
// many passes as kPpmGatherPaths paths need, or a share of the first pass's
// photons where it has more paths (the default photons of the
// k-nearest mode; on the Cornell box 1 to 10 passes of 200,000 gave the
// same errors, the gather's own noise dominating, at 0.3 to 2.3 s more).
struct ProgressiveResult {
  std::vector<glm::vec3> H;
  std::vector<double> noise;  // Poisson error estimate per vertex, of the luminance of rho H
  size_t verticesWithoutPhotons = 0;
  double meanRadius = 0, meanCount = 0;
  double traceSeconds = 0, buildSeconds = 0, querySeconds = 0;
  double peakBytes = 0;
  PhotonGatherCheck check;  // surface, photons over all passes, vertices with few photons
  std::vector<glm::vec3> byPath[3];  // H's terms by the photons' path kind (opt.lightPathSplit)
  HandOver ho;                       // the vertices that gathered, and why
  int gatherPasses = 0;              // passes whose photons the gather read
  size_t gatherStride = 1;           // every gatherStride-th of them (a pass of more than kPpmGatherPaths paths)
};
constexpr size_t kPpmGatherPaths = 200000;
// The stride that thins the photons of `paths` paths to a map of about
// kPpmGatherPaths paths' worth (1: keep them all).
inline size_t gatherMapStride(size_t paths) { return (paths + kPpmGatherPaths - 1) / kPpmGatherPaths; }
// Appends every stride-th photon (with its path's hits left) at `scale`
// times its power: each kept with probability 1 / stride, the same density
// when scale is the stride.
void appendEveryNth(const std::vector<Photon>& photons, const std::vector<uint8_t>& left, size_t stride, float scale,
                    std::vector<Photon>& out, std::vector<uint8_t>& outLeft);
ProgressiveResult progressivePhotonMap(const PhotonRun& r, const Progress& progress, PhotonTraceStats& stats);

// A vertex at a crease: one of its diffuse faces turns more than
// kCreaseDegrees from its (averaged) normal. There the k-nearest density
// estimate reads the photons of the faces on both sides, the mean of their
// irradiances near the crease, not the irradiance of the vertex's own tilted
// plane that the vertex value is (the reference, radiosity and the final
// gather see the hemisphere of the vertex normal): the k-nearest mode
// gathers there instead.
constexpr double kCreaseDegrees = 20.0;
std::vector<uint8_t> creaseVertices(const Scene& s, const VertexMaterial& mat);

}  // namespace gi
