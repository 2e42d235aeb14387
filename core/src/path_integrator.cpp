// The shared path integrator (path_integrator.h): BSDFs, lights, next-event
// estimation and the path loop.
#include "path_integrator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gi/color.h"
#include "gi/run.h"
#include "gi/specular.h"
#include "hit_origin.h"

namespace gi::paths {

namespace {
constexpr float kInvPi = 0.318309886f;
bool positive(const glm::vec3& v) { return v.r > 0.f || v.g > 0.f || v.b > 0.f; }
}  // namespace

glm::vec3 Bsdf::f(const glm::vec3& wi) const {
  if (glossy) return lobe.eval(woLocal, frame.toLocal(wi));
  return glm::dot(frame.n, wi) > 0.f ? rho * kInvPi : glm::vec3(0.f);
}

float Bsdf::pdf(const glm::vec3& wi) const {
  if (glossy) return lobe.pdf(woLocal, frame.toLocal(wi));
  return std::max(0.f, glm::dot(frame.n, wi)) * kInvPi;
}

bool Bsdf::sample(glm::vec2 u, glm::vec3& wi, glm::vec3& weight, float& pdfOut) const {
  if (glossy) {
    const GgxLobe::Sample smp = lobe.sample(woLocal, u);
    if (!smp.valid) return false;
    wi = frame.toWorld(smp.wi);
    weight = smp.weight;
    pdfOut = smp.pdf;
    return true;
  }
  const glm::vec3 l = cosineHemisphere(u);
  if (!(l.z > 0.f)) return false;
  wi = frame.toWorld(l);
  weight = rho;  // (rho / pi) cos / (cos / pi)
  pdfOut = l.z * kInvPi;
  return true;
}

Integrator::Integrator(const Scene& s, const RayCaster& c, const LightSettings& lights, const PathRules& rules,
                       const StoredLight* stored)
    : s_(s), caster_(c), L_(lights), rules_(rules), stored_(stored), emitters_(s), faceN_(unitFaceNormals(s)),
      faceAlt_(faceAltitudes(s)), eps_(0.f), farT_(0.f) {
  const SceneScale scale = sceneScale(s);
  eps_ = float(scale.rayEpsilon);
  farT_ = float(2.0 * scale.diagonal);
  hasSky_ = luminance(L_.skyRadiance) > 0.f;
  hasSun_ = luminance(L_.sunIrradiance) > 0.f;
  // The disk's solid angle 2 pi (1 - cos a) = 4 pi sin^2(a / 2), in double:
  // in single precision 1 - cos a is 0 below a = 0.014 degrees (and off by
  // 0.5% at the real sun's 0.27), which made the radiance and the density
  // infinite and every path's value NaN (a reference of zeros; found 5
  // December 2026). Below 1e-12 sr (a = 3.2e-5 degrees) the sun is taken
  // as the point it then is: one shadow ray, its radiance's limit.
  sunCone_ = Cone(L_.sunDirection, double(L_.sunAngularRadiusDeg));
  const double omega = sunCone_.solidAngle();
  sunDisk_ = hasSun_ && omega > 1e-12;
  sunPdf_ = sunDisk_ ? float(1.0 / omega) : 0.f;
  sunL_ = sunDisk_ ? L_.sunIrradiance * float(double(sunDiskScale(L_.sunAngularRadiusDeg)) / omega)
                   : glm::vec3(0.f);  // E / (pi sin^2 a)
  hasPoint_ = L_.point.on();
  spot_ = L_.point.spot();
}

bool Integrator::emits(uint32_t face) const { return positive(s_.faceEmission(face)); }

SurfacePoint Integrator::surfaceAt(const Ray& r, const Hit& h) const {
  SurfacePoint sp;
  if (!h.valid()) return sp;
  sp.x = r.o + r.d * h.t;
  sp.n = faceN_[h.face];
  if (h.t > farT_) {
    // A camera D away puts its hit off the face by about D * 6e-8 (the
    // float ray origin and t), beyond the ray offset past 170 diagonals:
    // shadow and bounce rays started behind the face (acne in a telephoto
    // view; an outside review). Projected onto the face's plane in double.
    const glm::dvec3 x(sp.x), n(sp.n), p0(s_.positions[s_.triangles[h.face].x]);
    sp.x = glm::vec3(x - n * glm::dot(x - p0, n));
  }
  sp.face = h.face;
  sp.u = h.u;
  sp.v = h.v;
  sp.t = h.t;
  return sp;
}

glm::vec3 Integrator::leaveFrom(const Ray& in, const SurfacePoint& sp) const {
  if (sp.t <= farT_)
    return hitRayOrigin(caster_, in.o, in.d, sp.t, sp.n, eps_, hitBorder(faceAlt_, sp.face, sp.u, sp.v));
  return sp.x + (glm::dot(in.d, sp.n) < 0.f ? sp.n : -sp.n) * eps_;
}

Ray Integrator::spawn(const glm::vec3& x, const glm::vec3& n, const glm::vec3& d, float lift) const {
  Ray r;
  r.o = x + (glm::dot(d, n) > 0.f ? n : -n) * lift;
  r.d = d;
  return r;
}

Ray Integrator::shadowRay(const glm::vec3& x, const glm::vec3& n, const glm::vec3& d, const glm::vec3& y, float lift,
                          float stop) const {
  Ray r = spawn(x, n, d, lift);
  const glm::vec3 w = y - r.o;
  const float len = glm::length(w);
  if (len > 0.f) r.d = w / len;
  r.tfar = len * (1.f - 1e-4f) - stop;
  return r;
}

glm::vec3 Integrator::escaped(const glm::vec3& d, bool delta, float pdfPrev, float nLPrev) const {
  glm::vec3 L = L_.skyRadiance;
  // Inside the disk, tested in double: a float cos test admitted a cone
  // wider than the disk whose solid angle sunL_ divides by (the sun 6.5
  // times too bright in mirrors at 0.01 degrees, 0.8% at 0.27; an outside
  // review).
  if (sunDisk_ && sunCone_.contains(d)) L += sunL_ * (delta ? 1.f : powerHeuristic(pdfPrev, nLPrev * sunPdf_));
  return L;
}

glm::vec3 Integrator::emitted(uint32_t face, float t, float cosO, bool delta, float pdfPrev, float nLPrev) const {
  const float pdfL = emitters_.pdfArea(face) * t * t / cosO;  // the light sample's density in solid angle
  return s_.faceEmission(face) * kInvPi * (delta ? 1.f : powerHeuristic(pdfPrev, nLPrev * pdfL));
}

Bsdf Integrator::bsdfAt(const SurfacePoint& sp, const glm::vec3& wo) const {
  Bsdf b(sp.n);
  if (s_.faceMaterial(sp.face) == Material::Glossy) {
    b.glossy = true;
    b.lobe = GgxLobe(s_.faceRoughness(sp.face), s_.faceRho(sp.face));
    b.woLocal = b.frame.toLocal(wo);
  } else {
    b.rho = s_.faceRho(sp.face);
  }
  return b;
}

glm::vec3 Integrator::nextEvent(const glm::vec3& x, const glm::vec3& n, const Bsdf& b, Sampler& smp, Counts& c, int nL,
                                float lift, const glm::vec3* from) const {
  glm::vec3 L(0.f);
  // Where the shadow rays leave: x lifted by `lift`, or `from` as given.
  const glm::vec3& o = from ? *from : x;
  const float up = from ? 0.f : lift;
  const float fn = float(nL);
  for (int k = 0; k < nL; ++k) {
    if (!emitters_.empty()) {
      const auto e = emitters_.sample(smp.next2D());
      glm::vec3 w = e.p - (from ? lightSeenFrom(x, *from, e.p, e.n, eps_) : x);
      const float r2 = glm::dot(w, w);
      if (r2 > 0.f) {
        const float r = std::sqrt(r2);
        w /= r;
        const float cx = glm::dot(n, w), ce = -glm::dot(e.n, w);
        const glm::vec3 f = cx > 0.f && ce > 0.f ? b.f(w) : glm::vec3(0.f);
        if (positive(f)) {
          const Ray ray = shadowRay(o, n, w, e.p, up, eps_);
          const bool cast = ray.tfar > 0.f;  // else the emitter point is closer than the offset: visible
          c.shadow += cast;
          if (!cast || !caster_.occluded(ray)) {
            const float pdfL = e.pdfArea * r2 / ce;  // solid angle
            L += f * e.E * kInvPi * (cx / pdfL) * (powerHeuristic(fn * pdfL, b.pdf(w)) / fn);
          }
        }
      }
    }
    if (sunDisk_) {
      const glm::vec3 w = Frame(L_.sunDirection).toWorld(uniformConeVersine(smp.next2D(), float(sunCone_.versine())));
      const float cx = glm::dot(n, w);
      const glm::vec3 f = cx > 0.f ? b.f(w) : glm::vec3(0.f);
      if (positive(f)) {
        ++c.shadow;
        if (!caster_.occluded(spawn(o, n, w, up)))
          L += f * sunL_ * (cx / sunPdf_) * (powerHeuristic(fn * sunPdf_, b.pdf(w)) / fn);
      }
    }
  }
  if (hasSun_ && !sunDisk_) {  // a sharp directional sun: one shadow ray
    const glm::vec3 w = L_.sunDirection;
    const float cx = glm::dot(n, w);
    const glm::vec3 f = cx > 0.f ? b.f(w) : glm::vec3(0.f);
    if (positive(f)) {
      ++c.shadow;
      if (!caster_.occluded(spawn(o, n, w, up))) L += f * L_.sunIrradiance * cx;
    }
  }
  if (hasPoint_) {
    glm::vec3 w = L_.point.position - x;
    const float r2 = glm::dot(w, w);
    if (r2 > 0.f) {
      const float r = std::sqrt(r2);
      w /= r;
      const float cx = glm::dot(n, w);
      const glm::vec3 f = cx > 0.f && spot_.contains(-w) ? b.f(w) : glm::vec3(0.f);
      if (positive(f)) {
        const Ray ray = shadowRay(o, n, w, L_.point.position, up, 0.f);
        ++c.shadow;
        if (!caster_.occluded(ray)) L += f * L_.point.intensity * (cx / r2);
      }
    }
  }
  return L;
}

void Integrator::specularStep(const SurfacePoint& sp, PathState& st, Sampler& smp, bool given) const {
  const Material m = s_.faceMaterial(sp.face);
  const float ior = s_.ior.empty() ? 1.5f : s_.ior[sp.face];
  const SpecularEvent ev = scatterSpecular(m, st.ray.d, sp.n, s_.faceRho(sp.face), ior, smp.next1D());
  st.beta *= ev.weight * ev.radianceScale;
  st.delta = true;
  st.kind = PathState::Kind::Specular;
  // A reflection leaves on the side the ray came from (leaveFrom), a
  // refraction through the other (specularOrigin); a point given apart from
  // a ray, lifted.
  st.ray = given ? spawn(sp.x, sp.n, ev.d)
                 : spawn(specularOrigin(st.ray.d, ev.d, sp.x, sp.n, eps_, [&] { return leaveFrom(st.ray, sp); }),
                         sp.n, ev.d, 0.f);
}

glm::vec3 Integrator::trace(PathState st, const SurfacePoint* first, Sampler& smp, Counts& c,
                            glm::vec3* parts) const {
  // A continuation ray that can only find lights is worth casting only if it can find one.
  const bool lightRays = !emitters_.empty() || hasSky_ || sunDisk_;
  glm::vec3 L(0.f);
  // A light found along the ray (emission, sky, sun): its kind from the
  // event that spawned the ray; a light sample at a glossy vertex: caustic
  // before the second diffuse vertex (see the header).
  auto found = [&](const glm::vec3& term) {
    L += term;
    if (parts)
      parts[st.diffuseVertices > 1                     ? kPathIndirect
            : st.kind == PathState::Kind::Diffuse ? kPathDirect
                                                   : kPathCaustic] += term;
  };
  auto sampled = [&](const glm::vec3& term) {
    L += term;
    if (parts) parts[st.diffuseVertices > 1 ? kPathIndirect : kPathCaustic] += term;
  };
  for (;;) {
    SurfacePoint sp;
    // A point given by the caller apart from st.ray (a vertex) does not
    // lie along it: its rays leave lifted along its normal (leaveFrom reads
    // the ray that reached the point). A camera's primary hit, given with
    // st.firstOnRay, is its ray's own hit and leaves as any hit.
    const bool given = first != nullptr && !st.firstOnRay;
    if (first) {
      sp = *first;
      first = nullptr;
    } else {
      switch (st.kind) {
        case PathState::Kind::Primary: ++c.primary; break;
        case PathState::Kind::Specular: ++c.specular; break;
        case PathState::Kind::Glossy: ++c.glossy; break;
        case PathState::Kind::Diffuse: ++c.diffuse; break;
      }
      sp = surfaceAt(st.ray, caster_.intersect(st.ray));
    }
    if (!sp.valid()) {
      found(st.beta * escaped(st.ray.d, st.delta, st.pdfPrev, st.nLPrev));
      break;
    }
    const Material m = s_.faceMaterial(sp.face);
    if (isSpecular(m)) {
      if (st.lightOnly) break;
      // At the limit a mirror or glass still shows the light straight behind
      // it, as a diffuse vertex's last sampled direction may still find a
      // light: max_depth k takes light of k reflections of any kind (the
      // light seen in a mirror is one, as the light a wall reflects is; it
      // took max_depth 2 until 4 December 2026).
      if (st.depth >= rules_.maxDepth) {
        ++c.cutAtMaxDepth;
        if (!lightRays) break;
        st.lightOnly = true;
      } else {
        ++st.depth;
      }
      specularStep(sp, st, smp, given);
    } else {
      const float cosO = -glm::dot(sp.n, st.ray.d);
      if (!(cosO > 0.f)) break;  // seen from behind: black
      int nL = 1;
      bool wanted = true;
      const Bsdf b = bsdfAt(sp, -st.ray.d);
      // Where the light samples and the BSDF sample leave: found once the
      // path goes on from here (leaveFrom may cast a ray near a corner).
      glm::vec3 o;
      const auto leave = [&] { o = given ? sp.x + sp.n * eps_ : leaveFrom(st.ray, sp); };
      if (m == Material::Glossy) {
        if (st.lightOnly) break;
        leave();
        sampled(st.beta * nextEvent(sp.x, sp.n, b, smp, c, 1, 0.f, &o));
      } else {
        if (emits(sp.face)) found(st.beta * emitted(sp.face, sp.t, cosO, st.delta, st.pdfPrev, st.nLPrev));
        if (st.lightOnly) break;
        if (stored_ && stored_->alone()) {
          ++st.diffuseVertices;  // the stored light lies beyond this diffuse vertex
          // (Read from the stored per-vertex values: it casts no ray.)
          sampled(st.beta * stored_->reflected(sp, sp.x + sp.n * eps_, b.rho, smp, c));
          break;
        }
        ++st.diffuseVertices;
        nL = st.diffuseVertices == 1 ? rules_.firstLightSamples : 1;
        leave();
        glm::vec3 Ld = nextEvent(sp.x, sp.n, b, smp, c, nL, 0.f, &o);
        // A first pass's indirect part is a difference of noisy estimates: keep the sum >= 0.
        if (stored_) Ld = glm::max(Ld + stored_->reflected(sp, o, b.rho, smp, c), glm::vec3(0.f));
        sampled(st.beta * Ld);  // after ++diffuseVertices: indirect when x0 started the path
        wanted = rules_.interreflection &&
                 (rules_.maxDiffuseBounces < 0 || st.diffuseVertices <= rules_.maxDiffuseBounces);
        if (!b.reflects()) break;
      }
      // The BSDF sample: it continues the path, or (at the limit, or beyond
      // the diffuse bounces wanted) may only find a light directly.
      const bool goOn = wanted && st.depth < rules_.maxDepth;
      if (wanted && !goOn) ++c.cutAtMaxDepth;
      if (!goOn && !lightRays && m != Material::Glossy) break;
      glm::vec3 wi, w;
      float pdf;
      if (!b.sample(smp.next2D(), wi, w, pdf)) break;
      st.beta *= w;
      st.delta = false;
      st.pdfPrev = pdf;
      st.nLPrev = float(nL);
      st.ray = spawn(o, sp.n, wi, 0.f);
      st.kind = m == Material::Glossy ? PathState::Kind::Glossy : PathState::Kind::Diffuse;
      if (goOn) ++st.depth;
      st.lightOnly = !goOn;
    }
    if (!positive(st.beta)) break;
    if (rules_.roulette && st.depth >= 3 && !st.lightOnly) {
      const float q = std::min(1.f, std::max({st.beta.r, st.beta.g, st.beta.b}));
      if (q < 1.f) {
        if (smp.next1D() >= q) { ++c.roulette; break; }
        st.beta /= q;
      }
    }
  }
  return L;
}

glm::vec3 Integrator::traceFromSurface(const glm::vec3& x, const glm::vec3& from, const glm::vec3& n, Sampler& smp,
                                       Counts& c, glm::vec3* parts) const {
  Bsdf b(n);
  b.rho = glm::vec3(1.f);
  const int nL = rules_.firstLightSamples;
  glm::vec3 L = nextEvent(x, n, b, smp, c, nL, 0.f, &from);
  if (parts) parts[kPathDirect] += L;  // light sampled at x0 itself: L D
  const bool lightRays = !emitters_.empty() || hasSky_ || sunDisk_;
  const bool wanted = rules_.interreflection && rules_.maxDiffuseBounces != 0;
  const bool goOn = wanted && rules_.maxDepth > 0;
  if (wanted && !goOn) ++c.cutAtMaxDepth;
  if (!goOn && !lightRays) return L;
  PathState st;
  glm::vec3 wi;
  if (!b.sample(smp.next2D(), wi, st.beta, st.pdfPrev)) return L;
  st.delta = false;
  st.nLPrev = float(nL);
  st.ray = spawn(from, n, wi, 0.f);
  st.diffuseVertices = 1;
  st.depth = goOn ? 1 : 0;
  st.lightOnly = !goOn;
  st.kind = PathState::Kind::Diffuse;
  return L + trace(st, nullptr, smp, c, parts);
}

namespace {
// Whether a spot's cone meets a mirror or glass face (a point light, or a
// spot wider than a hemisphere, meets every face): a triangle meets the cone
// where one of its edges comes within the half angle of the axis (the
// largest cosine along an edge, at its ends or where its derivative
// vanishes), or the axis passes through it. A 30-degree spot that could not
// reach a mirror was warned of all the same (an outside audit).
bool pointReachesSpecular(const Scene& s, const PointLight& p) {
  if (p.spotAngleDeg >= 90.f) return true;
  const glm::dvec3 u = glm::normalize(glm::dvec3(p.spotDirection)), o(p.position);
  const double cosA = std::cos(double(p.spotAngleDeg) * M_PI / 180.0);
  auto cosAt = [&](const glm::dvec3& q) {
    const double l = glm::length(q);
    return l > 0.0 ? glm::dot(u, q) / l : 1.0;
  };
  auto maxCosOnEdge = [&](const glm::dvec3& a, const glm::dvec3& b) {  // a, b relative to the light
    const glm::dvec3 e = b - a;
    double m = std::max(cosAt(a), cosAt(b));
    const double al = glm::dot(u, a), be = glm::dot(u, e), ga = glm::dot(a, a), de = glm::dot(a, e), ep = glm::dot(e, e);
    const double den = be * de - al * ep;
    if (den != 0.0) {
      const double t = (al * de - be * ga) / den;
      if (t > 0.0 && t < 1.0) m = std::max(m, cosAt(a + t * e));
    }
    return m;
  };
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!isSpecular(s.faceMaterial(f))) continue;
    const glm::uvec3 t = s.triangles[f];
    const glm::dvec3 a = glm::dvec3(s.positions[t.x]) - o, b = glm::dvec3(s.positions[t.y]) - o,
                     c = glm::dvec3(s.positions[t.z]) - o;
    if (std::max({maxCosOnEdge(a, b), maxCosOnEdge(b, c), maxCosOnEdge(c, a)}) >= cosA - 1e-9) return true;
    // The axis through the triangle (Moller and Trumbore 1997, from the light).
    const glm::dvec3 e1 = b - a, e2 = c - a, pv = glm::cross(u, e2);
    const double det = glm::dot(e1, pv);
    if (det == 0.0) continue;
    const glm::dvec3 tv = -a;
    const double bu = glm::dot(tv, pv) / det;
    const glm::dvec3 qv = glm::cross(tv, e1);
    const double bv = glm::dot(u, qv) / det, dist = glm::dot(e2, qv) / det;
    if (bu >= 0.0 && bv >= 0.0 && bu + bv <= 1.0 && dist > 0.0) return true;
  }
  return false;
}
}  // namespace

