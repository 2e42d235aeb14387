// Internal parts of the eye pass (gi/render.h) shared by its sources: the
// per-sample random numbers, ray counters, the lights and materials of the
// scene as the integrators see them, and the integrators themselves.
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

namespace gi {

namespace eye {

// The numbers of one pixel (or vertex) sample. QMC: consecutive 2D draws
// are Owen-scrambled Sobol points of the sample index, each pair with its
// own key, hence its own index shuffle and scrambling (Burley 2020, section
// 4): pairs never advance in lock-step, which would correlate them. Random:
// independent numbers (the path-traced mode's error bars need them).
class Sampler {
 public:
  Sampler(uint32_t key, uint32_t index, bool qmc) : key_(key), index_(index), qmc_(qmc), rng_(hashCombine(key, index)) {}
  glm::vec2 next2D() {
    if (qmc_) return sobolOwen2D(index_, hashCombine(key_, dim_++));
    const float a = rng_.next();
    return {a, rng_.next()};
  }
  float next1D() { return qmc_ ? next2D().x : rng_.next(); }

 private:
  uint32_t key_, index_, dim_ = 0;
  bool qmc_;
  Rng rng_;
};

struct Counts {
  uint64_t primary = 0, shadow = 0, specular = 0, glossy = 0, diffuse = 0, gather = 0;
  uint64_t cutAtMaxDepth = 0, belowWeight = 0, roulette = 0;
  void add(const Counts& o) {
    primary += o.primary; shadow += o.shadow; specular += o.specular; glossy += o.glossy; diffuse += o.diffuse;
    gather += o.gather; cutAtMaxDepth += o.cutAtMaxDepth; belowWeight += o.belowWeight; roulette += o.roulette;
  }
  uint64_t rays() const { return primary + shadow + specular + glossy + diffuse + gather; }
};

// A point where an eye path meets a surface. n: the unit normal used for
// shading and for the side tests (the face normal, or a vertex normal for
// the per-vertex radiance); (u, v): barycentrics of the face's vertices 1, 2.
struct SurfacePoint {
  glm::vec3 x{0.f}, n{0.f, 0.f, 1.f};
  uint32_t face = kNoHit;
  float u = 0.f, v = 0.f, t = 0.f;
  bool valid() const { return face != kNoHit; }
};

// A diffuse (Lambert) or glossy (GGX) reflector at one point, seen from wo.
struct Bsdf {
  explicit Bsdf(const glm::vec3& n) : frame(n) {}
  bool glossy = false;
  glm::vec3 rho{0.f};
  GgxLobe lobe;
  Frame frame;
  glm::vec3 woLocal{0.f, 0.f, 1.f};
  glm::vec3 f(const glm::vec3& wi) const;
  float pdf(const glm::vec3& wi) const;
  // Importance-sampled direction; weight = f cos / pdf. False: no sample.
  bool sample(glm::vec2 u, glm::vec3& wi, glm::vec3& weight, float& pdf) const;
};

// Caustic photons and their density estimate (render_caustics.cpp).
class CausticMap {
 public:
  explicit CausticMap(std::vector<Photon> photons);
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
  std::vector<glm::vec3> indirect;  // its indirect part (DirectIndirect, Caustics); noise may make it < 0
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
void prepareTwoPass(TwoPassData& tp, const Scene& s, const RayCaster& caster, const RenderOptions& o,
                    const Progress& progress, RunStats& stats);

class Context {
 public:
  Context(const Scene& s, const RayCaster& c, const RenderOptions& o, const TwoPassData* twoPass);

  // Radiance arriving along an eye ray; `first` (optional) is its first
  // surface point, already found (a batch of primary rays, or a vertex).
  glm::vec3 traceSampled(Ray ray, const SurfacePoint* first, Sampler& smp, Counts& c) const;
  glm::vec3 traceWhitted(const Ray& ray, const SurfacePoint* first, Counts& c) const;

  SurfacePoint surfaceAt(const Ray& r, const Hit& h) const;
  bool emits(uint32_t face) const;
  bool anyLight() const { return !lights_.empty() || hasSky_ || hasSun_ || hasPoint_; }
  size_t areaLightCount() const { return areaLights_.size(); }
  float eps() const { return eps_; }

 private:
  // A ray leaving x (normal n) in direction d, lifted to d's side.
  Ray spawn(const glm::vec3& x, const glm::vec3& n, const glm::vec3& d) const;
  // Sky and sun disk seen along d; MIS-weighted against a sun sample unless
  // the direction came from a delta (camera, mirror, glass) event.
  glm::vec3 escaped(const glm::vec3& d, bool delta, float pdfPrev, float nLPrev) const;
  // Next-event estimation at x for BSDF b: nL samples of the area emitters
  // and of the sun disk (MIS weights for nL light samples against one BSDF
  // sample), the point light and a sharp sun once.
  glm::vec3 nextEvent(const glm::vec3& x, const glm::vec3& n, const Bsdf& b, Sampler& smp, Counts& c, int nL) const;
  Bsdf bsdfAt(const SurfacePoint& sp, const glm::vec3& wo) const;
  glm::vec3 interpolate(const std::vector<glm::vec3>& perVertex, const SurfacePoint& sp) const;
  // The two-pass mode's reflected light at a diffuse hit besides the direct light.
  glm::vec3 twoPassIndirect(const SurfacePoint& sp, const glm::vec3& rho, Sampler& smp, Counts& c) const;
  glm::vec3 finalGather(const SurfacePoint& sp, Sampler& smp, Counts& c) const;
  // Whitted: direct irradiance at x, exact area-light factors with one shadow ray each.
  glm::vec3 whittedIrradiance(const glm::vec3& x, const glm::vec3& n, Counts& c) const;

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

  const Scene& s_;
  const RayCaster& caster_;
  const RenderOptions& o_;
  const TwoPassData* tp_;
  EmitterSampler lights_;
  std::vector<AreaLight> areaLights_;
  std::vector<glm::vec3> faceN_;
  float eps_;
  bool hasSky_ = false, hasSun_ = false, sunDisk_ = false, hasPoint_ = false;
  float sunCos_ = 1.f, sunPdf_ = 0.f;
  glm::vec3 sunL_{0.f};
};

}  // namespace eye
}  // namespace gi
