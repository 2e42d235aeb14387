// The filters whose result is pictures (filter_run.cpp's steps call them):
// the form factors and the hemicube of one face, the ray-traced view; and
// the attribute helpers every step shares.
#pragma once
#include <string>
#include <vector>

#include "gi/filter_run.h"

namespace gi::detail {

inline VertexAttribute scalarAttribute(const std::string& name, const std::vector<float>& v) { return {name, 1, v}; }
// Beside a lighting filter's Radiosity: 1 where it holds caustics (photon
// mapping, the reference), 0 where not (radiosity); the two-pass view reads
// it to know whether to take the first pass's caustics out.
inline VertexAttribute firstPassCausticsAttribute(size_t nv, bool caustics) {
  return scalarAttribute("RadiosityCaustics", std::vector<float>(nv, caustics ? 1.f : 0.f));
}

inline VertexAttribute vectorAttribute(const std::string& name, const std::vector<glm::vec3>& v) {
  VertexAttribute a{name, 3, {}};
  a.values.reserve(v.size() * 3);
  for (const glm::vec3& x : v) a.values.insert(a.values.end(), {x.x, x.y, x.z});
  return a;
}

void runFormFactors(FilterInput& in, FilterResult& res);
void runHemicube(FilterInput& in, FilterResult& res);
void runRender(FilterInput& in, FilterResult& res, const Progress& progress);

}  // namespace gi::detail
