// Small helpers shared by the engine tests.
#pragma once
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <array>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/color.h"
#include "gi/scene.h"

namespace gi::test {

// Appends an nx x ny grid of quads (two triangles each, vertices of its
// own) spanned by p0 + u s + v t, counter-clockwise seen from the side
// u x v points to.
inline void addGrid(std::vector<glm::dvec3>& pts, std::vector<glm::uvec3>& tris, glm::dvec3 p0, glm::dvec3 u,
                    glm::dvec3 v, int nx, int ny) {
  const uint32_t base = uint32_t(pts.size());
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) pts.push_back(p0 + u * (double(i) / nx) + v * (double(j) / ny));
  auto id = [&](int i, int j) { return base + uint32_t(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
}

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

// A radiosity result's face f as the mean over the whole face (luminance):
// B is the radiosity of the part the scene sees, and a buried part (under
// a block) has none (gi/patch_seen.h). What a path tracer's vertices
// average to over the face.
template <class RadiosityResult>
double wholePatchMean(const RadiosityResult& r, size_t f) {
  return double(luminance(r.B[f])) * (r.seenShare.empty() ? 1.0 : double(r.seenShare[f]));
}

inline double rms(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += double(a[i] - b[i]) * double(a[i] - b[i]);
  return std::sqrt(s / double(a.size()));
}

// 1 for vertices on a mesh border (an edge used by one face).
inline std::vector<uint8_t> borderVertices(const Scene& s) {
  std::map<std::pair<uint32_t, uint32_t>, int> edgeUse;
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) ++edgeUse[std::minmax(t[k], t[(k + 1) % 3])];
  std::vector<uint8_t> border(s.vertexCount(), 0);
  for (const auto& [e, n] : edgeUse)
    if (n == 1) border[e.first] = border[e.second] = 1;
  return border;
}

// Walls of a box scene: faces grouped by (normal, reflectance), skipping
// emitters and faces touching a mesh border (creases, the rim of a light,
// where per-vertex values and patch averages legitimately differ). Per
// group: area and the area-weighted sums of two per-face values a and b.
inline std::map<std::string, std::array<double, 3>> wallSums(const Scene& s, const std::function<double(size_t)>& a,
                                                              const std::function<double(size_t)>& b) {
  const std::vector<uint8_t> border = borderVertices(s);
  std::map<std::string, std::array<double, 3>> groups;
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const auto& t = s.triangles[f];
    if (s.faceEmission(f).r > 0 || border[t.x] || border[t.y] || border[t.z]) continue;
    const glm::vec3 n = glm::normalize(faceNormalUnnormalized(s, f));
    const std::string key = std::to_string(int(std::lround(n.x * 10))) + "," + std::to_string(int(std::lround(n.y * 10))) +
                            "," + std::to_string(int(std::lround(n.z * 10))) + "," +
                            std::to_string(int(s.faceRho(f).r * 100));
    const double area = faceArea(s, f);
    auto& g = groups[key];
    g[0] += area;
    g[1] += area * a(f);
    g[2] += area * b(f);
  }
  return groups;
}

// A scene's points (world units) and its triangles each followed, after
// all of them, by a reversed copy: a two-sided surface, whose vertices have
// no normal (the faces' normals cancel).
struct TwoSidedMesh {
  std::vector<glm::dvec3> pts;
  std::vector<glm::uvec3> tris;  // the originals first, then their copies
};
inline TwoSidedMesh twoSided(const Scene& one) {
  TwoSidedMesh m;
  for (const auto& p : one.positions) m.pts.push_back(one.toWorld(p));
  m.tris = one.triangles;
  for (const glm::uvec3& t : one.triangles) m.tris.push_back({t.x, t.z, t.y});
  return m;
}

// Adaptive runs whose counts a pilot sized (gi/sampling.h, kPilotMargin):
// the quantiles of each vertex's reported error over its target.
struct OverTarget {
  double median = 0, p90 = 0, p99 = 0, largest = 0;
  size_t above = 0;  // ratios above 1
};
inline OverTarget overTarget(std::vector<double> ratio) {
  OverTarget o;
  if (ratio.empty()) return o;
  std::sort(ratio.begin(), ratio.end());
  const size_t n = ratio.size();
  o.median = ratio[n / 2];
  o.p90 = ratio[n * 9 / 10];
  o.p99 = ratio[n * 99 / 100];
  o.largest = ratio.back();
  o.above = size_t(ratio.end() - std::upper_bound(ratio.begin(), ratio.end(), 1.0));
  std::printf("reported error over the target: median %.3f, 90th percentile %.3f, 99th %.3f, largest %.3f; %zu of %zu "
              "above\n", o.median, o.p90, o.p99, o.largest, o.above, n);
  return o;
}

}  // namespace gi::test
