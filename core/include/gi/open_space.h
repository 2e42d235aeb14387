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
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi {

class OpenSpaceTest {
 public:
  // normals: the vertex normals the rays use (kept by reference, as is s).
  OpenSpaceTest(const Scene& s, float eps, const std::vector<glm::vec3>& normals,
                const std::vector<uint8_t>* usable = nullptr);
  ~OpenSpaceTest();
  bool openWithin(uint32_t vertex, float maxDistance) const;

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
