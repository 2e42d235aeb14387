#include "gi/output.h"

#include <algorithm>
#include <cmath>

#include "gi/direct.h"

namespace gi {

VertexOutput radiometricOutput(const Scene& s, const std::vector<glm::vec3>& rgb, double exposureParam) {
  VertexOutput o;
  o.rgb = rgb;
  o.quality.resize(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) o.quality[i] = luminance(rgb[i]);
  if (exposureParam > 0) {
    o.exposure = float(exposureParam);
    return o;
  }
  const VertexMaterial m = vertexMaterial(s);
  std::vector<float> lit;
  lit.reserve(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i)
    if (i >= m.E.size() || luminance(m.E[i]) <= 0.f) lit.push_back(o.quality[i]);
  o.exposure = lit.empty() ? autoExposure(o.quality.data(), o.quality.size()) : autoExposure(lit.data(), lit.size());
  return o;
}

std::vector<Rgb8> greyColors(const std::vector<float>& value) {
  std::vector<Rgb8> c(value.size());
  for (size_t i = 0; i < value.size(); ++i) {
    const float v = std::isfinite(value[i]) ? std::clamp(value[i], 0.f, 1.f) : 0.f;
    const auto b = uint8_t(std::lround(v * 255.f));
    c[i] = {b, b, b};
  }
  return c;
}

}  // namespace gi
