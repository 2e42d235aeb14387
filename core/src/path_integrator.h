// The path integrator shared by the eye pass (gi/render.h: the distributed,
// two-pass and path-traced modes) and the per-vertex path-traced reference
// (gi/pathtrace.h): one estimator of the rendering equation (Kajiya 1986)
//   L(x, wo) = Le(x, wo) + ∫ f(x, wi, wo) L(x', -wi) cos(theta_i) dwi
// along a path traced in a loop (never recursion). Per vertex:
//   mirror, glass  the Fresnel-weighted choice is sampled (gi/specular.h),
//                  radiance scaled by eta^2 across glass; emitters and the sun
//                  seen after it count fully (a delta event light sampling
//                  cannot reach);
//   glossy         next-event estimation + one sample of the GGX lobe
//                  (gi/glossy.h), combined by multiple importance sampling;
//   diffuse        its emission (MIS-weighted after a non-delta event), next-
//                  event estimation, then a cosine-weighted continuation.
// Next-event estimation: nL samples of the area emitters (in proportion to
// power) and of the sun disk, weighted by the power heuristic (Veach 1997)
// against the one BSDF sample that may hit them too (pdf of an emitter point
// in solid angle: pdfArea t^2 / cos); the point or spot light and a sharp sun
// by one shadow ray each. Rays that leave the scene see the sky and the sun
// disk (MIS-weighted likewise). Russian roulette after 3 events, survival
// min(1, the largest channel of the path throughput).
// Depth: max_depth bounds the scattering events (diffuse, glossy, mirror,
// glass) that continue a path; a diffuse or glossy vertex at the limit still
// casts its BSDF ray, which may only find a light directly (its MIS share of
// the direct light), so 0 gives exactly the direct light at the first vertex.
#pragma once
#include <cstdint>
#include <string>

#include <glm/glm.hpp>

#include "gi/emitters.h"
#include "gi/glossy.h"
#include "gi/light_paths.h"
#include "gi/sky.h"
#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/sampling.h"
#include "gi/scene.h"

namespace gi::paths {

// The numbers of one pixel (or vertex) sample. QMC: consecutive 2D draws
// are Owen-scrambled Sobol points of the sample index, each pair with its
// own key, hence its own index shuffle and scrambling (Burley 2020, section
// 4): pairs never advance in lock-step, which would correlate them. Random:
// independent numbers (error bars from the sample variance need them).
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

// Rays by kind and how paths ended, summed over threads.
struct Counts {
  uint64_t primary = 0, shadow = 0, specular = 0, glossy = 0, diffuse = 0, gather = 0;
  uint64_t cutAtMaxDepth = 0, belowWeight = 0, roulette = 0;
  uint64_t gatherNear = 0;  // the two-pass view's gather hits relit at the point (render_integrators.cpp)
  void add(const Counts& o) {
    primary += o.primary; shadow += o.shadow; specular += o.specular; glossy += o.glossy; diffuse += o.diffuse;
    gather += o.gather; cutAtMaxDepth += o.cutAtMaxDepth; belowWeight += o.belowWeight; roulette += o.roulette;
    gatherNear += o.gatherNear;
  }
  uint64_t rays() const { return primary + shadow + specular + glossy + diffuse + gather; }
};

// A point where a path meets a surface. n: the unit normal used for shading
// and for the side tests (the face normal, or a vertex normal); (u, v):
// barycentrics of the face's vertices 1, 2; t: the distance along the ray.
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
  // Whether any light can leave it (a black diffuse face ends a path).
  bool reflects() const { return glossy || rho.r > 0.f || rho.g > 0.f || rho.b > 0.f; }
};

// Lights besides the emitting faces, in the scene's local units.
struct LightSettings {
  glm::vec3 skyRadiance{0.f};  // uniform over the sphere, W/(m^2 sr)
  glm::vec3 sunDirection{0.3f, 1.f, 0.2f};
  glm::vec3 sunIrradiance{0.f};  // on a surface facing the sun, W/m^2
  float sunAngularRadiusDeg = 0.27f;
  PointLight point;
};

