#include "gi/emitters.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "gi/color.h"
#include "gi/luminaires.h"
#include "gi/raycaster.h"
#include "gi/sampling.h"
#include "gi/specular.h"
#include "hit_origin.h"

namespace gi {

EmitterSampler::EmitterSampler(const Scene& s) : s_(s) {
  const auto ok = usableFaceMask(s);
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!ok[f]) continue;
    const double p = double(luminance(s.faceEmission(f))) * faceArea(s, f);
    if (!(p > 0.0)) continue;
    faces_.push_back(uint32_t(f));
    area_.push_back(float(faceArea(s, f)));
    total_ += p;
    cdf_.push_back(total_);
  }
  pdfOfFace_.assign(s.faceCount(), 0.f);
  for (size_t k = 0; k < faces_.size(); ++k)
    pdfOfFace_[faces_[k]] = float((cdf_[k] - (k ? cdf_[k - 1] : 0.0)) / total_) / area_[k];
}

EmitterSampler::Sample EmitterSampler::sample(glm::vec2 u) const {
  float ux;
  const size_t k = invertCdf(cdf_, double(u.x), &ux);
  const double w = cdf_[k] - (k ? cdf_[k - 1] : 0.0);
  const uint32_t f = faces_[k];
  const auto& t = s_.triangles[f];
  const glm::vec2 b = uniformTriangle({ux, u.y});
  Sample smp;
  smp.p = b.x * s_.positions[t.x] + b.y * s_.positions[t.y] + (1.f - b.x - b.y) * s_.positions[t.z];
  smp.n = glm::normalize(faceNormalUnnormalized(s_, f));
  smp.E = s_.faceEmission(f);
  smp.pdfArea = float(w / total_) / area_[k];
  smp.face = f;
  return smp;
}

std::optional<std::string> emitterOrientationWarning(const Scene& s, const RayCaster& caster, bool otherLights,
                                                     int rays) {
  const EmitterSampler lights(s);
  if (lights.empty() || rays < 1) return std::nullopt;
  const float eps = float(sceneScale(s).rayEpsilon);
  int front = 0, back = 0, escaped = 0;
  std::vector<EmitterSampler::Sample> points;  // for the probe below, where a warning follows
  points.reserve(size_t(rays));
  Rng rng(0x11e7u);
  for (int k = 0; k < rays; ++k) {
    const EmitterSampler::Sample smp = lights.sample({rng.next(), rng.next()});
    points.push_back(smp);
    Ray r;
    r.o = smp.p + smp.n * eps;
    r.d = Frame(smp.n).toWorld(cosineHemisphere({rng.next(), rng.next()}));
    const Hit h = caster.intersect(r);
    if (!h.valid()) ++escaped;
    // Glass and mirrors take light on either side (a mirror turned away
    // from the lamp still lit the floor, warned of as lost; an outside audit).
    else if (glm::dot(r.d, h.ng) < 0.f || isSpecular(s.faceMaterial(h.face))) ++front;
    else ++back;
  }
  if (100 * front >= rays || (otherLights && 2 * back < rays)) return std::nullopt;
  // How many rays started past a surface closer than the offset (the
  // light's own face left out): then nothing is turned away.
  int past = 0;
  for (const EmitterSampler::Sample& smp : points) past += surfaceWithinOffset(caster, smp.p, smp.n, eps);
  // Plates 1e-5 of the diagonal apart facing each other were told to turn
  // their faces round (an outside audit).
  if (2 * past >= rays) {
    char b[480];
    std::snprintf(b, sizeof b,
                  "the lights face no surface they can reach: %d of %d rays cast from their fronts start past a "
                  "surface closer than the ray offset (%.3g in mesh units), so that surface and the light do not see "
                  "each other and the light between them is lost (the lights themselves still show); keep surfaces "
                  "facing a light farther apart than ten offsets, or let them touch (shared vertices)",
                  past, rays, double(eps) * s.unit);
    return std::string(b);
  }
  return "the lights face no surface: of " + std::to_string(rays) + " rays cast from their fronts, " +
         std::to_string(escaped) + " left the scene and " + std::to_string(back) + " met the back of a face (" +
         std::to_string(front) + " a front), so their light is lost: the surfaces they should light stay dark (the "
         "lights themselves still show). If the scene is a room, its faces point out of it (a box built as a solid "
         "has outward normals): invert the faces' "
         "orientation (MeshLab: Filters > Normals, Curvatures and Orientation > Invert Faces Orientation), or only "
         "the lights' if they alone face away";
}

bool PointLight::on() const { return luminance(intensity) > 0.f; }
Cone PointLight::spot() const { return Cone(spotDirection, double(std::clamp(spotAngleDeg, 0.f, 180.f))); }

void PointLight::check() const {
  if (!on()) return;
  if (!(double(spotAngleDeg) >= kMinSpotAngleDeg && spotAngleDeg <= 180.f))
    throw std::invalid_argument("spot_angle = " + std::to_string(spotAngleDeg) +
                                ": the spot's half angle must lie in [0.1, 180] degrees (narrower cones hold no "
                                "direction but the axis in single precision, and would emit nothing)");
}

