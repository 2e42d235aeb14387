// The scan-room scene of the radiosity scale benchmark (gi::scenes::scanRoom):
// its triangle count, the mesh properties the solvers rely on, determinism.
#include <gtest/gtest.h>

#include <cmath>

#include "gi/scan.h"
#include "gi/scenes.h"
#include "mesh_io.h"

namespace {

using gi::scenes::ScanOptions;
using gi::scenes::SceneFile;

const gi::Scene& bunny() {
  static const gi::Scene s = gi::io::loadMesh(std::string(GI_TEST_MESHES) + "/bunny.ply").scene;
  return s;
}

size_t scanFaces(size_t requested) {
  size_t n = bunny().faceCount();
  while (double(n) * 4 <= gi::scenes::kScanRoomScanShare * double(requested)) n *= 4;
  return n;
}

TEST(ScanRoom, TriangleCountWithinThreePercentOfTheRequest) {
  for (size_t want : {10000u, 40000u, 100000u}) {
    const SceneFile sf = gi::scenes::scanRoom(bunny(), want, ScanOptions{});
    const double n = double(sf.scene.faceCount());
    EXPECT_NEAR(n / double(want), 1.0, 0.03) << want;
    // The scan (the most subdivided that leaves the room its share) comes first.
    const size_t scan = scanFaces(want);
    EXPECT_LE(double(scan), gi::scenes::kScanRoomScanShare * double(want));
    for (size_t f = 0; f < scan; ++f) ASSERT_EQ(sf.scene.faceRho(f), glm::vec3(0.6f));
    EXPECT_NE(sf.scene.faceRho(scan), glm::vec3(0.6f));
  }
  EXPECT_THROW(gi::scenes::scanRoom(bunny(), 3000, ScanOptions{}), std::invalid_argument);
}

TEST(ScanRoom, NoDegenerateTrianglesEmittersMarkedRoomFacesInwards) {
  const SceneFile sf = gi::scenes::scanRoom(bunny(), 20000, ScanOptions{});
  const gi::Scene& s = sf.scene;
  const size_t scan = scanFaces(20000), nf = s.faceCount();
  ASSERT_EQ(sf.attrs.faceQuality.size(), nf);
  ASSERT_EQ(sf.attrs.faceColor.size(), nf);
  size_t emitters = 0;
  for (size_t f = 0; f < nf; ++f) {
    const glm::uvec3 t = s.triangles[f];
    const glm::dvec3 a = s.toWorld(s.positions[t.x]), b = s.toWorld(s.positions[t.y]), c = s.toWorld(s.positions[t.z]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    ASSERT_GT(glm::length(n), 1e-12) << "face " << f;  // the room is 3 x 2.5 x 3
    const bool emits = s.faceEmission(f) != glm::vec3(0.f);
    EXPECT_EQ(sf.attrs.faceQuality[f], emits ? 1.f : 0.f);
    if (emits) {
      ++emitters;
      EXPECT_GT(f, scan);
      EXPECT_NEAR(glm::normalize(n).y, -1.0, 1e-9);  // the ceiling light faces down
    }
    if (f < scan) continue;
    // Room faces are axis-aligned and face the interior (the room's centre
    // (0, 1.25, 0) is in front of each, strictly).
    const glm::dvec3 u = glm::normalize(n), centroid = (a + b + c) / 3.0;
    EXPECT_GT(glm::dot(u, glm::dvec3(0, 1.25, 0) - centroid), 0.4) << "face " << f;
    EXPECT_NEAR(std::fabs(u.x) + std::fabs(u.y) + std::fabs(u.z), 1.0, 1e-9) << "face " << f;
  }
  EXPECT_GE(emitters, 2u);
  EXPECT_LE(emitters, 200u);
  // The scan stands on the floor, inside the room, and keeps its outward
  // winding: its signed volume is positive.
  double lowest = 1e300, volume = 0;
  for (size_t f = 0; f < scan; ++f) {
    const glm::uvec3 t = s.triangles[f];
    const glm::dvec3 a = s.toWorld(s.positions[t.x]), b = s.toWorld(s.positions[t.y]), c = s.toWorld(s.positions[t.z]);
    lowest = std::min({lowest, a.y, b.y, c.y});
    volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    for (const glm::dvec3& p : {a, b, c}) {
      EXPECT_LE(std::fabs(p.x), 0.5 + 1e-9);
      EXPECT_LE(std::fabs(p.z), 0.5 + 1e-9);
      EXPECT_LE(p.y, 1.0 + 1e-3 + 1e-9);
    }
  }
  EXPECT_NEAR(lowest, 1e-3, 1e-6);
  EXPECT_GT(volume, 0.0);
  // The window: no face of the wall x = 1.5 covers the opening's centre.
  for (size_t f = scan; f < nf; ++f) {
    const glm::uvec3 t = s.triangles[f];
    const glm::dvec3 a = s.toWorld(s.positions[t.x]), b = s.toWorld(s.positions[t.y]), c = s.toWorld(s.positions[t.z]);
    if (std::fabs(a.x - 1.5) > 1e-9 || std::fabs(b.x - 1.5) > 1e-9 || std::fabs(c.x - 1.5) > 1e-9) continue;
    const glm::dvec3 lo = glm::min(a, glm::min(b, c)), hi = glm::max(a, glm::max(b, c));
    EXPECT_FALSE(lo.y < 1.3 && hi.y > 1.3 && lo.z < 0.0 && hi.z > 0.0) << "face " << f;
  }
}

TEST(ScanRoom, DeterministicForABaseAndSeed) {
  ScanOptions o;
  const SceneFile a = gi::scenes::scanRoom(bunny(), 15000, o), b = gi::scenes::scanRoom(bunny(), 15000, o);
  ASSERT_EQ(a.scene.vertexCount(), b.scene.vertexCount());
  ASSERT_EQ(a.scene.triangles, b.scene.triangles);
  for (size_t v = 0; v < a.scene.vertexCount(); ++v)
    ASSERT_EQ(a.scene.toWorld(a.scene.positions[v]), b.scene.toWorld(b.scene.positions[v]));
  o.seed = 2;
  const SceneFile c = gi::scenes::scanRoom(bunny(), 15000, o);
  ASSERT_EQ(c.scene.vertexCount(), a.scene.vertexCount());
  size_t moved = 0;
  for (size_t v = 0; v < a.scene.vertexCount(); ++v)
    moved += a.scene.toWorld(a.scene.positions[v]) != c.scene.toWorld(c.scene.positions[v]) ? 1 : 0;
  EXPECT_EQ(moved, bunny().vertexCount());  // another seed: every vertex of the scan moves, none of the room
}

}  // namespace