std::string unsampledLightPaths(const Scene& s, const LightSettings& lights, bool sunMet, double paths) {
  const bool sun = luminance(lights.sunIrradiance) > 0.f;
  if (!lights.point.on() && !sun) return "";
  if (!anyFaceMaterial(s, isSpecular)) return "";
  std::string w;
  if (lights.point.on() && pointReachesSpecular(s, lights.point))
    w = "the point light's light reflected or refracted by mirrors or glass onto other surfaces (caustics, "
        "L S+ D paths) is missing: no traced path can reach a point light through a perfect mirror or glass; "
        "photon mapping computes it";
  // A sun's disk is reached through a mirror or glass only by a sampled
  // direction that happens to meet it: 1 in pi / Omega of the cosine-
  // weighted ones (13,000 at the real sun's 0.27 degrees). A room lit by the
  // sun through a glass pane read 14 times too dark in the reference, with
  // error bars that did not show it (an outside audit); from about 2
  // degrees (1 in 800) the paths find it and the bars hold, if each vertex
  // (pixel) traces enough paths to meet it about once: at 2.1 degrees and
  // 256 paths (0.34 expected) 12 of 810 vertices lit by the sun in a mirror
  // read half their light with bars of 0.0008 (z -880), at 5 degrees and
  // 64 paths (0.49) one read z -178; at 3 and 5 degrees with 256 paths (0.7,
  // 1.9) the bars held (a second audit).
  const double omega = Cone(lights.sunDirection, double(lights.sunAngularRadiusDeg)).solidAngle();
  const bool fewPaths = paths > 0.0 && paths * omega / M_PI < 1.0;
  if (sun && !sunMet) {
    w += std::string(w.empty() ? "" : "; ") +
         "the sun's light reflected or refracted by mirrors or glass onto other surfaces (sunlight through a glass "
         "pane, a mirror's sun patch) is missing: this mode's shadow rays stop at mirrors and glass; the "
         "path-traced or two-pass mode computes it";
  } else if (sun && (omega < M_PI / 800.0 || fewPaths)) {
    char chance[96];
    if (omega > 0.0) std::snprintf(chance, sizeof chance, "only by meeting its disk, 1 direction in %.3g", M_PI / omega);
    else std::snprintf(chance, sizeof chance, "never (a sharp sun, radius 0, is a direction no path meets)");
    char b[480];
    std::snprintf(b, sizeof b,
                  "the sun's light reflected or refracted by mirrors or glass onto other surfaces (sunlight through "
                  "a glass pane, a mirror's sun patch) is mostly missing, its error bars too small: a traced path "
                  "reaches the sun (%g degrees) through a mirror or glass %s; photon mapping computes it (or widen "
                  "sun_angular_radius, or trace %.3g paths or more, so that each meets it about once)",
                  double(lights.sunAngularRadiusDeg), chance, omega > 0.0 ? std::ceil(M_PI / omega) : HUGE_VAL);
    w += (w.empty() ? "" : "; ") + std::string(b);
  }
  return w;
}

