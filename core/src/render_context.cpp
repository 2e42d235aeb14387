// The scene as the eye-pass integrators see it: lights, materials, ray
// offsets, and next-event estimation.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "gi/color.h"
#include "gi/specular.h"
#include "render_internal.h"

namespace gi::eye {

namespace {
constexpr float kInvPi = 0.318309886f;
}

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

Context::Context(const Scene& s, const RayCaster& c, const RenderOptions& o, const TwoPassData* tp)
    : s_(s), caster_(c), o_(o), tp_(tp), lights_(s), faceN_(unitFaceNormals(s)), eps_(float(sceneScale(s).rayEpsilon)) {
  hasSky_ = luminance(o.skyRadiance) > 0.f;
  hasSun_ = luminance(o.sunIrradiance) > 0.f;
  sunDisk_ = hasSun_ && o.sunAngularRadiusDeg > 0.f;
  sunCos_ = std::cos(glm::radians(o.sunAngularRadiusDeg));
  const float omega = 2.f * float(M_PI) * (1.f - sunCos_);
  sunPdf_ = sunDisk_ ? 1.f / omega : 0.f;
  sunL_ = sunDisk_ ? o.sunIrradiance / omega : glm::vec3(0.f);
  hasPoint_ = o.point.on();
  if (o.mode != RenderMode::Whitted) return;
  // Whitted's area lights: connected sets of emitting faces (shared vertices).
  const auto ok = usableFaceMask(s);
  std::vector<uint32_t> parent(s.vertexCount());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f] && emits(uint32_t(f)))
      for (int k = 1; k < 3; ++k) parent[find(s.triangles[f][k])] = find(s.triangles[f][0]);
  std::vector<int> group(s.vertexCount(), -1);
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!ok[f] || !emits(uint32_t(f))) continue;
    const uint32_t root = find(s.triangles[f][0]);
    if (group[root] < 0) {
      group[root] = int(areaLights_.size());
      areaLights_.emplace_back();
    }
    areaLights_[size_t(group[root])].faces.push_back(uint32_t(f));
  }
  for (AreaLight& l : areaLights_) {
    std::map<std::pair<uint32_t, uint32_t>, int> edges;  // directed edge -> uses
    std::vector<uint32_t> verts;
    double area = 0.0;
    l.E = s.faceEmission(l.faces[0]);
    for (const uint32_t f : l.faces) {
      const auto& t = s.triangles[f];
      l.uniform = l.uniform && s.faceEmission(f) == l.E;
      for (int k = 0; k < 3; ++k) {
        ++edges[{t[k], t[(k + 1) % 3]}];
        verts.push_back(t[k]);
      }
      const double a = faceArea(s, f);
      l.centroid += a * (glm::dvec3(s.positions[t.x]) + glm::dvec3(s.positions[t.y]) + glm::dvec3(s.positions[t.z])) / 3.0;
      area += a;
    }
    l.centroid /= area;
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    for (const uint32_t v : verts) l.corners.push_back(glm::dvec3(s.positions[v]));
    for (const auto& [e, n] : edges)
      if (!edges.count({e.second, e.first}))
        for (int k = 0; k < n; ++k) l.boundary.push_back({glm::dvec3(s.positions[e.first]), glm::dvec3(s.positions[e.second])});
  }
}

bool Context::emits(uint32_t face) const {
  const glm::vec3 E = s_.faceEmission(face);
  return E.r > 0.f || E.g > 0.f || E.b > 0.f;
}

SurfacePoint Context::surfaceAt(const Ray& r, const Hit& h) const {
  SurfacePoint sp;
  if (!h.valid()) return sp;
  sp.x = r.o + r.d * h.t;
  sp.n = faceN_[h.face];
  sp.face = h.face;
  sp.u = h.u;
  sp.v = h.v;
  sp.t = h.t;
  return sp;
}

Ray Context::spawn(const glm::vec3& x, const glm::vec3& n, const glm::vec3& d) const {
  Ray r;
  r.o = x + (glm::dot(d, n) > 0.f ? n : -n) * eps_;
  r.d = d;
  return r;
}

