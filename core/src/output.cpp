#include "gi/output.h"

#include <algorithm>
#include <cmath>

#include "gi/direct.h"
#include "gi/form_factors.h"

#include <cstdio>

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

FormFactorOutput formFactorOutput(const Scene& s, const FormFactorReport& rep, uint32_t face, uint64_t number) {
  FormFactorOutput o;
  o.faceF.assign(s.faceCount(), 0.f);
  float maxF = 0;
  for (size_t k = 0; k < rep.row.j.size(); ++k) {
    o.faceF[rep.row.j[k]] = rep.row.F[k];
    maxF = std::max(maxF, rep.row.F[k]);
  }
  std::vector<glm::vec3> f3(s.faceCount());
  for (size_t f = 0; f < f3.size(); ++f) f3[f] = glm::vec3(o.faceF[f]);
  for (const auto& v : faceToVertex(s, f3)) o.vertexF.push_back(v.x);
  o.faceColor.resize(s.faceCount());
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const auto g = uint8_t(std::lround(255.f * (maxF > 0 ? std::sqrt(o.faceF[f] / maxF) : 0.f)));
    o.faceColor[f] = f == face ? Rgb8{255, 0, 0} : Rgb8{g, g, g};
  }
  char b[256];
  std::snprintf(b, sizeof b,
                "GI: Form Factors of Selected Face: face %llu, %zu faces reached, row sum %.6f, lost %.6f, max F %.6g, "
                "reciprocity error max %.3g over the %d strongest receivers, %.3f s",
                (unsigned long long)(number == UINT64_MAX ? face : number), rep.row.j.size(), rep.rowSum, rep.escaped, double(maxF), rep.maxReciprocityError,
                rep.reciprocityChecked, rep.seconds);
  o.summary = b;
  return o;
}

}  // namespace gi
