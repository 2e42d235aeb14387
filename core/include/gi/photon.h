// Photon mapping (Jensen 1996), first stage: photons emitted from the area
// emitters in proportion to power, traced with Russian roulette through
// diffuse surfaces and stored at every diffuse hit (global map, nanoflann
// kd-tree). Per-vertex radiosity from the k nearest photons on the same side:
//   B(x) = E(x) + rho(x) * sum_p Phi_p / (pi r_k^2)
// (the irradiance density estimate with a uniform disk kernel). By default
// the direct light is computed apart by light sampling and only photons that
// bounced at least once are read (Jensen 1996's split); an optional final
// gather reads the map where cosine rays from the vertex land.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/direct.h"
#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/scene.h"

namespace gi {

struct PhotonOptions {
  int photons = 200000;       // emitted photon paths
  int kNearest = 64;          // photons per estimate
  double maxRadius = 0.0;     // 0 = unlimited; else gather radius cap
  int maxDepth = 16;          // diffuse bounces before a path stops for sure
  bool directLight = true;    // direct light by light sampling at vertices; photons for the indirect part
  int lightSamples = 256;     // shadow rays per vertex for the direct light
  bool finalGather = false;   // read the photon map where gather rays land instead of at the vertex
  int gatherRays = 64;
  uint32_t seed = 0;
  static std::vector<ParamSpec> specs();
  static PhotonOptions fromParams(const ParamValues& v);
};

struct Photon {
  glm::vec3 p;      // position (local scene coordinates)
  glm::vec3 power;  // RGB flux, W
  glm::vec3 n;      // unit normal of the surface side it arrived on
  uint16_t depth;   // diffuse bounces before it arrived (0: straight from a light)
};

// Traces the photons; deterministic for a seed, any thread count.
std::vector<Photon> tracePhotons(const Scene& s, const RayCaster& caster, const PhotonOptions& opt,
                                 const Progress& progress, RunStats& stats);

VertexRadiometry computePhotonMap(const Scene& s, const RayCaster& caster, const PhotonOptions& opt,
                                  const Progress& progress = Progress(nullptr));

}  // namespace gi
