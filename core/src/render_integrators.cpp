// The sampled eye-path integrator shared by the distributed, two-pass and
// path-traced modes: one loop (no recursion: a path in a box of mirrors may
// bounce hundreds of times). Per vertex:
//   mirror, glass   the Fresnel-weighted choice is sampled (gi/specular.h); emitters
//                   and the sun seen after it count fully (delta event);
//   glossy          next-event estimation + one lobe sample, MIS (power heuristic);
//   diffuse         emission (MIS-weighted after a non-delta event), then by mode:
//     path traced   next-event estimation + a cosine-weighted continuation;
//     distributed   next-event estimation + one cosine ray that may only reach
//                   a light directly (sky, sun, emitter: MIS): no interreflection;
//     two-pass      the same direct light plus the first pass's indirect light
//                   (or the first pass alone: Map).
// The path-traced mode's diffuse vertices beyond max_diffuse_bounces behave
// as the distributed mode's, so that 0 gives exactly the distributed image's
// expectation. max_depth bounds the events that continue a path (0: the
// direct light at the first hit only); a cosine or lobe ray that may only
// find a light directly does not count. Russian roulette (path traced only) after 3 events, with
// survival probability min(1, max channel of the throughput).
#include <algorithm>
#include <cmath>

#include "gi/color.h"
#include "gi/specular.h"
#include "render_internal.h"

