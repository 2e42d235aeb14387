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
// coarse Cornell box). Used by the path integrator (reference, the eye
// views, the camera's first hits included), the Whitted view, photon
// mapping's final gather and radiosity's near-hit relighting.
#pragma once
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <vector>

#include "gi/raycaster.h"
#include "gi/sampling.h"
#include "gi/scene.h"

namespace gi {

// Per face, its three altitudes: component i from corner i (of t.x, t.y,
// t.z) onto the edge opposite it, twice the area over that edge's length.
// A point's distance to that edge is its barycentric i times it. (One
// lower bound for all three, twice the area over the longest edge, took
// a sliver's every hit for one near its border.)
inline std::vector<glm::vec3> faceAltitudes(const Scene& s) {
  std::vector<glm::vec3> out(s.faceCount(), glm::vec3(0.f));
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const glm::uvec3 t = s.triangles[f];
    const glm::vec3 a = s.positions[t.x], b = s.positions[t.y], c = s.positions[t.z];
    const float twice = glm::length(glm::cross(b - a, c - a));
    const float la = glm::length(c - b), lb = glm::length(a - c), lc = glm::length(b - a);
    out[f] = {la > 0.f ? twice / la : 0.f, lb > 0.f ? twice / lb : 0.f, lc > 0.f ? twice / lc : 0.f};
  }
  return out;
}

// o, d, t: the ray and its hit; n: the face's unit normal; border: the
// hit's distance to its triangle's border (hitBorder).
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

// Where a ray that arrived along `in` and was turned by a mirror or glass
// at the hit y (unit normal n) into `out` leaves: a reflection (out on the
// side the ray came from) from back(), the hit's ray origin (hitRayOrigin,
// through the caller's own access to the hit); a refraction, through the
// face, from y lifted by eps to out's side. Shared by the eye views, the
// reference and photon mapping's paths and gathers.
template <class Back>
glm::vec3 specularOrigin(const glm::vec3& in, const glm::vec3& out, const glm::vec3& y, const glm::vec3& n, float eps,
                         const Back& back) {
  if (glm::dot(out, n) * glm::dot(in, n) < 0.f) return back();
  return y + (glm::dot(out, n) > 0.f ? n : -n) * eps;
}

// Whether a surface lies within eps of the point x of a face along the
// unit direction d, x's own face left out (the ray starts 0.01 eps off):
// a lift along d would start past it. FacePoints' check, and the light
// probe's (emitters.cpp) for plates closer than the offset.
inline bool surfaceWithinOffset(const RayCaster& caster, const glm::vec3& x, const glm::vec3& d, float eps) {
  Ray r;
  r.o = x;
  r.d = d;
  r.tnear = 0.01f * eps;
  r.tfar = eps;
  return caster.occluded(r);
}

// The distance to its triangle's border of the hit at barycentrics (u, v)
// (the hit (1 - u - v) t.x + u t.y + v t.z, as Embree reports it).
inline float hitBorder(const std::vector<glm::vec3>& altitudes, uint32_t face, float u, float v) {
  const glm::vec3& h = altitudes[face];
  return std::min({(1.f - u - v) * h.x, u * h.y, v * h.z});
}

// Points sampled on a face f, as the patches' estimators take them (form
// factors, direct light, sky, closure and seen-share rays), whose rays
// leave lifted by eps along the normal n: a point within eps cot a of an
// edge where a neighbouring face meets f at a dihedral angle a below 90
// degrees (on n's side) lifts past that face, and its rays start outside
// (inside a closed tetrahedron with inward normals, under a sky outside,
// every patch read about 2e-5 of the ground's light). So a point closer
// than 4 eps to an edge (a >= 14 degrees, as hitRayOrigin) casts one short
// ray along its lift; only where that meets a surface is the point moved,
// straight off each near edge until it is 4 eps away (across the face,
// never along it), and kept there if its lift is then free (else, a
// surface closer than the offset above the face, as sampled). Points near
// flat or convex edges, and everywhere else, stay as sampled: moving every
// point of the band (to the face shrunk about its incentre) moved points
// along slivers too, by up to 0.4 of a 0.5-long facet.
class FacePoints {
 public:
  FacePoints(const Scene& s, uint32_t f, const glm::vec3& n, float eps, const RayCaster& caster)
      : n_(n), eps_(eps), caster_(caster) {
    const glm::uvec3 t = s.triangles[f];
    p_[0] = s.positions[t.x], p_[1] = s.positions[t.y], p_[2] = s.positions[t.z];
    gap_ = 4.f * eps;
    for (int i = 0; i < 3; ++i) {
      // The altitude from corner i onto the edge opposite it: a point's
      // distance to that edge is its barycentric i times it; off[i], the
      // unit direction from the edge towards corner i in the face's plane.
      const glm::vec3 a = p_[(i + 1) % 3], e = p_[(i + 2) % 3] - a;
      const float ee = glm::dot(e, e);
      const glm::vec3 foot = ee > 0.f ? a + e * (glm::dot(p_[i] - a, e) / ee) : a;
      const glm::vec3 up = p_[i] - foot;
      h_[i] = glm::length(up);
      off_[i] = h_[i] > 0.f ? up / h_[i] : glm::vec3(0.f);
    }
  }
  // The point for a uniform sample u of the unit square (uniform on the
  // face but where its lift would cross a surface).
  glm::vec3 at(glm::vec2 u) const {
    const glm::vec2 w = strictlyInside(uniformTriangle(u));
    const float b[3] = {w.x, w.y, 1.f - w.x - w.y};
    const glm::vec3 x = b[0] * p_[0] + b[1] * p_[1] + b[2] * p_[2];
    float d[3];
    for (int i = 0; i < 3; ++i) d[i] = b[i] * h_[i];
    if (std::min({d[0], d[1], d[2]}) >= gap_ || !liftCrosses(x)) return x;
    glm::vec3 y = x;
    for (int i = 0; i < 3; ++i)
      if (d[i] < gap_) y += off_[i] * (gap_ - d[i]);
    // Kept on the face (a face narrower than the pushes: as sampled).
    for (int i = 0; i < 3; ++i)
      if (glm::dot(y - p_[(i + 1) % 3], off_[i]) < 0.f) return x;
    return liftCrosses(y) ? x : y;
  }

 private:
  bool liftCrosses(const glm::vec3& x) const { return surfaceWithinOffset(caster_, x, n_, eps_); }
  glm::vec3 p_[3], off_[3], n_;
  float h_[3], gap_, eps_;
  const RayCaster& caster_;
};

}  // namespace gi
