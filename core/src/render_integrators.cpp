// The eye pass's sampled modes on the shared integrator (path_integrator.h):
//   distributed   every diffuse vertex ends the path with its direct light
//                 (next-event estimation + one cosine ray that may only reach a
//                 light directly: sky, sun, emitter, MIS); no interreflection;
//   two-pass      the same direct light plus the first pass's indirect light
//                 (or the first pass alone: Map), read here;
//   path traced   every vertex continues (Russian roulette after 3 events);
//                 diffuse vertices beyond max_diffuse_bounces behave as the
//                 distributed mode's, so that 0 gives exactly the distributed
//                 image's expectation.
// Mirrors, glass and glossy surfaces are followed in every mode.
#include <algorithm>
#include <cmath>

#include "gi/color.h"
#include "gi/specular.h"
#include "hit_origin.h"
#include "render_internal.h"

namespace gi::eye {

namespace {
constexpr float kInvPi = 0.318309886f;
constexpr float kPi = 3.14159265f;
constexpr int kGatherMaxEvents = 16;  // specular and glossy events a gather ray may follow
constexpr int kNearLevels = 2;        // near gather hits relit by one more ray, levels deep
}  // namespace

glm::vec3 Context::traceSampled(const Ray& ray, const SurfacePoint* first, Sampler& smp, Counts& c, bool onRay) const {
  PathState st;
  st.ray = ray;
  st.firstOnRay = onRay;
  return trace(st, first, smp, c);
}

bool Context::alone() const { return o_.twoPass == TwoPassDiffuse::Map; }

glm::vec3 Context::reflected(const SurfacePoint& sp, const glm::vec3& from, const glm::vec3& rho, Sampler& smp,
                             Counts& c) const {
  if (o_.twoPass == TwoPassDiffuse::Map) return interpolate(tp_->R, sp) * kInvPi;
  glm::vec3 L(0.f);
  if (o_.twoPass != TwoPassDiffuse::DirectIndirect) L += rho * kInvPi * tp_->caustic(sp.x, sp.n, o_.causticK);
  if (o_.twoPass == TwoPassDiffuse::FinalGather) L += rho * kInvPi * finalGather(sp, from, smp, c);
  else L += interpolate(tp_->indirect, sp) * kInvPi;
  return L;
}

glm::vec3 Context::interpolate(const std::vector<glm::vec3>& perVertex, const SurfacePoint& sp) const {
  const auto& t = s_.triangles[sp.face];
  return (1.f - sp.u - sp.v) * perVertex[t.x] + sp.u * perVertex[t.y] + sp.v * perVertex[t.z];
}

// Irradiance at sp from the first pass's reflected radiosity R (emission
// left out: the direct light and the caustic map carry the light that
// reaches sp from an emitter with no diffuse bounce between), by cosine-
// weighted rays that follow mirrors, glass and glossy lobes to the first
// diffuse face: H = pi mean(L) = mean(R seen), each weighted by its path.
glm::vec3 Context::finalGather(const SurfacePoint& sp, const glm::vec3& from, Sampler& smp, Counts& c) const {
  glm::dvec3 H(0.0);
  const Frame frame(sp.n);
  for (int g = 0; g < o_.gatherRays; ++g)
    H += glm::dvec3(gatherRay(spawn(from, sp.n, frame.toWorld(cosineHemisphere(smp.next2D())), 0.f), kNearLevels, smp, c));
  return glm::vec3(H / double(o_.gatherRays));
}

// The reflected radiosity one gather ray sees, weighted by its path. A
// diffuse hit within two patch edges of the ray's origin (nearT, as
// radiosity's own gather reads its near hits) sees the first pass up close,
// where its per-vertex values interpolated over a coarse patch hide how
// the light varies across it: the floor's vertices beside a block standing
// on it read the light beyond the block's shadow (the block's front face by
// the floor came out 18% bright in the shipped Cornell box; an outside
// audit), or the dark under it (the block's vertices on the floor 17% dark).
// There the reflected radiosity is rebuilt at the point (nearReflected).
glm::vec3 Context::gatherRay(Ray ray, int levels, Sampler& smp, Counts& c) const {
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
      // A reflection leaves on the side the ray came from (leaveFrom), a refraction through the other.
      ray = spawn(specularOrigin(ray.d, ev.d, q.x, q.n, eps(), [&] { return leaveFrom(ray, q); }), q.n, ev.d, 0.f);
      continue;
    }
    if (!(glm::dot(q.n, ray.d) < 0.f)) break;
    if (m == Material::Glossy) {
      glm::vec3 wi, weight;
      float pdf;
      if (!bsdfAt(q, -ray.d).sample(smp.next2D(), wi, weight, pdf)) break;
      w *= weight;
      ray = spawn(leaveFrom(ray, q), q.n, wi, 0.f);
      continue;
    }
    const bool near = k == 0 && !tp_->nearT.empty() && q.t < tp_->nearT[q.face];
    return w * (near ? nearReflected(q, leaveFrom(ray, q), levels, smp, c) : interpolate(tp_->R, q));
  }
  return glm::vec3(0.f);
}

// A near hit's reflected radiosity rho (H_direct + H_caustic + H_indirect):
// the direct light from this view's own lights (next-event estimation and a
// ray that may only find a light), the caustic map, and the indirect light
// gathered again by one cosine ray whose own near hit is treated the same
// way, for `levels` more levels (a multi-level gather, as radiosity's);
// past them the first pass's indirect part interpolated (it varies on the
// scale of the room, but under a block it is the dark of the buried
// vertices).
glm::vec3 Context::nearReflected(const SurfacePoint& q, const glm::vec3& from, int levels, Sampler& smp,
                                 Counts& c) const {
  ++c.gatherNear;
  const glm::vec3 rho = s_.faceRho(q.face);
  const glm::vec3 direct = kPi * traceFromSurface(q.x, from, q.n, smp, c);  // H_direct of a white surface
  glm::vec3 H = direct + tp_->caustic(q.x, q.n, o_.causticK);
  if (levels > 0) {
    const Frame frame(q.n);
    H += gatherRay(spawn(from, q.n, frame.toWorld(cosineHemisphere(smp.next2D())), 0.f), levels - 1, smp, c);
    return rho * H;
  }
  return glm::max(rho * H + interpolate(tp_->indirect, q), glm::vec3(0.f));
}

}  // namespace gi::eye
