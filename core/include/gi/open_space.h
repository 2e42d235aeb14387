// Proofs that a vertex is fully open, so that it needs no rays at all.
// OpenSpaceTest: no geometry lies above its tangent plane within a distance
// (every ray limited to that distance escapes): a usable face within reach
// of a ray (its bounding sphere) with a corner eps/2 or more above the plane
// refuses it. A tree of boxes over the faces, searched without the faces out
// of reach or wholly below the plane: bounded by each node's box, and for
// nodes of 64 faces or fewer by their slab along their mean normal (tight on
// nearly flat parts, where a box's bound is loose by its size), after a quick
// refusal from the vertex's own faces. Conservative: "false" means "maybe".
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi {

class OpenSpaceTest {
 public:
  // normals: the vertex normals the rays use (kept by reference, as is s).
  // buildTree false: the tree waits for build() (or pays()), so that a run
  // the proof would not pay for does not build it.
  OpenSpaceTest(const Scene& s, float eps, const std::vector<glm::vec3>& normals,
                const std::vector<uint8_t>* usable = nullptr, bool buildTree = true);
  ~OpenSpaceTest();
  void build();  // not concurrently with anything else
  bool openWithin(uint32_t vertex, float maxDistance) const;  // after build()

  // Whether proving every candidate pays for itself when each open one
  // would otherwise cast `rays` rays: a proof costs about 6 to 9 of a
  // vertex's rays (0.8 to 1.2 microseconds with its share of the tree, where
  // a ray costs 0.13 to 0.14, on bunny_fine and a 470k-vertex scan:
  // bench/ao_open_proof_bench.json), so the share of open vertices in an
  // even sample of the candidates (all of a small mesh, at least 256 of a
  // large one, in index order: the same decision in every part of a split
  // run), times rays, must reach 8. The share not refused by their own faces
  // bounds it first; only past that bound is the tree built and the sample
  // proved.
  struct Plan {
    bool pays = false;
    double share = 0.0;         // of the sample: open, or (ownFacesOnly) not refused by its own faces
    size_t sampled = 0;
    bool ownFacesOnly = false;  // settled by that bound, without the tree
    std::string whyNot(int rays) const;  // the log's line where it does not pay
  };
  Plan plan(const std::vector<uint32_t>& candidates, float maxDistance, int rays);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Proves that the whole scene lies at or below a vertex's tangent plane (no
// point of a usable face more than eps/2 above it): rays start eps above the
// plane and go up, so none can hit anything, at any distance, and the vertex
// is open (AO 1) without rays. True only where the plane supports the scene's
// convex hull, so it holds on the outer, convex parts of a closed object
// (about a tenth of the bunny's vertices). A tree of boxes over the vertices
// of the usable faces, searched with the bound n.(centre - p) + |n|.(half
// size), after two quick refusals: a corner of one of the vertex's own faces
// above its plane, or one of the scene's 26 extreme points (the farthest in
// the directions of a cube's faces, edges and corners). Conservative:
// "false" means "maybe".
class SceneBelowTest {
 public:
  // normals: the vertex normals the rays use (kept by reference, as is s).
  SceneBelowTest(const Scene& s, float eps, const std::vector<glm::vec3>& normals,
                 const std::vector<uint8_t>* usable = nullptr);
  ~SceneBelowTest();
  bool sceneBelow(uint32_t vertex) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gi
