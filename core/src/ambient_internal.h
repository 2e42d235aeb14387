// Between computeAmbient (ambient.cpp) and the shared estimator (ao_shared.cpp).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "gi/ambient.h"
#include "gi/raycaster.h"

namespace gi {

// Obscurance's rho(s) = min(1, s / d_max)^k of a ray's hit (1 if none),
// with s the distance from the vertex p, not from the ray's origin
// o = p + offset (lifted off the surface and pulled into a crease's
// wedge), to the plane of the face hit: s = t + (offset . n_F) / (d . n_F),
// at least 0, exact for a flat face. Measured from the origin, a wall
// meeting the floor at the vertex lay about 1e-3 of the diagonal away, and
// at k = 0.1 the foot of a wall read 0.76 where it is 0.5 (an outside
// audit; k below 1 is the falloff for "only very near geometry").
inline double obscuranceOf(const Hit& h, const glm::vec3& d, const glm::vec3& offset, double maxDistance,
                           double exponent) {
  if (!h.valid()) return 1.0;
  double s = double(h.t);
  const glm::dvec3 ng(h.ng);
  const double dn = glm::dot(glm::dvec3(d), ng);
  if (dn != 0.0) {
    const double c = glm::dot(glm::dvec3(offset), ng) / dn;
    if (std::isfinite(c)) s += c;
  }
  return std::pow(std::min(1.0, std::max(0.0, s) / maxDistance), exponent);
}

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
