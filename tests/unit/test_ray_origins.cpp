// Where a vertex's rays start (vertexRayOrigins): eps along its normal, and
// at a lopsided one-ring pulled by eps into its faces, but never behind one
// of its own faces.
//
// An outside audit found the inner corner of a closed box whose floor is a
// fan of six or more triangles from that corner reading 0 in the path-traced
// reference (4,096 paths) and the direct light alone in radiosity and photon
// mapping, where a floor of four triangles read 0.1330: the floor's faces
// outnumbered the walls' in the pull, which tipped the origin down through
// the floor, and every path started outside the box.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gi/color.h"
#include "gi/pathtrace.h"
#include "gi/raycaster.h"
#include "gi/scene.h"

using namespace gi;

namespace {

// The unit box seen from inside: walls of two triangles, the ceiling (z = 1)
// emitting E = 1, the floor a fan of `fan` triangles from its corner at the
// origin to points along its two far edges; rho 0.5.
Scene boxWithFanFloor(int fan) {
  std::vector<glm::dvec3> p = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                               {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  std::vector<glm::uvec3> t;
  std::vector<glm::vec3> E;
  // A rectangle's two triangles, turned to face `inward`.
  auto quad = [&](uint32_t a, uint32_t b, uint32_t c, uint32_t d, glm::dvec3 inward, float e) {
    const bool turn = glm::dot(glm::cross(p[b] - p[a], p[c] - p[a]), inward) > 0;
    t.push_back(turn ? glm::uvec3(a, b, c) : glm::uvec3(a, c, b));
    t.push_back(turn ? glm::uvec3(a, c, d) : glm::uvec3(a, d, c));
    E.push_back(glm::vec3(e)), E.push_back(glm::vec3(e));
  };
  quad(4, 5, 6, 7, {0, 0, -1}, 1.f);  // ceiling
  quad(0, 1, 5, 4, {0, 1, 0}, 0.f);   // y = 0
  quad(1, 2, 6, 5, {-1, 0, 0}, 0.f);  // x = 1
  quad(2, 3, 7, 6, {0, -1, 0}, 0.f);  // y = 1
  quad(3, 0, 4, 7, {1, 0, 0}, 0.f);   // x = 0
  // The floor's rim from (1, 0) by (1, 1) to (0, 1), `fan` segments.
  std::vector<uint32_t> rim;
  for (int k = 0; k <= fan; ++k) {
    const double u = 2.0 * k / fan;  // 0..2 along the two edges
    if (k == 0) rim.push_back(1);
    else if (k == fan) rim.push_back(3);
    else if (u == 1.0) rim.push_back(2);
    else {
      p.push_back(u < 1.0 ? glm::dvec3(1, u, 0) : glm::dvec3(2 - u, 1, 0));
      rim.push_back(uint32_t(p.size() - 1));
    }
  }
  for (int k = 0; k < fan; ++k) {
    t.push_back({0, rim[size_t(k)], rim[size_t(k) + 1]});  // counter-clockwise from above: facing up
    E.push_back(glm::vec3(0.f));
  }
  Scene s = Scene::fromAbsolute(p, t);
  s.emission = E;
  s.rho.assign(s.faceCount(), glm::vec3(0.5f));
  return s;
}

}  // namespace

// Every vertex's origin lies in front of each of its faces' planes, with at
// least half the clearance its normal alone gives, whatever the fan.
TEST(RayOrigins, NeverBehindTheVertexsOwnFaces) {
  for (int fan : {2, 4, 6, 8, 12, 24}) {
    const Scene s = boxWithFanFloor(fan);
    const std::vector<glm::vec3> n = vertexNormalsForRays(s);
    const float eps = 1e-3f;
    const std::vector<glm::vec3> o = vertexRayOrigins(s, n, eps);
    for (size_t f = 0; f < s.faceCount(); ++f) {
      const glm::vec3 m = glm::normalize(faceNormalUnnormalized(s, f));
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = s.triangles[f][k];
        const float clearance = glm::dot(o[v] - s.positions[v], m) / eps;
        EXPECT_GE(clearance, 0.5f * glm::dot(n[v], m) - 1e-4f) << "fan " << fan << ", vertex " << v << ", face " << f;
        EXPECT_GT(clearance, 0.f) << "fan " << fan << ", vertex " << v << ", face " << f;
      }
    }
  }
}

// The corner's radiosity does not depend on how the floor is cut: fans of 6
// and 12 triangles against the fan of 2 (each 4,096 paths; within 4
// standard errors of the difference). The old origins read 0 at 6.
TEST(RayOrigins, BoxCornerOverAFanFloor) {
  PathTraceOptions o;
  o.samplesPerVertex = 4096;
  auto corner = [&](int fan, float& se) {
    const Scene s = boxWithFanFloor(fan);
    auto caster = makeEmbreeCaster(s);
    const PathTraceResult r = pathTrace(s, *caster, o);
    se = r.stdError[0];
    return luminance(r.B[0]);
  };
  float se2 = 0, se = 0;
  const float b2 = corner(2, se2);
  ASSERT_GT(b2, 0.05f);
  for (int fan : {6, 12}) {
    const float b = corner(fan, se);
    EXPECT_NEAR(b, b2, 4.f * std::sqrt(se * se + se2 * se2)) << "fan " << fan;
  }
}