namespace gi::eye {

namespace {
constexpr float kInvPi = 0.318309886f;
constexpr int kGatherMaxEvents = 16;  // specular and glossy events a gather ray may follow
bool positive(const glm::vec3& v) { return v.r > 0.f || v.g > 0.f || v.b > 0.f; }
}  // namespace

glm::vec3 Context::traceSampled(Ray ray, const SurfacePoint* first, Sampler& smp, Counts& c) const {
  const bool path = o_.mode == RenderMode::PathTraced, twoPass = o_.mode == RenderMode::TwoPass;
  // A continuation ray that can only find lights is worth casting only if it can find one.
  const bool lightRays = !lights_.empty() || hasSky_ || sunDisk_;
  glm::vec3 L(0.f), beta(1.f);
  bool delta = true, lightOnly = false;
  float pdfPrev = 0.f, nLPrev = 1.f;
  int depth = 0, diffuseVertices = 0;
  for (;;) {
    SurfacePoint sp;
    if (first) {
      sp = *first;
      first = nullptr;
    } else {
      sp = surfaceAt(ray, caster_.intersect(ray));
    }
    if (!sp.valid()) {
      L += beta * escaped(ray.d, delta, pdfPrev, nLPrev);
      break;
    }
    const Material m = s_.faceMaterial(sp.face);
    if (isSpecular(m)) {
      if (lightOnly) break;
      if (depth >= o_.maxDepth) { ++c.cutAtMaxDepth; break; }
      ++depth;
      const float ior = s_.ior.empty() ? 1.5f : s_.ior[sp.face];
      const SpecularEvent ev = scatterSpecular(m, ray.d, sp.n, s_.faceRho(sp.face), ior, smp.next1D());
      beta *= ev.weight * ev.radianceScale;
      delta = true;
      ray = spawn(sp.x, sp.n, ev.d);
      ++c.specular;
    } else {
      const float cosO = -glm::dot(sp.n, ray.d);
      if (!(cosO > 0.f)) break;  // seen from behind: black
      if (m == Material::Glossy) {
        if (lightOnly) break;
        const Bsdf b = bsdfAt(sp, -ray.d);
        L += beta * nextEvent(sp.x, sp.n, b, smp, c, 1);
        // At max_depth the lobe sample may still find a light directly (its
        // MIS share of the direct light), but goes no further.
        const bool goOn = depth < o_.maxDepth;
        if (!goOn) ++c.cutAtMaxDepth;
        glm::vec3 wi, w;
        float pdf;
        if (!b.sample(smp.next2D(), wi, w, pdf)) break;
        beta *= w;
        delta = false;
        pdfPrev = pdf;
        nLPrev = 1.f;
        ray = spawn(sp.x, sp.n, wi);
        ++c.glossy;
        if (goOn) ++depth;
        lightOnly = !goOn;
      } else {
        // Diffuse.
        const glm::vec3 rho = s_.faceRho(sp.face);
        if (emits(sp.face)) {
          const float pdfL = lights_.pdfArea(sp.face) * sp.t * sp.t / cosO;
          L += beta * s_.faceEmission(sp.face) * kInvPi * (delta ? 1.f : powerHeuristic(pdfPrev, nLPrev * pdfL));
        }
        if (lightOnly) break;
        if (twoPass && o_.twoPass == TwoPassDiffuse::Map) {
          L += beta * interpolate(tp_->R, sp) * kInvPi;
          break;
        }
        ++diffuseVertices;
        const int nL = diffuseVertices == 1 ? o_.lightSamples : 1;
        const Bsdf b = bsdfAt(sp, -ray.d);
        glm::vec3 Ld = nextEvent(sp.x, sp.n, b, smp, c, nL);
        if (twoPass) Ld = glm::max(Ld + twoPassIndirect(sp, rho, smp, c), glm::vec3(0.f));  // see render_twopass.cpp
        L += beta * Ld;
        const bool wanted = path && (o_.maxDiffuseBounces < 0 || diffuseVertices <= o_.maxDiffuseBounces);
        const bool goOn = wanted && depth < o_.maxDepth;
        if (wanted && !goOn) ++c.cutAtMaxDepth;
        if (!goOn && !lightRays) break;
        glm::vec3 wi, w;
        float pdf;
        if (!b.sample(smp.next2D(), wi, w, pdf)) break;
        beta *= w;
        delta = false;
        pdfPrev = pdf;
        nLPrev = float(nL);
        ray = spawn(sp.x, sp.n, wi);
        ++c.diffuse;
        if (goOn) ++depth;
        lightOnly = !goOn;
      }
    }
    if (!positive(beta)) break;
    if (path && depth >= 3 && !lightOnly) {  // Russian roulette
      const float q = std::min(1.f, std::max({beta.r, beta.g, beta.b}));
      if (q < 1.f) {
        if (smp.next1D() >= q) { ++c.roulette; break; }
        beta /= q;
      }
    }
  }
  return L;
}

glm::vec3 Context::twoPassIndirect(const SurfacePoint& sp, const glm::vec3& rho, Sampler& smp, Counts& c) const {
  glm::vec3 L(0.f);
  if (o_.twoPass != TwoPassDiffuse::DirectIndirect) L += rho * kInvPi * tp_->caustic(sp.x, sp.n, o_.causticK);
  if (o_.twoPass == TwoPassDiffuse::FinalGather) L += rho * kInvPi * finalGather(sp, smp, c);
  else L += interpolate(tp_->indirect, sp) * kInvPi;
  return L;
}

// Irradiance at sp from the first pass's reflected radiosity R (emission
// left out: the direct light and the caustic map carry the light that
// reaches sp from an emitter with no diffuse bounce between), by cosine-
// weighted rays that follow mirrors, glass and glossy lobes to the first
// diffuse face: H = pi mean(L) = mean(R seen), each weighted by its path.
glm::vec3 Context::finalGather(const SurfacePoint& sp, Sampler& smp, Counts& c) const {
  glm::dvec3 H(0.0);
  const Frame frame(sp.n);
  for (int g = 0; g < o_.gatherRays; ++g) {
    Ray ray = spawn(sp.x, sp.n, frame.toWorld(cosineHemisphere(smp.next2D())));
    glm::vec3 w(1.f);
    for (int k = 0; k <= kGatherMaxEvents; ++k) {
      ++c.gather;
      const SurfacePoint q = surfaceAt(ray, caster_.intersect(ray));
      if (!q.valid() || k == kGatherMaxEvents) break;
      const Material m = s_.faceMaterial(q.face);
      if (isSpecular(m)) {
        const float ior = s_.ior.empty() ? 1.5f : s_.ior[q.face];
        const SpecularEvent ev = scatterSpecular(m, ray.d, q.n, s_.faceRho(q.face), ior, smp.next1D());
        w *= ev.weight * ev.radianceScale;
        ray = spawn(q.x, q.n, ev.d);
        continue;
      }
      if (!(glm::dot(q.n, ray.d) < 0.f)) break;
      if (m == Material::Glossy) {
        glm::vec3 wi, weight;
        float pdf;
        if (!bsdfAt(q, -ray.d).sample(smp.next2D(), wi, weight, pdf)) break;
        w *= weight;
        ray = spawn(q.x, q.n, wi);
        continue;
      }
      H += glm::dvec3(w * interpolate(tp_->R, q));
      break;
    }
  }
  return glm::vec3(H / double(o_.gatherRays));
}

}  // namespace gi::eye
