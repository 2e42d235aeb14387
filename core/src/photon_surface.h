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
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi {

class GatherSurface {
 public:
  explicit GatherSurface(const Scene& s);
  // Of all the diffuse faces.
  double totalArea() const { return nodes_.empty() ? 0.0 : nodes_[0].area; }

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

 private:
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
  };
  uint32_t build(uint32_t begin, uint32_t end, std::vector<glm::vec3>& centroid);
  std::vector<glm::vec3> a_, b_, c_, m_, n_;  // per counted face: corners, quantised and exact unit normals
  std::vector<double> faceArea_;
  std::vector<glm::vec4> bound_;  // per face: a bounding sphere (centre, radius)
  std::vector<uint32_t> order_;
  std::vector<Node> nodes_;
};

}  // namespace gi
