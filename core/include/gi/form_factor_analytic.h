// The exact unoccluded form factor from a differential area (point x, unit
// normal n) to a polygon: Lambert's contour integral,
//   F = 1/(2 pi) sum_k Theta_k n . (v_k x v_k+1) / |v_k x v_k+1|,  v_k = p_k - x,
// with the polygon first clipped to the half-space in front of x (Baum et al.
// 1989 and Wallace et al. 1989 use it per vertex with ray-cast visibility),
// and its mean over a source triangle i,
//   F_ij = 1/A_i int_{A_i} F(x -> j) dA_x,
// by an adaptive midpoint rule: the centroids of 4^L congruent sub-triangles
// (midpoint subdivision), and where a sub-triangle's one-point value and its
// four quarters' differ by more than a tolerance, the quarters are split again.
#pragma once
#include <algorithm>
#include <array>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

namespace gi {

// One edge's term of the contour integral, Theta n . (v0 x v1) / |v0 x v1|
// with v0, v1 the edge's ends relative to x (0 for a degenerate edge).
double lambertEdgeTerm(const glm::dvec3& v0, const glm::dvec3& v1, const glm::dvec3& n);

// Triangle (a, b, c), seen from either side; 0 if it lies behind x's tangent plane.
// How far the farthest of a, b, c lies in front of the plane through o with
// unit normal n (negative: wholly behind it). Up to the scene's ray offset a
// triangle counts as in the plane: it exchanges nothing with a surface there.
inline double heightAbovePlane(const glm::dvec3& n, const glm::dvec3& o, const glm::dvec3& a, const glm::dvec3& b,
                               const glm::dvec3& c) {
  return std::max({glm::dot(n, a - o), glm::dot(n, b - o), glm::dot(n, c - o)});
}

double pointToTriangleFormFactor(const glm::dvec3& x, const glm::dvec3& n, const glm::dvec3& a, const glm::dvec3& b,
                                 const glm::dvec3& c);

// The source triangle split into 4^level congruent sub-triangles (level =
// floor(log4(points)), at most 6): the analytic method's base points are
// their centroids.
int analyticBaseLevel(int points);

// Unoccluded F from source triangle s (front: counter-clockwise) to the front
// of target triangle t, by the adaptive midpoint rule: base level L, then each
// sub-triangle whose quarters change the estimate by more than
// relTol x (the base estimate) x (its share of the area) is split, at most
// maxRefine levels further. Exact as relTol -> 0 and maxRefine grows.
double triangleToTriangleFormFactor(const glm::dvec3 s[3], const glm::dvec3 t[3], int baseLevel, double relTol,
                                    int maxRefine);

// A target polygon for meanOverTriangle: its boundary edges (where the
// point-to-target factor changes fastest), its plane, its area, half the
// smallest altitude of its triangles (a target narrower than a
// sub-triangle is split for, as the analytic method does), and a sphere
// around it.
struct FormFactorTarget {
  std::vector<std::array<glm::dvec3, 2>> edges;
  glm::dvec3 normal{0.0}, origin{0.0};  // unit normal, a point of the plane
  double area = 0.0, narrowest = 0.0;
  glm::dvec3 centre{0.0};
  double radius = 0.0;
  bool twoSided = false;  // seen from either side (a sky portal); else from its normal's side only
};

// The mean of g over source triangle s, g the unoccluded factor from a point
// of s to `target` (0 where it is not seen): at the centroid where s is
// farther from the target's sphere than 16 of its radii; else at four base
// points, and within 16 of their radii the analytic method's refinement
// (the comparison, then the target's edges: exact up to about 0.3% where s
// meets the target at a common edge or a thin gap). The one-point rule's
// error, about (r / d)^2 / 4, is below 0.1% where it is used.
// *best (optional): the base point of largest g. 0 without evaluating g
// where the target lies wholly behind or in s's plane, or s wholly behind or
// in a one-sided target's, up to inPlane (the scene's ray offset: coplanar
// faces whose corners were rounded off the plane are coplanar; without it
// the edge rule split such pairs to its budget, and a furnace whose every
// face emits took 100 times as long).
double meanOverTriangle(const glm::dvec3 s[3], const std::function<double(const glm::dvec3&)>& g,
                        const FormFactorTarget& target, double inPlane, glm::dvec3* best = nullptr);

}  // namespace gi
