// Small helpers shared by the engine tests.
#pragma once
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi::test {

// Index of the vertex nearest to p (local coordinates), among those accepted by `keep`.
inline size_t nearestVertex(const Scene& s, const glm::dvec3& pWorld,
                            const std::function<bool(size_t)>& keep = nullptr) {
  size_t best = 0;
  double bd = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    if (keep && !keep(i)) continue;
    const double d = glm::length(s.toWorld(s.positions[i]) - pWorld);
    if (d < bd) { bd = d; best = i; }
  }
  return best;
}

// Applies x -> x * scale + offset to every vertex, in double, and re-centres.
inline Scene transformed(const Scene& s, double scale, const glm::dvec3& offset) {
  std::vector<glm::dvec3> pts;
  for (const auto& p : s.positions) pts.push_back(s.toWorld(p) * scale + offset);
  Scene t = Scene::fromAbsolute(pts, s.triangles);
  t.rho = s.rho; t.emission = s.emission; t.material = s.material;
  return t;
}

inline double rms(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += double(a[i] - b[i]) * double(a[i] - b[i]);
  return std::sqrt(s / double(a.size()));
}

}  // namespace gi::test
