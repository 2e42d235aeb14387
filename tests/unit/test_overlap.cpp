// Faces that overlap in one plane, facing the same way, where one of them
// emits (an outside audit, 6 December 2026: a ceiling lamp listed as 2
// triangles and again as 8 doubled every value, in radiosity and in the
// reference, without a word; copies with the same corners were already left
// out). The lighting filters' set-up warns of them, and only of them.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "filter_input.h"
#include "gi/filter_run.h"
#include "gi/filters.h"

using namespace gi;

namespace {

struct Builder {
  std::vector<glm::dvec3> pts;
  std::vector<glm::uvec3> tris;
  std::vector<float> quality;  // > 0.5: emits
  // Quad a b c d (counter-clockwise from its front) as n x n cells of two triangles.
  void quad(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d, int n, bool emits) {
    const uint32_t base = uint32_t(pts.size());
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const double u = double(i) / n, v = double(j) / n;
        pts.push_back((1 - u) * (1 - v) * a + u * (1 - v) * b + u * v * c + (1 - u) * v * d);
      }
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const uint32_t p = base + uint32_t(j * (n + 1) + i), q = p + 1, r = p + uint32_t(n) + 2, t = p + uint32_t(n) + 1;
        tris.push_back({p, q, r});
        tris.push_back({p, r, t});
        quality.insert(quality.end(), 2, emits ? 1.f : 0.f);
      }
  }
  scenes::SceneFile file() const {
    scenes::SceneFile sf;
    sf.scene = Scene::fromAbsolute(pts, tris);
    sf.attrs.faceQuality = quality;
    return sf;
  }
};

// A floor (y = 0, facing up) and a ceiling (y = 1, facing down) 2 wide, a
// lamp 0.6 wide facing down at height `lamp`.
Builder room(double lamp) {
  Builder b;
  b.quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 4, false);
  b.quad({-1, 1, -1}, {1, 1, -1}, {1, 1, 1}, {-1, 1, 1}, 4, false);
  b.quad({-0.3, lamp, -0.3}, {0.3, lamp, -0.3}, {0.3, lamp, 0.3}, {-0.3, lamp, 0.3}, 1, true);
  return b;
}

bool warnsOfOverlap(const Builder& b) {
  FilterInput in = test::filterInput(FilterKind::PathTracedReference, b.file());
  in.values.set("samples_per_vertex", 2);
  const FilterResult r = runFilter(FilterKind::PathTracedReference, in);
  for (const std::string& w : r.stats.warnings)
    if (w.find("lie on another face in the same plane") != std::string::npos) return true;
  return false;
}

}  // namespace

TEST(Overlap, EmittersOverlappingInOnePlaneAreWarned) {
  EXPECT_FALSE(warnsOfOverlap(room(0.9)));  // a lamp below the ceiling
  EXPECT_TRUE(warnsOfOverlap(room(1.0)));   // in the ceiling's plane, over its faces
  Builder twice = room(0.9);                // the lamp again, as 2 x 2 cells
  twice.quad({-0.3, 0.9, -0.3}, {0.3, 0.9, -0.3}, {0.3, 0.9, 0.3}, {-0.3, 0.9, 0.3}, 2, true);
  EXPECT_TRUE(warnsOfOverlap(twice));
  // The lamp again split along its other diagonal: each copy's centroids lie
  // on the other's diagonal edge, which a centroid test alone missed (a review).
  Builder crossed = room(0.9);
  crossed.quad({0.3, 0.9, -0.3}, {0.3, 0.9, 0.3}, {-0.3, 0.9, 0.3}, {-0.3, 0.9, -0.3}, 1, true);
  EXPECT_TRUE(warnsOfOverlap(crossed));
  // A small lamp inside one ceiling cell, in the ceiling's plane (its ball
  // holds no ceiling centroid; the cell's holds the lamp's).
  Builder small = room(0.9);
  small.quad({0.55, 1, 0.55}, {0.6, 1, 0.55}, {0.6, 1, 0.6}, {0.55, 1, 0.6}, 1, true);
  EXPECT_TRUE(warnsOfOverlap(small));
  Builder rug = room(0.9);  // a rug on the floor, emitting nothing: its light is right, no warning
  rug.quad({-0.5, 0, -0.5}, {-0.5, 0, 0.5}, {0.5, 0, 0.5}, {0.5, 0, -0.5}, 3, false);
  EXPECT_FALSE(warnsOfOverlap(rug));
  Builder twoSided = room(0.9);  // the lamp's reversed copy (a two-sided lamp): another orientation
  twoSided.quad({-0.3, 0.9, -0.3}, {-0.3, 0.9, 0.3}, {0.3, 0.9, 0.3}, {0.3, 0.9, -0.3}, 1, true);
  EXPECT_FALSE(warnsOfOverlap(twoSided));
}
