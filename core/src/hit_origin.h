// Where rays leaving a surface point that a ray hit start.
//
// A hit y = o + t d on a face of unit normal n: the light samples and the
// next bounce from y leave from a point off the face (a ray from y itself
// may hit the face again by rounding), y lifted by eps along the normal to
// the side the ray came from. Within a few eps of an acute corner or edge
// that point lies past the neighbouring face: a sky outside a closed
// tetrahedron with inward normals lit its corners (up to 0.15 for a sky of
// 1) in the reference and photon mapping (an outside audit). The segment
// (o, y) is free (the ray crossed it), so where the ray came from near by
// (t below 16 eps: corners and creases) or the hit lies within 4 eps of its
// triangle's border (a neighbouring face at a dihedral angle a crosses the
// lift within eps cot a of the edge: 4 eps covers a >= 14 degrees), the
// lifted point is taken only if it is reached from a point q of that
// segment, eps off the plane (eps / c back along the ray, c = |d.n|, at
// most 4 eps and t), without crossing a surface (one short ray); else q
// itself. q is not taken everywhere: it lies up to 4 eps aside from y, and
// beside a block's foot that moved the light samples of floor hits across
// the shadow of the block's corner (its bottom vertices read 35% low on a
// coarse Cornell box).
#pragma once
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <vector>

#include "gi/raycaster.h"
#include "gi/scene.h"

namespace gi {

// Per face, a lower bound of its altitudes (twice its area over its longest
// edge): a hit's distance to the border is at least its smallest
// barycentric times this.
inline std::vector<float> faceMinAltitudes(const Scene& s) {
  std::vector<float> out(s.faceCount(), 0.f);
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const glm::uvec3 t = s.triangles[f];
    const glm::vec3 a = s.positions[t.x], b = s.positions[t.y], c = s.positions[t.z];
    const float longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    out[f] = longest > 0.f ? glm::length(glm::cross(b - a, c - a)) / longest : 0.f;
  }
  return out;
}

// o, d, t: the ray and its hit; n: the face's unit normal; border: a lower
// bound of the hit's distance to its triangle's border
// (min(u, v, 1 - u - v) times faceMinAltitudes).
inline glm::vec3 hitRayOrigin(const RayCaster& caster, const glm::vec3& o, const glm::vec3& d, float t,
                              const glm::vec3& n, float eps, float border) {
  const glm::vec3 y = o + d * t;
  const glm::vec3 lifted = y + (glm::dot(d, n) < 0.f ? n : -n) * eps;
  if (!(t < 16.f * eps) && !(border < 4.f * eps)) return lifted;
  const float c = std::fabs(glm::dot(n, d));
  const float back = c > 0.f ? std::min({eps / c, 4.f * eps, t}) : 0.f;
  const glm::vec3 q = y - d * back;
  const glm::vec3 w = lifted - q;
  const float len = glm::length(w);
  if (!(len > 0.f)) return q;
  Ray r;
  r.o = q;
  r.d = w / len;
  r.tfar = len;
  return caster.occluded(r) ? q : lifted;
}

inline float hitBorder(const std::vector<float>& minAltitude, uint32_t face, float u, float v) {
  return std::min({u, v, 1.f - u - v}) * minAltitude[face];
}

}  // namespace gi