// Light paths these integrators cannot find, in one sentence, or "": a
// point light's light reaching a diffuse surface by way of a mirror or glass
// (L S+ D: a path from the surface meets the mirror in one direction and must
// then hit a point exactly, which no sampled direction does; pbrt and every
// unidirectional path tracer miss it too). Photon mapping finds it.
// `sunMet`: whether paths continue off mirrors and glass and can meet the
// sun's disk (the reference and the path-traced view; the distributed view's
// shadow rays stop at them and it never finds the sun through them).
// `paths`: the paths a vertex or pixel traces (0: not known), below which a
// wide sun is still missed.
std::string unsampledLightPaths(const Scene& s, const LightSettings& lights, bool sunMet = true, double paths = 0.0);

// Warns (st) where paths cut at the depth limit (maxDepth, -1 = none but
// `cap`) may miss more light than the mean relative error: `cut` of `paths`;
// `remedy` ends the warning.
void depthWarnings(const Scene& s, int maxDepth, int cap, double paths, double cut, double relErr,
                   const char* remedy, RunStats& st);

struct PathRules {
  int maxDepth = 32;            // events that continue a path (see the top of this file)
  int maxDiffuseBounces = -1;   // diffuse vertices that continue (-1: any); beyond: direct light only
  int firstLightSamples = 1;    // nL at the first diffuse vertex of a path (deeper: 1)
  bool interreflection = true;  // false: diffuse vertices never continue (direct light only)
  bool roulette = true;         // Russian roulette after 3 events
};

// What a diffuse vertex receives besides its ray-traced direct light, when
// the light comes from elsewhere (the two-pass mode's first pass).
class StoredLight {
 public:
  virtual ~StoredLight() = default;
  // True: the vertex's reflected light is `reflected` alone (no light
  // sampling); false: next-event estimation + `reflected`, clamped at 0.
  virtual bool alone() const = 0;
  // Radiance reflected at sp (reflectance rho) towards the path; rays it
  // casts leave from `from` (sp off its face: Integrator::leaveFrom).
  virtual glm::vec3 reflected(const SurfacePoint& sp, const glm::vec3& from, const glm::vec3& rho, Sampler& smp,
                              Counts& c) const = 0;
};

// Where a path stands between vertices: its next ray and throughput beta
// (what a radiance arriving along the ray adds to the estimate); delta: the
// ray came from a mirror, glass or the camera (emitters count fully);
// pdfPrev, nLPrev: the BSDF sample's density and the light samples taken at
// its vertex, for the MIS weights of what the ray finds; lightOnly: the ray
// may only find a light directly (its vertex was the last); firstOnRay:
// the first point trace is given is the ray's own hit (a camera's primary
// ray), so its rays leave as any hit's (leaveFrom), not lifted along the
// normal as a point given apart from the ray (a vertex).
struct PathState {
  enum class Kind : uint8_t { Primary, Specular, Glossy, Diffuse };
  Ray ray;
  Kind kind = Kind::Primary;  // what spawned the ray (counted when cast; primary rays by the caller)
  glm::vec3 beta{1.f};
  bool delta = true, lightOnly = false, firstOnRay = false;
  float pdfPrev = 0.f, nLPrev = 1.f;
  int depth = 0, diffuseVertices = 0;
};

class Integrator {
 public:
  Integrator(const Scene& s, const RayCaster& c, const LightSettings& lights, const PathRules& rules,
             const StoredLight* stored = nullptr);

  // Radiance arriving along st.ray; `first` (optional) is its first surface
  // point, already found (a batch of primary rays, or a vertex).
  // parts (kPathKinds entries of gi/light_paths.h, or null; the renderer
  // passes null and pays one branch per term): the same terms added by the
  // light path's kind as seen from the path's start vertex x0 (a path
  // started by traceFromSurface, st.diffuseVertices = 1). In Heckbert's
  // notation (Heckbert 1990), glossy vertices count as S, as the photon
  // tracer tags them: a light found by x0's own light sample or BSDF ray is
  // direct (L D), one found through mirror, glass and glossy events only
  // (including a glossy vertex's light sample) caustic (L S+ D), and every
  // light found at or after another diffuse vertex indirect.
  glm::vec3 trace(PathState st, const SurfacePoint* first, Sampler& smp, Counts& c,
                  glm::vec3* parts = nullptr) const;
  // Radiance a white Lambertian surface at x (unit normal n) reflects, i.e.
  // its incident irradiance / pi, by next-event estimation at x and a path
  // continued from there. Rays leave from `from`, x already lifted off the
  // surface (a vertex's ray origin); the lights' distances and cosines are
  // x's own (taken at the lifted point they read eps / h low for a light at
  // height h; an outside audit).
  // parts: as for trace (x is the start vertex x0).
  glm::vec3 traceFromSurface(const glm::vec3& x, const glm::vec3& from, const glm::vec3& n, Sampler& smp, Counts& c,
                             glm::vec3* parts = nullptr) const;

