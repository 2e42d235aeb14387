// The area of the photon-holding surface inside a gather sphere: the
// normalisation of the density estimate,
//   H(x) ~ sum_p Phi_p / A(x, r),   A(x, r) = area of {y on the counted faces : |y - x| <= r},
// which is Jensen's (1996) pi r^2 on a plane all around x, but a half disk at a
// crease whose other face is not counted, a quarter at a box's corner, and a
// part of the disk at a mesh border. The counted faces are the diffuse ones
// whose (quantised) normal m has m.n >= 0.5: those whose photons the gather
// keeps. Each face's part is exact: the triangle clipped to the disk in which
// the sphere cuts its plane (triangleBallArea).
// Internal to the photon-mapping sources.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi {

class GatherSurface {
 public:
  explicit GatherSurface(const Scene& s) : GatherSurface(s, false) {}
  // Of all the diffuse faces.
  double totalArea() const { return nodes_.empty() ? 0.0 : nodes_[0].area; }
  // The smallest squared radius a density estimate divides by: the ray
  // offset's (photons closer than it are one place to the tracer). Without
  // it, k photons at one point (a 0.5-degree spot's directions collapsed
  // in single precision) read k Phi / 0: 1e22 (an outside audit).
  float minRadius2() const { return minRadius2_; }

  // A(x, r) over the faces facing n's side (m.n >= 0.5). *flat: whether all
  // of them lie in one plane through x (then A(rho) = A(r) rho^2 / r^2 for
  // rho < r when A(r) is the whole disk).
  double area(const glm::vec3& x, const glm::vec3& n, float r, bool* flat = nullptr) const;
  // The cone filter's normalisation (Jensen 1996, w = 1 - d / (k r)):
  //   int_{A} w dA = A(r) (1 - 1/k) + (1 / (k r)) int_0^r A(rho) drho
  // (from int d dA = r A(r) - int_0^r A; pi r^2 (1 - 2 / (3k)) on a plane),
  // the radial integral by 8-point Gauss-Legendre, or pi r^2 (1 - 2/(3k))
  // at once where the whole disk lies on one plane through x.
  double coneArea(const glm::vec3& x, const glm::vec3& n, float r, float k) const;

  // The sheets: the usable faces joined where they share a corner (by
  // position, so that a welded room and a triangle soup of it are one sheet).
  // The sheet of vertex v (kNoSheet for one no usable face holds).
  static constexpr uint32_t kNoSheet = 0xffffffffu;
  uint32_t vertexSheet(size_t v) const { return v < vertexSheet_.size() ? vertexSheet_[v] : kNoSheet; }
  // Whether a face (diffuse, any orientation; or a mirror's, glass' or
  // glossy surface's, which hold no photons but hide the same light) within
  // r of x rises above x's tangent plane (on n's side) and belongs to another sheet than
  // `sheet` (an object standing on the surface, a lamp just below a ceiling:
  // by more than 1e-4 r) or turns more than acos(cosTurn) from n (a wall
  // meeting the floor, welded or not: by more than r / 10; a convex surface
  // curving away from the plane, or a gentle hollow, does not count). There the density estimate's premise,
  // the irradiance even over the surface inside the sphere, fails: the
  // other surface hides part of the sky from points near it (the light
  // falls steeply towards the edge, and the point may be in a contact
  // shadow the sphere averages away), the floor hidden under a block counts
  // as area, a lamp's photons as the ceiling's.
  bool otherSurfaceWithin(const glm::vec3& x, const glm::vec3& n, float r, uint32_t sheet, float cosTurn) const;

 private:
  // specular: of the mirror, glass and glossy faces instead (otherSurfaceWithin's only).
  GatherSurface(const Scene& s, bool specular);
  float minRadius2_ = 1e-30f;
  bool facesWithin(const glm::vec3& x, const glm::vec3& n, float r, uint32_t sheet, float cosTurn) const;
  std::shared_ptr<const GatherSurface> specular_;  // null where the scene has none
  // A bounding-volume hierarchy over the faces. A node wholly inside the ball
  // whose faces share one normal adds its area at once: on the planar walls
  // of most scenes only the faces the sphere cuts are clipped.
  struct Node {
    glm::vec3 lo, hi;
    glm::vec3 m;            // the faces' common quantised normal, or 0 if they differ
    glm::vec3 plane;        // their common unit normal if they lie in one plane (offset d), else 0
    float d;
    double area;            // of the faces below
    uint32_t first, count;  // leaf: faces order_[first, first + count); inner: count = 0, children index + 1 and first
    uint32_t sheet;         // the faces' common sheet, or kNoSheet if they differ
  };
  uint32_t build(uint32_t begin, uint32_t end, std::vector<glm::vec3>& centroid);
  template <class Skip, class Leaf>
  void walk(const glm::vec3& x, float r2, Skip skip, Leaf leaf) const;
  std::vector<glm::vec3> a_, b_, c_, m_, n_;  // per counted face: corners, quantised and exact unit normals
  std::vector<double> faceArea_;
  std::vector<glm::vec4> bound_;  // per face: a bounding sphere (centre, radius)
  std::vector<uint32_t> order_;
  std::vector<Node> nodes_;
  std::vector<uint32_t> sheet_;        // per counted face
  std::vector<uint32_t> vertexSheet_;  // per vertex
};

}  // namespace gi
