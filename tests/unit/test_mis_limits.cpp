// Multiple importance sampling at the ends of its densities (an outside
// audit, 6 December 2026): a vertex on an emitter's own plane (the foot of
// a two-sided emitting panel welded to a floor) saw the emitter at a cosine
// of about 0, its light sample's density was infinite, and the power
// heuristic's inf / inf made the reference's value NaN (written as 0 with
// an error bar of 0).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "gi/emitters.h"
#include "gi/pathtrace.h"

using namespace gi;

TEST(MisLimits, PowerHeuristicAtInfiniteAndZeroDensities) {
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(powerHeuristic(1.f, 1.f), 0.5f);
  EXPECT_EQ(powerHeuristic(3.f, 4.f), 9.f / 25.f);  // the same bits as a^2 / (a^2 + b^2)
  EXPECT_EQ(powerHeuristic(inf, 1.f), 1.f);
  EXPECT_EQ(powerHeuristic(1.f, inf), 0.f);
  EXPECT_EQ(powerHeuristic(inf, inf), 0.5f);
  EXPECT_EQ(powerHeuristic(0.f, 0.f), 0.f);
  EXPECT_EQ(powerHeuristic(0.f, 2.f), 0.f);
  EXPECT_NEAR(powerHeuristic(1e30f, 1e30f), 0.5f, 1e-6f);  // squares overflow
  EXPECT_NEAR(powerHeuristic(1.5e19f, 1.5e19f), 0.5f, 1e-6f);  // only their sum does
  EXPECT_NEAR(powerHeuristic(2e30f, 1e30f), 0.8f, 1e-6f);
}

namespace {

// Welded vertices by exact position.
struct Welded {
  std::vector<glm::dvec3> P;
  std::vector<glm::uvec3> T;
  uint32_t at(const glm::dvec3& p) {
    for (size_t i = 0; i < P.size(); ++i)
      if (P[i] == p) return uint32_t(i);
    P.push_back(p);
    return uint32_t(P.size() - 1);
  }
  // Quad p0 p1 p2 p3 (counter-clockwise from its front) as n x n cells.
  void quad(glm::dvec3 p0, glm::dvec3 p1, glm::dvec3 p2, glm::dvec3 p3, int n) {
    auto pt = [&](int i, int j) {
      const double u = double(i) / n, v = double(j) / n;
      return at((1 - u) * (1 - v) * p0 + u * (1 - v) * p1 + u * v * p2 + (1 - u) * v * p3);
    };
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const uint32_t a = pt(i, j), b = pt(i + 1, j), c = pt(i + 1, j + 1), d = pt(i, j + 1);
        T.push_back({a, b, c});
        T.push_back({a, c, d});
      }
  }
};

}  // namespace

// A closed room 1 x 1 x 1 (faces inward, 4 x 4 cells, rho 0.5) with a
// two-sided emitting panel (each face with a reversed copy, E = 10) standing
// on its floor in the plane x = 0.5, welded to the floor's vertices: the
// vertex at the middle of its foot read NaN in the reference. Every vertex's
// value and error bar are finite now, the foot's bar above 0.
TEST(MisLimits, VertexOnAnEmittersPlaneIsFinite) {
  Welded w;
  w.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, 4);  // floor, up
  w.quad({0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}, 4);  // ceiling
  w.quad({0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}, 4);
  w.quad({1, 0, 0}, {1, 0, 1}, {1, 1, 1}, {1, 1, 0}, 4);
  w.quad({0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, 4);
  w.quad({0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}, 4);
  const size_t roomFaces = w.T.size();
  w.quad({0.5, 0.25, 0}, {0.5, 0.75, 0}, {0.5, 0.75, 0.5}, {0.5, 0.25, 0.5}, 2);
  const size_t panelEnd = w.T.size();
  for (size_t f = roomFaces; f < panelEnd; ++f) w.T.push_back({w.T[f].x, w.T[f].z, w.T[f].y});
  Scene s = Scene::fromAbsolute(w.P, w.T);
  s.rho.assign(w.T.size(), glm::vec3(0.5f));
  s.emission.assign(w.T.size(), glm::vec3(0.f));
  for (size_t f = roomFaces; f < w.T.size(); ++f) s.emission[f] = glm::vec3(10.f);
  const uint32_t foot = w.at({0.5, 0.5, 0});
  ASSERT_LT(foot, s.vertexCount());
  auto caster = makeEmbreeCaster(s);
  PathTraceOptions o;
  o.samplesPerVertex = 64;
  const PathTraceResult r = pathTrace(s, *caster, o);
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    EXPECT_TRUE(std::isfinite(r.B[v].x) && std::isfinite(r.B[v].y) && std::isfinite(r.B[v].z)) << "vertex " << v;
    EXPECT_TRUE(std::isfinite(r.stdError[v])) << "vertex " << v;
  }
  EXPECT_GT(r.stdError[foot], 0.f);
}