  SurfacePoint surfaceAt(const Ray& r, const Hit& h) const;
  bool emits(uint32_t face) const;
  bool anyLight() const { return !emitters_.empty() || hasSky_ || hasSun_ || hasPoint_; }
  float eps() const { return eps_; }
  const std::vector<glm::vec3>& faceNormals() const { return faceN_; }

  // Where rays leaving a surface point reached by `in` start on the side it
  // was reached from: hitRayOrigin (hit_origin.h), the normal lift unless
  // that crosses a surface near a corner; the lift itself where the hit
  // was projected onto its face (a far camera: no short segment there).
  glm::vec3 leaveFrom(const Ray& in, const SurfacePoint& sp) const;
  // A ray leaving x (normal n) in direction d, lifted by `lift` to d's side.
  Ray spawn(const glm::vec3& x, const glm::vec3& n, const glm::vec3& d, float lift) const;
  Ray spawn(const glm::vec3& x, const glm::vec3& n, const glm::vec3& d) const { return spawn(x, n, d, eps_); }
  // A shadow ray from x (lifted by `lift` to d's side) to the light point y,
  // aimed from the lifted origin: aimed from x, a ray lifted off a surface
  // that sees the light at a grazing angle meets the light's own plane
  // before y (by up to lift / cos at the light). It stops `stop` before y
  // (and 1e-4 of the way); tfar <= 0 means y is nearer than that.
  Ray shadowRay(const glm::vec3& x, const glm::vec3& n, const glm::vec3& d, const glm::vec3& y, float lift,
                float stop) const;
  Bsdf bsdfAt(const SurfacePoint& sp, const glm::vec3& wo) const;
  // Sky and sun disk seen along d; MIS-weighted against a sun sample unless
  // the direction came from a delta event.
  glm::vec3 escaped(const glm::vec3& d, bool delta, float pdfPrev, float nLPrev) const;
  // Emission E / pi of the front of an emitting face seen at distance t
  // under cosine cosO, MIS-weighted against light sampling after a BSDF sample.
  glm::vec3 emitted(uint32_t face, float t, float cosO, bool delta, float pdfPrev, float nLPrev) const;
  // Next-event estimation at x for BSDF b (see the top of this file); shadow
  // rays lifted by `lift`, or leaving from `from` where given (x lifted
  // already).
  glm::vec3 nextEvent(const glm::vec3& x, const glm::vec3& n, const Bsdf& b, Sampler& smp, Counts& c, int nL,
                      float lift, const glm::vec3* from = nullptr) const;
  glm::vec3 nextEvent(const glm::vec3& x, const glm::vec3& n, const Bsdf& b, Sampler& smp, Counts& c, int nL) const {
    return nextEvent(x, n, b, smp, c, nL, eps_);
  }
  // A mirror or glass event at sp: the sampled direction, beta times its
  // weight and eta^2, the ray continued.
  void specularStep(const SurfacePoint& sp, PathState& st, Sampler& smp, bool given) const;

 protected:
  const Scene& s_;
  const RayCaster& caster_;
  LightSettings L_;
  PathRules rules_;
  const StoredLight* stored_;
  EmitterSampler emitters_;
  std::vector<glm::vec3> faceN_;
  std::vector<glm::vec3> faceAlt_;  // faceAltitudes (hit_origin.h)
  float eps_;
  // Hits farther than this (twice the diagonal: only rays from outside the
  // scene, a camera's) are put back onto their face's plane (surfaceAt).
  float farT_;
  bool hasSky_ = false, hasSun_ = false, sunDisk_ = false, hasPoint_ = false;
  // The sun's disk and the spot's cone, tested and sampled in double
  // (exact where cos a is 1 in float).
  Cone sunCone_, spot_;
  float sunPdf_ = 0.f;
  glm::vec3 sunL_{0.f};
};

}  // namespace gi::paths
