#include "gi/sampling.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace gi {

glm::vec3 cosineHemisphere(glm::vec2 u) {
  // Malley's method on a uniform disk (concentric map, Shirley and Chiu 1997).
  float a = 2.f * u.x - 1.f, b = 2.f * u.y - 1.f;
  float r, phi;
  if (a == 0.f && b == 0.f) return {0.f, 0.f, 1.f};
  if (std::fabs(a) > std::fabs(b)) { r = a; phi = 0.785398163f * (b / a); }
  else { r = b; phi = 1.570796327f - 0.785398163f * (a / b); }
  // phi is in [-pi/4, pi/2 + pi/4]; fold to [-pi/4, pi/4] and use short
  // Taylor series (error < 2e-9 there) instead of the libm calls.
  float c, sn;
  if (phi > 0.785398163f) { sinCosQuarterPi(1.570796327f - phi, sn, c); std::swap(c, sn); }
  else sinCosQuarterPi(phi, sn, c);
  float x = r * c, y = r * sn;
  float z = std::sqrt(std::fmax(0.f, 1.f - x * x - y * y));
  return {x, y, z};
}

// Both block functions are built twice, for AVX2 and for any x86-64, and
// the loader picks one (GCC function multiversioning). AVX2 has the 32-bit
// multiplies and byte shuffles the scrambling needs in 8 lanes; neither
// version uses fused multiply-adds (that would be the "fma" target), so they
// give the same bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define GI_BLOCK_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define GI_BLOCK_CLONES
#endif

GI_BLOCK_CLONES void scrambleBlock(int n, const uint32_t* r, uint32_t seed, float* u) {
  for (int j = 0; j < n; ++j) u[j] = toUnitFloat(reverseBits(laineKarrasPermutation(r[j], seed)));
}

GI_BLOCK_CLONES void cosineHemisphereBlock(int n, const float* u0, const float* u1, float* x, float* y, float* z) {
  // Same concentric map as cosineHemisphere, with selects instead of branches.
  for (int j = 0; j < n; ++j) {
    const float a = 2.f * u0[j] - 1.f, b = 2.f * u1[j] - 1.f;
    const bool first = std::fabs(a) > std::fabs(b);
    const float r = first ? a : b;
    const float num = first ? b : a;
    const float t = r != 0.f ? num / r : 0.f;
    float sn, c;
    sinCosQuarterPi(0.785398163f * t, sn, c);
    x[j] = r * (first ? c : sn);
    y[j] = r * (first ? sn : c);
    z[j] = std::sqrt(std::max(0.f, 1.f - r * r));  // max, not fmax (a call): the loop vectorises; no NaN here
  }
}

glm::vec3 uniformSphere(glm::vec2 u) {
  float z = 1.f - 2.f * u.x;
  float r = std::sqrt(std::fmax(0.f, 1.f - z * z));
  float phi = 6.283185307f * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

glm::vec3 uniformHemisphere(glm::vec2 u) {
  float z = u.x;
  float r = std::sqrt(std::fmax(0.f, 1.f - z * z));
  float phi = 6.283185307f * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

glm::vec3 uniformCone(glm::vec2 u, float cosMax) {
  float z = 1.f - u.x * (1.f - cosMax);
  float r = std::sqrt(std::fmax(0.f, 1.f - z * z));
  float phi = 6.283185307f * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

glm::vec3 uniformConeVersine(glm::vec2 u, float versine) {
  const float t = u.x * versine;  // 1 - z
  const float r = std::sqrt(std::fmax(0.f, t * (2.f - t)));  // 1 - z^2 without cancellation
  const float phi = 6.283185307f * u.y;
  return {r * std::cos(phi), r * std::sin(phi), 1.f - t};
}

Cone::Cone(const glm::vec3& axis, double halfAngleDeg) : axis_(axis) {
  all_ = halfAngleDeg >= 180.0;
  if (all_) {  // a point light: no trigonometry (built per shadow ray by pointLightIrradiance)
    versine_ = 2.0, sin2_ = 0.0, cos_ = -1.0, narrow_ = false;
    return;
  }
  const double a = halfAngleDeg * M_PI / 180.0;
  versine_ = 2.0 * std::sin(0.5 * a) * std::sin(0.5 * a);
  sin2_ = std::sin(a) * std::sin(a);
  cos_ = std::cos(a);
  narrow_ = halfAngleDeg <= 90.0;
}

bool Cone::contains(const glm::vec3& d) const {
  if (all_) return true;
  const glm::dvec3 a(d), &s = axis_;
  const double c = glm::dot(a, s), ll = glm::dot(a, a) * glm::dot(s, s);
  if (narrow_) {
    const glm::dvec3 x = glm::cross(a, s);
    return c > 0.0 && glm::dot(x, x) <= sin2_ * ll;
  }
  return c >= cos_ * std::sqrt(ll);
}

glm::vec2 uniformTriangle(glm::vec2 u) {
  // Heitz 2019, "A Low-Distortion Map Between Triangle and Square".
  float b0, b1;
  if (u.y > u.x) { b0 = u.x / 2.f; b1 = u.y - b0; }
  else { b1 = u.y / 2.f; b0 = u.x - b1; }
  return {b0, b1};
}

Frame::Frame(const glm::vec3& nn) : n(nn) {
  // Duff et al. 2017, "Building an Orthonormal Basis, Revisited".
  float sign = std::copysign(1.f, n.z);
  float a = -1.f / (sign + n.z);
  float k = n.x * n.y * a;
  t = {1.f + sign * n.x * n.x * a, sign * k, -sign * n.x};
  b = {k, sign + n.y * n.y * a, -n.y};
}

}  // namespace gi
