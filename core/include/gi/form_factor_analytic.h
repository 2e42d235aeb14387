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

}  // namespace gi
