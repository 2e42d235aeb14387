// Files appended as layers (the CLI's --layer) share one frame, the one
// MeshLab's layers get: each file coordinate rounded to float once, about
// the centre of the whole scene's box (Scene::fromAbsolute of every point).
// Appending kept the first file's centre and rounded the others' floats
// again, one float step off (photon paths through a glass sphere flipped
// against the same layers in meshlabserver; an outside audit).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "gi/scene.h"
#include "mesh_io.h"

namespace {

std::string obj(const std::vector<glm::dvec3>& p) {
  char b[160];
  std::string s;
  for (const auto& x : p) {
    std::snprintf(b, sizeof b, "v %.17g %.17g %.17g\n", x.x, x.y, x.z);
    s += b;
  }
  return s + "f 1 2 3\nf 1 3 4\n";
}

// The same quad as an ASCII PLY with a normal per vertex.
std::string plyWithNormals(const std::vector<glm::dvec3>& p) {
  std::string s = "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
                  "property float nx\nproperty float ny\nproperty float nz\nelement face 2\n"
                  "property list uchar int vertex_indices\nend_header\n";
  char b[160];
  for (const auto& x : p) {
    std::snprintf(b, sizeof b, "%.17g %.17g %.17g 0 0 1\n", x.x, x.y, x.z);
    s += b;
  }
  return s + "3 0 1 2\n3 0 2 3\n";
}

TEST(LayerFrame, AppendedFilesShareTheWholeScenesFrame) {
  // A room's floor and a block reaching a little below it (as the caustic
  // Cornell box's glossy block does), at coordinates with many digits.
  const std::vector<glm::dvec3> floor = {{0.1, 6.1e-6, 0.3}, {556.3, 6.1e-6, 0.3}, {556.3, 548.7, 559.1},
                                         {0.1, 548.7, 559.1}};
  const std::vector<glm::dvec3> block = {{130.7, 1.4e-14, 65.1}, {82.3, 165.2, 225.3}, {240.1, 165.2, 272.9},
                                         {290.3, 0.7, 114.6}};
  gi::io::LoadedMesh both = gi::io::parseMesh(obj(floor), "obj", "floor.obj");
  gi::io::appendMesh(both, gi::io::parseMesh(obj(block), "obj", "block.obj"));
  std::vector<glm::dvec3> all = floor;
  all.insert(all.end(), block.begin(), block.end());
  const gi::Scene once = gi::Scene::fromAbsolute(all, both.scene.triangles);
  EXPECT_EQ(both.scene.origin, once.origin);
  EXPECT_EQ(both.scene.unit, once.unit);
  ASSERT_EQ(both.scene.positions.size(), once.positions.size());
  for (size_t i = 0; i < all.size(); ++i) EXPECT_EQ(both.scene.positions[i], once.positions[i]) << i;
  EXPECT_EQ(both.points, all);
}

TEST(LayerFrame, DeferredReframingGivesTheSameScene) {
  // The CLI appends its --layer files with the frame deferred to one
  // rebuild after the last (a rebuild per file costs the square of their
  // count): the scene must be the same bits as rebuilding at every file.
  const std::vector<std::vector<glm::dvec3>> parts = {
      {{0.1, 6.1e-6, 0.3}, {556.3, 6.1e-6, 0.3}, {556.3, 548.7, 559.1}, {0.1, 548.7, 559.1}},
      {{130.7, 1.4e-14, 65.1}, {82.3, 165.2, 225.3}, {240.1, 165.2, 272.9}, {290.3, 0.7, 114.6}},
      {{-12.5, 600.25, 3.3}, {-1.75, 600.25, 3.3}, {-1.75, 611.0, 9.1}, {-12.5, 611.0, 9.1}}};
  gi::io::LoadedMesh now = gi::io::parseMesh(obj(parts[0]), "obj", "p0.obj");
  gi::io::LoadedMesh later = now;
  for (size_t k = 1; k < parts.size(); ++k) {
    // The second part carries normals (a PLY's): the first's, missing, are
    // computed from its faces, in the frame either way gives.
    const gi::io::LoadedMesh part = k == 1 ? gi::io::parseMesh(plyWithNormals(parts[k]), "ply", "p1.ply")
                                           : gi::io::parseMesh(obj(parts[k]), "obj", "p" + std::to_string(k) + ".obj");
    ASSERT_EQ(part.scene.vertexNormals.empty(), k != 1);
    gi::io::appendMesh(now, part);
    gi::io::appendMesh(later, part, gi::io::Reframing::Deferred);
  }
  gi::io::reframe(later);
  EXPECT_EQ(later.scene.origin, now.scene.origin);
  EXPECT_EQ(later.scene.unit, now.scene.unit);
  EXPECT_EQ(later.scene.positions, now.scene.positions);
  EXPECT_EQ(later.scene.triangles, now.scene.triangles);
  EXPECT_EQ(later.points, now.points);
  EXPECT_FALSE(now.scene.vertexNormals.empty());
  EXPECT_EQ(later.scene.vertexNormals, now.scene.vertexNormals);
  // And both are the frame of all the files' coordinates at once.
  std::vector<glm::dvec3> all;
  for (const auto& p : parts) all.insert(all.end(), p.begin(), p.end());
  const gi::Scene once = gi::Scene::fromAbsolute(all, now.scene.triangles);
  EXPECT_EQ(later.scene.origin, once.origin);
  EXPECT_EQ(later.scene.positions, once.positions);
}

}  // namespace
