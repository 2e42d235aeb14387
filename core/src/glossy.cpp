#include "gi/glossy.h"

#include <algorithm>
#include <cmath>

namespace gi {

GgxLobe::GgxLobe(float a, const glm::vec3& f0) : alpha(std::clamp(a, 1e-3f, 1.f)), F0(glm::clamp(f0, 0.f, 1.f)) {}

float GgxLobe::D(const glm::vec3& h) const {
  if (h.z <= 0.f) return 0.f;
  const float a2 = alpha * alpha;
  const float t = h.z * h.z * (a2 - 1.f) + 1.f;
  return a2 / (float(M_PI) * t * t);
}

float GgxLobe::lambda(const glm::vec3& w) const {
  const float c2 = w.z * w.z, s2 = std::max(0.f, 1.f - c2);
  if (s2 <= 0.f) return 0.f;
  if (c2 <= 0.f) return HUGE_VALF;  // grazing: fully masked
  const float a2t2 = alpha * alpha * s2 / c2;
  return 0.5f * (std::sqrt(1.f + a2t2) - 1.f);
}

glm::vec3 GgxLobe::fresnel(float cosH) const {
  const float m = std::clamp(1.f - cosH, 0.f, 1.f), m2 = m * m;
  return F0 + (glm::vec3(1.f) - F0) * (m2 * m2 * m);
}

glm::vec3 GgxLobe::eval(const glm::vec3& wo, const glm::vec3& wi) const {
  if (wo.z <= 0.f || wi.z <= 0.f) return glm::vec3(0.f);
  glm::vec3 h = wo + wi;
  const float hl = glm::length(h);
  if (!(hl > 0.f)) return glm::vec3(0.f);
  h /= hl;
  return fresnel(glm::dot(wi, h)) * (D(h) * G2(wo, wi) / (4.f * wo.z * wi.z));
}

float GgxLobe::pdf(const glm::vec3& wo, const glm::vec3& wi) const {
  if (wo.z <= 0.f || wi.z <= 0.f) return 0.f;
  glm::vec3 h = wo + wi;
  const float hl = glm::length(h);
  if (!(hl > 0.f)) return 0.f;
  h /= hl;
  return G1(wo) * D(h) / (4.f * wo.z);
}

GgxLobe::Sample GgxLobe::sample(const glm::vec3& wo, glm::vec2 u) const {
  Sample s;
  if (wo.z <= 0.f) return s;
  // Heitz 2018, listing 1: stretch to the unit-roughness configuration,
  // sample the projected area of the hemisphere of visible normals, unstretch.
  const glm::vec3 Vh = glm::normalize(glm::vec3(alpha * wo.x, alpha * wo.y, wo.z));
  const float lensq = Vh.x * Vh.x + Vh.y * Vh.y;
  const glm::vec3 T1 = lensq > 0.f ? glm::vec3(-Vh.y, Vh.x, 0.f) / std::sqrt(lensq) : glm::vec3(1.f, 0.f, 0.f);
  const glm::vec3 T2 = glm::cross(Vh, T1);
  const float r = std::sqrt(u.x), phi = 2.f * float(M_PI) * u.y;
  const float t1 = r * std::cos(phi);
  float t2 = r * std::sin(phi);
  const float sh = 0.5f * (1.f + Vh.z);
  t2 = (1.f - sh) * std::sqrt(std::max(0.f, 1.f - t1 * t1)) + sh * t2;
  const glm::vec3 Nh = t1 * T1 + t2 * T2 + std::sqrt(std::max(0.f, 1.f - t1 * t1 - t2 * t2)) * Vh;
  const glm::vec3 h = glm::normalize(glm::vec3(alpha * Nh.x, alpha * Nh.y, std::max(1e-7f, Nh.z)));
  const float woh = glm::dot(wo, h);
  s.wi = 2.f * woh * h - wo;
  if (s.wi.z <= 0.f || woh <= 0.f) return s;  // reflected below the surface: lost (G2 < G1 accounts for it)
  s.pdf = G1(wo) * D(h) / (4.f * wo.z);
  if (!(s.pdf > 0.f)) return s;
  s.weight = fresnel(glm::dot(s.wi, h)) * (G2(wo, s.wi) / G1(wo));
  s.valid = true;
  return s;
}

}  // namespace gi
