// Between computeAmbient (ambient.cpp) and the shared estimator (ao_shared.cpp).
#pragma once
#include <cstdint>
#include <vector>

#include "gi/ambient.h"

namespace gi {

struct SharedStats {
  int rounds = 0;
  double meanPooledVertices = 0.0, meanRings = 0.0;
  double castSeconds = 0.0, poolSeconds = 0.0;  // casting rays, pooling (graph included)
};

// The shared estimator (gi/ao_shared.h) for the vertices with mine[i] = 1:
// casts their rays and fills their value, stdError, rays (own rays cast) and
// bentNormal in res. poolable[i] = 1 for every vertex that casts rays in the
// whole run (mine and, in a split run, the other parts' vertices, whose rays
// arrive through o.vertices.sumOverParts after each round; a vertex that casts
// none there counts as not poolable); usable = usableFaceMask(scene). `o` is
// in local units (Scene::unit); occlusion or obscurance, no cone.
SharedStats computeSharedAmbient(const Scene& scene, const RayCaster& caster, const AmbientOptions& o,
                                 const std::vector<glm::vec3>& normals, const std::vector<glm::vec3>& origins,
                                 const std::vector<uint8_t>& poolable, const std::vector<uint8_t>& mine,
                                 const std::vector<uint8_t>& usable, AmbientResult& res, const Progress& progress);

}  // namespace gi