// Paths the depth limit ended while they would have gone on: their further
// light is missing, a bias outside the error bars. No limit (maxDepth -1):
// only paths caught between perfect mirrors reach `cap`. A limit k: in a
// closed room of the scene's mean reflectance rho the light of more than k
// bounces is a share rho^(k+1) of B where the surface does not emit (the
// series E (1 + rho + ... + rho^k) rho against its sum: the warning's
// figure, an upper bound), rho^(k+2) where it also emits (a furnace, whose
// B holds E besides); warn when that may exceed the mean
// relative error (the reference and the path-traced view; the view only noted the
// cut paths until 5 December 2026, when a white furnace's image read 26% of
// its radiance at max_depth 32 without a warning).
void depthWarnings(const Scene& s, int maxDepth, int cap, double paths, double cut, double relErr,
                   const char* remedy, RunStats& st) {
  if (!(cut > 0) || !(paths > 0)) return;
  char b[400];
  if (maxDepth < 0) {
    std::snprintf(b, sizeof b,
                  "%.0f of %.0f paths (%.3g%%) were still going after %d bounces (caught between perfect mirrors?) "
                  "and were cut: their further light is missing",
                  cut, paths, 100.0 * cut / paths, cap);
    st.warn(b);
    return;
  }
  // The share of B that more bounces would add in a closed room of the
  // scene's mean reflectance (area-weighted, each face's largest channel,
  // mirrors and glass at their tint): rho^(k+1), the tail of the
  // interreflection series sum rho^n. The largest reflectance read 100% as
  // soon as one white mirror was in the scene (an outside audit).
  double rhoArea = 0, area = 0;
  const auto ok = usableFaceMask(s);
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f]) {
      const glm::vec3 r = s.faceRho(f);
      const double a = faceArea(s, f);
      rhoArea += a * std::max({r.r, r.g, r.b});
      area += a;
    }
  const double rhoMean = area > 0 ? std::min(1.0, rhoArea / area) : 0.0;
  const double share = std::pow(rhoMean, double(maxDepth) + 1.0);
  if (share <= relErr) return;
  std::snprintf(b, sizeof b,
                "max_depth = %d cut %.0f of %.0f paths: the light of more bounces is missing (in a closed room of "
                "the mean reflectance here, %.4g, a share %.3g%% of B), more than the mean relative error "
                "%.3g%%, and is not in the error bars (%s)",
                maxDepth, cut, paths, rhoMean, 100.0 * share, 100.0 * relErr, remedy);
  st.warn(b);
}

}  // namespace gi::paths
