// Proves that no geometry lies above a vertex's tangent plane within a
// distance: such a vertex is fully open for every ray limited to that
// distance, so it needs no rays at all. Conservative: "false" means "maybe".
#pragma once
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi {

class OpenSpaceTest {
 public:
  OpenSpaceTest(const Scene& s, float eps);
  ~OpenSpaceTest();
  bool hemisphereEmpty(const glm::vec3& p, const glm::vec3& n, float maxDistance) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gi
