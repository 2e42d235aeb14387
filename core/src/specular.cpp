#include "gi/specular.h"

#include <algorithm>
#include <cmath>

namespace gi {

float fresnelDielectric(float cosI, float eta) {
  cosI = std::clamp(cosI, 0.f, 1.f);
  const float sin2T = eta * eta * (1.f - cosI * cosI);
  if (sin2T >= 1.f) return 1.f;
  const float cosT = std::sqrt(1.f - sin2T);
  // Amplitude ratios for s and p polarisation (relative index 1/eta).
  const float rs = (eta * cosI - cosT) / (eta * cosI + cosT);
  const float rp = (cosI - eta * cosT) / (cosI + eta * cosT);
  return 0.5f * (rs * rs + rp * rp);
}

SpecularEvent scatterSpecular(Material m, const glm::vec3& d, const glm::vec3& n, const glm::vec3& tint, float ior, float u) {
  SpecularEvent e;
  e.weight = tint;
  if (m == Material::Mirror) {
    e.d = glm::normalize(reflectDir(d, n));
    return e;
  }
  const bool entering = glm::dot(d, n) < 0.f;
  const glm::vec3 nf = entering ? n : -n;  // faces the incoming ray
  const float eta = entering ? 1.f / ior : ior;
  const float cosI = std::min(1.f, -glm::dot(d, nf));
  const float sin2T = eta * eta * std::max(0.f, 1.f - cosI * cosI);
  if (sin2T >= 1.f) {
    e.totalInternal = true;
    e.d = glm::normalize(reflectDir(d, nf));
    return e;
  }
  const float F = fresnelDielectric(cosI, eta);
  if (u < F) {
    e.d = glm::normalize(reflectDir(d, nf));
    return e;
  }
  const float cosT = std::sqrt(1.f - sin2T);
  e.d = glm::normalize(eta * d + (eta * cosI - cosT) * nf);
  e.transmitted = true;
  e.radianceScale = eta * eta;  // radiance is compressed into the denser medium's smaller solid angle
  return e;
}

}  // namespace gi
