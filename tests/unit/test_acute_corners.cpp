// Rays leaving a surface point a ray hit start lifted along the face's
// normal unless, near a corner, a surface lies between that point and the
// free segment the ray came along (hit_origin.h): a hit within a few ray
// offsets of an acute corner or edge, lifted along its normal, started its
// light samples and its next bounce past the neighbouring face. An outside audit found a closed tetrahedron with
// inward normals, lit by a sky outside it, reading up to 0.15 in its three
// acute corners in the path-traced reference (0 at max_depth 0: the
// vertex's own rays were right, the bounces' were not) and 0.13 in photon
// mapping (its gather rays at the creases), where ambient occlusion and sky
// lighting read 0. No light can enter a closed surface: every vertex must
// read exactly 0, whatever the samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "filter_input.h"
#include "gi/filter_run.h"
#include "gi/filters.h"

using namespace gi;

namespace {

// A regular tetrahedron (edge 2 sqrt 2), each face a grid of n^2 triangles
// facing inward, the vertices welded.
scenes::SceneFile closedTetrahedron(int n) {
  const glm::dvec3 P[4] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  const int F[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  std::vector<glm::dvec3> pts;
  std::vector<glm::uvec3> tris;
  std::map<std::tuple<long, long, long>, uint32_t> weld;
  auto vertex = [&](const glm::dvec3& p) {
    const auto key = std::make_tuple(std::lround(p.x * 1e6), std::lround(p.y * 1e6), std::lround(p.z * 1e6));
    auto [it, fresh] = weld.emplace(key, uint32_t(pts.size()));
    if (fresh) pts.push_back(p);
    return it->second;
  };
  for (const auto& f : F) {
    glm::dvec3 a = P[f[0]], b = P[f[1]], c = P[f[2]];
    if (glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0) > 0) std::swap(b, c);  // inward
    std::map<std::pair<int, int>, uint32_t> id;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n - i; ++j)
        id[{i, j}] = vertex((double(i) * a + double(j) * b + double(n - i - j) * c) / double(n));
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n - i; ++j) {
        tris.push_back({id[{i, j}], id[{i + 1, j}], id[{i, j + 1}]});
        if (i + j < n - 1) tris.push_back({id[{i + 1, j}], id[{i + 1, j + 1}], id[{i, j + 1}]});
      }
  }
  scenes::SceneFile sf;
  sf.scene = Scene::fromAbsolute(pts, tris);
  return sf;
}

}  // namespace

// The sky (1 W/m^2) outside a closed tetrahedron of 8 x 8 triangles a face:
// the reference at max_depth 1 and without a limit (1,024 paths a vertex;
// the old origins read up to 0.031 at the corners with them) and photon
// mapping with and without final gather: 0 at every vertex.
TEST(AcuteCorners, NoSkyEntersAClosedTetrahedron) {
  const scenes::SceneFile sf = closedTetrahedron(8);
  ASSERT_EQ(sf.scene.vertexCount(), 130u);
  struct Case {
    FilterKind kind;
    std::vector<std::pair<std::string, std::string>> values;
  };
  const std::vector<Case> cases = {
      {FilterKind::PathTracedReference, {{"samples_per_vertex", "1024"}, {"max_depth", "1"}}},
      {FilterKind::PathTracedReference, {{"samples_per_vertex", "1024"}}},
      {FilterKind::PhotonMapping, {}},
      {FilterKind::PhotonMapping, {{"final_gather", "true"}}},
  };
  for (const Case& c : cases) {
    FilterInput in = test::filterInput(c.kind, sf);
    const auto specs = filterSpecs(c.kind);
    const double diag = analyzeScene(in.scene).diagonal;
    std::vector<std::pair<std::string, std::string>> v = {{"emitter_source", "None"}, {"sky_irradiance", "1"}};
    v.insert(v.end(), c.values.begin(), c.values.end());
    std::string name = filterDesc(c.kind).cliName;
    for (const auto& [k, val] : v) {
      in.values.set(k, parseValue(*findSpec(specs, k), val, diag));
      name += " --" + k + " " + val;
    }
    const FilterResult r = runFilter(c.kind, in);
    ASSERT_EQ(r.vertexQuality.size(), sf.scene.vertexCount()) << name;
    size_t lit = 0;
    float most = 0.f;
    for (const float q : r.vertexQuality) {
      lit += q != 0.f;
      most = std::max(most, q);
    }
    std::printf("%s: %zu of %zu vertices lit, at most %g\n", name.c_str(), lit, r.vertexQuality.size(), double(most));
    EXPECT_EQ(lit, 0u) << name << ": at most " << most;
  }
}
