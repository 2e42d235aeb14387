// Internal parts of the eye pass (gi/render.h) shared by its sources: the
// shared path integrator (path_integrator.h) with the eye pass's additions:
// Whitted's ray trees, the two-pass mode's first pass and final gather.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "gi/emitters.h"
#include "gi/glossy.h"
#include "gi/photon.h"
#include "gi/render.h"
#include "gi/sampling.h"
#include "path_integrator.h"

namespace gi {

namespace eye {

// The integrator's parts (path_integrator.h), shared with the reference.
using paths::Bsdf;
using paths::Counts;
using paths::PathState;
using paths::Sampler;
using paths::SurfacePoint;

// Caustic photons and their density estimate (render_caustics.cpp).
class CausticMap {
 public:
  CausticMap(std::vector<Photon> photons, const Scene& s);
  ~CausticMap();
  size_t size() const;
  // Irradiance at x (unit normal n) from the k nearest photons on n's side within sqrt(r2max).
  glm::vec3 irradiance(const glm::vec3& x, const glm::vec3& n, int k, float r2max) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The first pass's data for the two-pass mode (render_twopass.cpp).
struct TwoPassData {
  std::vector<glm::vec3> R;         // reflected radiosity B - E per vertex (>= 0)
  std::vector<glm::vec3> indirect;  // its indirect part (DirectIndirect, Caustics, FinalGather); noise may make it < 0
  std::vector<float> nearT;         // FinalGather: per face, the distance within which a gather hit is relit
  std::unique_ptr<CausticMap> caustics;  // null: none (no mirror or glass, or not asked for)
  float r2max = HUGE_VALF;
  glm::vec3 caustic(const glm::vec3& x, const glm::vec3& n, int k) const {
    return caustics ? caustics->irradiance(x, n, k, r2max) : glm::vec3(0.f);
  }
  TwoPassData();
  TwoPassData(const TwoPassData&) = delete;
  TwoPassData& operator=(const TwoPassData&) = delete;
  ~TwoPassData();
};
// The memory the caustic photons may take: what the image leaves of the
// run's limit (0: unknown, nothing is checked).
struct PhotonMemory {
  size_t limitBytes = 0;
  double imageBytes = 0;
};
void prepareTwoPass(TwoPassData& tp, const Scene& s, const RayCaster& caster, const RenderOptions& o,
                    const PhotonMemory& memory, const Progress& progress, RunStats& stats);

// The integrator as the eye pass drives it: its rules from the mode, the
// two-pass mode's stored light, and Whitted's ray trees beside it.
class Context : public paths::Integrator, private paths::StoredLight {
 public:
  Context(const Scene& s, const RayCaster& c, const RenderOptions& o, const TwoPassData* twoPass);

  // Radiance arriving along an eye ray; `first` (optional) is its first
  // surface point, already found: the ray's own hit (onRay: a batch of
  // primary rays), whose rays leave as any hit's (Integrator::leaveFrom),
  // or a point given apart from it (a vertex), lifted along its normal.
  glm::vec3 traceSampled(const Ray& ray, const SurfacePoint* first, Sampler& smp, Counts& c, bool onRay) const;
  glm::vec3 traceWhitted(const Ray& ray, const SurfacePoint* first, Counts& c, bool onRay) const;
  size_t areaLightCount() const { return areaLights_.size(); }

 private:
  // The two-pass mode's reflected light at a diffuse hit besides the direct light (paths::StoredLight).
  bool alone() const override;
  glm::vec3 reflected(const SurfacePoint& sp, const glm::vec3& from, const glm::vec3& rho, Sampler& smp,
                      Counts& c) const override;
  glm::vec3 interpolate(const std::vector<glm::vec3>& perVertex, const SurfacePoint& sp) const;
  // Rays of the gather at sp (and at a near hit q) leave from `from` (Integrator::leaveFrom).
  glm::vec3 finalGather(const SurfacePoint& sp, const glm::vec3& from, Sampler& smp, Counts& c) const;
  glm::vec3 gatherRay(Ray ray, int levels, Sampler& smp, Counts& c) const;  // the R one gather ray sees
  glm::vec3 nearReflected(const SurfacePoint& q, const glm::vec3& from, int levels, Sampler& smp,
                          Counts& c) const;  // a near hit's R
  // Whitted's direct light at x (unit normal n) from every light, its
  // shadow rays leaving from `from` (x off the surface on n's side).
  glm::vec3 whittedIrradiance(const glm::vec3& x, const glm::vec3& n, const glm::vec3& from, Counts& c) const;
  // Whitted: what reaches the end of a shadow ray: 0 past an opaque face,
  // through glass the tint times 1 - F at each interface crossed; a ray
  // aimed at area light `light` that meets the front of one of its faces
  // has reached it (a closed light's aim point lies inside it).
  glm::vec3 whittedTransmittance(Ray ray, Counts& c, int light = -1) const;

  struct AreaLight {
    std::vector<uint32_t> faces;
    // With one emission over the light, the sum of its faces' contour
    // integrals is the integral over its boundary (inner edges cancel)
    // whenever no face is clipped: x in front of every face and every
    // corner in front of x (Stokes). Boundary edges directed as the faces wind.
    bool uniform = true;
    glm::vec3 E{0.f};
    std::vector<glm::dvec3> corners;
    std::vector<std::pair<glm::dvec3, glm::dvec3>> boundary;
    glm::dvec3 centroid{0.0};  // area-weighted
  };

  const RenderOptions& o_;
  const TwoPassData* tp_;
  std::vector<AreaLight> areaLights_;
  std::vector<int> lightOfFace_;  // per face, its area light (-1: none)
};

}  // namespace eye
}  // namespace gi
