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

#include "gi/ambient.h"
#include "gi/color.h"
#include "gi/pathtrace.h"
#include "gi/raycaster.h"
#include "gi/scene.h"

using namespace gi;

namespace {

constexpr double kPi = 3.14159265358979323846;

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

namespace {

// A flat sheet (z = 0, facing up) around a vertex at the origin: the wedge
// from angle 0 to `span` cut into triangles at the given angles, out to
// radius 1; the vertex is index 0.
Scene wedge(const std::vector<double>& cuts) {
  std::vector<glm::dvec3> p = {{0, 0, 0}};
  for (double a : cuts) p.push_back({std::cos(a), std::sin(a), 0.0});
  std::vector<glm::uvec3> t;
  for (uint32_t k = 1; k + 1 < p.size(); ++k) t.push_back({0, k, k + 1});
  return Scene::fromAbsolute(p, t);
}

// Vertex 0's ray origin less its position (local units: the scenes here are of unit size).
glm::vec3 originOfVertex0(const Scene& s, float eps) {
  return vertexRayOrigins(s, vertexNormalsForRays(s), eps)[0] - s.positions[0];
}

}  // namespace

// The pull follows the wedge the faces span, not its triangles: a straight
// border (180 degrees) cut into 2 triangles or into 12 with slivers of 0.01
// degree along the border, and an L-shaped room's inner corner (270
// degrees) cut into 6 triangles two ways, give the same origin. The mean
// of the directions to the faces' centroids did not: thin triangles along
// a border cancelled each other (the origin sat on a wall standing there:
// a crease vertex read 0.09 for 0.33), and one fan of the L's corner
// pointed into the block (0.0035 for 0.020; an outside audit).
TEST(RayOrigins, TheWedgeNotItsTrianglesSetsThePull) {
  const double d = kPi / 180;
  const float eps = 1e-3f;
  const glm::vec3 border2 = originOfVertex0(wedge({0, 90 * d, 180 * d}), eps);
  const glm::vec3 border12 = originOfVertex0(
      wedge({0, 0.01 * d, 0.02 * d, 30 * d, 60 * d, 90 * d, 100 * d, 150 * d, 179.97 * d, 179.98 * d, 179.99 * d, 180 * d}), eps);
  EXPECT_NEAR(glm::length(border2 - border12), 0.f, 1e-4f * eps);
  EXPECT_NEAR(border2.y, 2 * eps, 1e-4f * eps);  // 2 eps into the sheet, eps up
  EXPECT_NEAR(border2.z, eps, 1e-4f * eps);
  const glm::vec3 lA = originOfVertex0(wedge({0, 45 * d, 90 * d, 135 * d, 180 * d, 225 * d, 270 * d}), eps);
  const glm::vec3 lB = originOfVertex0(wedge({0, 26.6 * d, 90 * d, 153.4 * d, 180 * d, 243.4 * d, 270 * d}), eps);
  EXPECT_NEAR(glm::length(lA - lB), 0.f, 1e-4f * eps);
  // Towards the wedge's middle (135 degrees), away from the block (315 degrees): 2 eps.
  EXPECT_NEAR(lA.x, -std::sqrt(2.f) * eps, 1e-4f * eps);
  EXPECT_NEAR(lA.y, std::sqrt(2.f) * eps, 1e-4f * eps);
}

// A floor vertex where a separate sheet meets the floor at 30 degrees: the
// cosine-weighted directions between the two, (1 - cos 30) / 2 = 0.0670,
// with the floor cut into slivers along the crease (4,096 rays, 4 standard
// errors). With the pull at 45 degrees above the floor the origin lay
// behind the other sheet and read 0.93 (an outside audit).
TEST(RayOrigins, SeparateSheetsMeetingAtANarrowCrease) {
  const double d = kPi / 180;
  // Floor: the wedge around the vertex from 0 to 180 degrees (x > 0 side
  // is y > 0 here), slivers by the crease line (the x axis).
  Scene s = wedge({0, 0.02 * d, 0.05 * d, 45 * d, 90 * d, 135 * d, 179.95 * d, 179.98 * d, 180 * d});
  // The other sheet: through the x axis, rising at 30 degrees over y > 0,
  // facing down towards the floor, from x = -1 to 1 and out to 1.
  std::vector<glm::dvec3> p;
  for (const glm::vec3& q : s.positions) p.push_back(s.toWorld(q));
  const uint32_t k = uint32_t(p.size());
  const double c = std::cos(30 * d), sn = std::sin(30 * d);
  p.push_back({-1, 0, 0}), p.push_back({1, 0, 0}), p.push_back({1, c, sn}), p.push_back({-1, c, sn});
  std::vector<glm::uvec3> t = s.triangles;
  t.push_back({k, k + 2, k + 1}), t.push_back({k, k + 3, k + 2});  // facing down (towards the floor)
  const Scene both = Scene::fromAbsolute(p, t);
  ASSERT_LT(glm::dot(faceNormalUnnormalized(both, both.faceCount() - 1), glm::vec3(0, 0, 1)), 0.f);
  auto caster = makeEmbreeCaster(both);
  AmbientOptions o;
  o.raysPerVertex = 4096;
  const AmbientResult r = computeAmbient(both, *caster, o);
  const double exact = (1 - c) / 2;
  EXPECT_NEAR(r.value[0], exact, 4 * r.stdError[0]);
}