glm::vec3 Context::escaped(const glm::vec3& d, bool delta, float pdfPrev, float nLPrev) const {
  glm::vec3 L = o_.skyRadiance;
  if (sunDisk_ && glm::dot(d, o_.sunDirection) >= sunCos_)
    L += sunL_ * (delta ? 1.f : powerHeuristic(pdfPrev, nLPrev * sunPdf_));
  return L;
}

Bsdf Context::bsdfAt(const SurfacePoint& sp, const glm::vec3& wo) const {
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

glm::vec3 Context::nextEvent(const glm::vec3& x, const glm::vec3& n, const Bsdf& b, Sampler& smp, Counts& c,
                             int nL) const {
  glm::vec3 L(0.f);
  const float fn = float(nL);
  for (int k = 0; k < nL; ++k) {
    if (!lights_.empty()) {
      const auto e = lights_.sample(smp.next2D());
      glm::vec3 w = e.p - x;
      const float r2 = glm::dot(w, w);
      if (r2 > 0.f) {
        const float r = std::sqrt(r2);
        w /= r;
        const float cx = glm::dot(n, w), ce = -glm::dot(e.n, w);
        const glm::vec3 f = cx > 0.f && ce > 0.f ? b.f(w) : glm::vec3(0.f);
        if (f.r > 0.f || f.g > 0.f || f.b > 0.f) {
          Ray ray = spawn(x, n, w);
          ray.tfar = r * (1.f - 1e-4f) - eps_;
          ++c.shadow;
          if (!(ray.tfar > 0.f) || !caster_.occluded(ray)) {
            const float pdfL = e.pdfArea * r2 / ce;  // solid angle
            L += f * e.E * kInvPi * (cx / pdfL) * (powerHeuristic(fn * pdfL, b.pdf(w)) / fn);
          }
        }
      }
    }
    if (sunDisk_) {
      const glm::vec3 w = Frame(o_.sunDirection).toWorld(uniformCone(smp.next2D(), sunCos_));
      const float cx = glm::dot(n, w);
      const glm::vec3 f = cx > 0.f ? b.f(w) : glm::vec3(0.f);
      if (f.r > 0.f || f.g > 0.f || f.b > 0.f) {
        ++c.shadow;
        if (!caster_.occluded(spawn(x, n, w)))
          L += f * sunL_ * (cx / sunPdf_) * (powerHeuristic(fn * sunPdf_, b.pdf(w)) / fn);
      }
    }
  }
  if (hasSun_ && !sunDisk_) {  // a sharp directional sun: one shadow ray
    const glm::vec3 w = o_.sunDirection;
    const float cx = glm::dot(n, w);
    const glm::vec3 f = cx > 0.f ? b.f(w) : glm::vec3(0.f);
    if (f.r > 0.f || f.g > 0.f || f.b > 0.f) {
      ++c.shadow;
      if (!caster_.occluded(spawn(x, n, w))) L += f * o_.sunIrradiance * cx;
    }
  }
  if (hasPoint_) {
    glm::vec3 w = o_.point.position - x;
    const float r2 = glm::dot(w, w);
    if (r2 > 0.f) {
      const float r = std::sqrt(r2);
      w /= r;
      const float cx = glm::dot(n, w);
      const glm::vec3 f = cx > 0.f && o_.point.shinesTowards(-w) ? b.f(w) : glm::vec3(0.f);
      if (f.r > 0.f || f.g > 0.f || f.b > 0.f) {
        Ray ray = spawn(x, n, w);
        ray.tfar = r * (1.f - 1e-4f);
        ++c.shadow;
        if (!caster_.occluded(ray)) L += f * o_.point.intensity * (cx / r2);
      }
    }
  }
  return L;
}

glm::vec3 Context::interpolate(const std::vector<glm::vec3>& perVertex, const SurfacePoint& sp) const {
  const auto& t = s_.triangles[sp.face];
  return (1.f - sp.u - sp.v) * perVertex[t.x] + sp.u * perVertex[t.y] + sp.v * perVertex[t.z];
}

}  // namespace gi::eye
