#include "gi/color.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace gi {

float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
float linearToSrgb(float c) {
  c = std::clamp(c, 0.f, 1.f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f;
}
glm::vec3 srgb8ToLinear(uint8_t r, uint8_t g, uint8_t b) {
  return {srgbToLinear(r / 255.f), srgbToLinear(g / 255.f), srgbToLinear(b / 255.f)};
}

Rgb8 displayMap(const glm::vec3& linear, float exposure) {
  glm::vec3 c = linear * exposure;
  for (int k = 0; k < 3; ++k)
    if (!(c[k] > 0.f)) c[k] = 0.f;  // negatives and NaN to black
  float m = std::max({c.r, c.g, c.b});
  if (m > 1.f) c /= m;
  auto q = [](float v) { return uint8_t(std::lround(linearToSrgb(v) * 255.f)); };
  return {q(c.r), q(c.g), q(c.b)};
}

float autoExposure(const float* lum, size_t n, float percentile) {
  std::vector<float> v;
  v.reserve(n);
  for (size_t i = 0; i < n; ++i)
    if (std::isfinite(lum[i]) && lum[i] > 0.f) v.push_back(lum[i]);
  if (v.empty()) return 1.f;
  size_t k = std::min(v.size() - 1, size_t(percentile * float(v.size() - 1) + 0.5f));
  std::nth_element(v.begin(), v.begin() + long(k), v.end());
  return v[k] > 0.f ? 1.f / v[k] : 1.f;
}

}  // namespace gi