namespace {
// The shadow ray from `from` (a surface point lifted off its surface) to the
// light point y, stopping `stop` before it; tfar <= 0: y is nearer than that.
Ray shadowRayTo(const glm::vec3& from, const glm::vec3& y, float stop) {
  Ray ray;
  ray.o = from;
  const glm::vec3 w = y - from;
  const float len = glm::length(w);
  ray.d = len > 0.f ? w / len : glm::vec3(0.f, 0.f, 1.f);
  ray.tfar = len * (1.f - 1e-4f) - stop;
  return ray;
}
}  // namespace

glm::vec3 pointLightIrradiance(const PointLight& L, const RayCaster& caster, const glm::vec3& x, const glm::vec3& from,
                               const glm::vec3& n) {
  if (!L.on()) return glm::vec3(0.f);
  glm::vec3 w = L.position - x;
  const float r2 = glm::dot(w, w);
  if (!(r2 > 0.f)) return glm::vec3(0.f);
  const float r = std::sqrt(r2);
  w /= r;
  const float cx = glm::dot(n, w);
  if (cx <= 0.f || !L.spot().contains(-w)) return glm::vec3(0.f);
  const Ray ray = shadowRayTo(from, L.position, 0.f);
  return ray.tfar > 0.f && caster.occluded(ray) ? glm::vec3(0.f) : L.intensity * cx / r2;
}

glm::vec3 sampleDirectIrradiance(const EmitterSampler& lights, const RayCaster& caster, const glm::vec3& x,
                                 const glm::vec3& from, const glm::vec3& n, glm::vec2 u, float eps, uint32_t skip) {
  const auto L = lights.sample(u);
  if (L.face == skip) return glm::vec3(0.f);
  glm::vec3 w = L.p - lightSeenFrom(x, from, L.p, L.n, eps);
  const float r2 = glm::dot(w, w);
  if (!(r2 > 0.f)) return glm::vec3(0.f);
  const float r = std::sqrt(r2);
  w /= r;
  const float cx = glm::dot(n, w), ce = -glm::dot(L.n, w);
  if (cx <= 0.f || ce <= 0.f) return glm::vec3(0.f);  // behind x or the emitter's back
  const Ray ray = shadowRayTo(from, L.p, eps);
  if (ray.tfar > 0.f && caster.occluded(ray)) return glm::vec3(0.f);
  return L.E * (0.318309886f * cx * ce / (r2 * L.pdfArea));
}

glm::vec3 sampleLightMIS(const EmitterSampler& lights, const RayCaster& caster, const glm::vec3& x,
                         const glm::vec3& from, const glm::vec3& n, glm::vec2 u, float eps, uint64_t* rays) {
  const auto L = lights.sample(u);
  glm::vec3 w = L.p - lightSeenFrom(x, from, L.p, L.n, eps);
  const float r2 = glm::dot(w, w);
  if (!(r2 > 0.f)) return glm::vec3(0.f);
  const float r = std::sqrt(r2);
  w /= r;
  const float cx = glm::dot(n, w), ce = -glm::dot(L.n, w);
  if (cx <= 0.f || ce <= 0.f) return glm::vec3(0.f);
  const Ray ray = shadowRayTo(from, L.p, eps);
  if (rays) ++*rays;
  if (ray.tfar > 0.f && caster.occluded(ray)) return glm::vec3(0.f);
  const float pdfL = L.pdfArea * r2 / ce;  // solid angle
  return L.E * (0.318309886f * cx / pdfL) * powerHeuristic(pdfL, cx * 0.318309886f);
}

glm::vec3 sampleDirectIrradianceMIS(const EmitterSampler& lights, const Scene& s, const RayCaster& caster,
                                    const glm::vec3& x, const glm::vec3& from, const glm::vec3& n, glm::vec2 uLight,
                                    glm::vec2 uDir, float eps) {
  glm::vec3 H = sampleLightMIS(lights, caster, x, from, n, uLight, eps);
  {
    const glm::vec3 w = Frame(n).toWorld(cosineHemisphere(uDir));
    const float cx = glm::dot(n, w);
    if (cx > 0.f) {
      Ray ray;
      ray.o = from;
      ray.d = w;
      const Hit h = caster.intersect(ray);
      if (h.valid()) {
        const glm::vec3 E = s.faceEmission(h.face);
        const glm::vec3 ng = glm::normalize(faceNormalUnnormalized(s, h.face));
        const float cosY = -glm::dot(ng, w);
        if (cosY > 0.f && (E.r > 0.f || E.g > 0.f || E.b > 0.f)) {
          const float pdfL = lights.pdfArea(h.face) * h.t * h.t / cosY;
          H += E * powerHeuristic(cx * 0.318309886f, pdfL);  // pi L_e cos / pdf_B = E, weighted
        }
      }
    }
  }
  return H;
}

}  // namespace gi
