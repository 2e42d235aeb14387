// The exact unoccluded form factor from a differential area (point x, unit
// normal n) to a polygon: Lambert's contour integral,
//   F = 1/(2 pi) sum_k Theta_k n . (v_k x v_k+1) / |v_k x v_k+1|,  v_k = p_k - x,
// with the polygon first clipped to the half-space in front of x (Baum et al.
// 1989 and Wallace et al. 1989 use it per vertex with ray-cast visibility).
#pragma once
#include <glm/glm.hpp>

namespace gi {

// Triangle (a, b, c), seen from either side; 0 if it lies behind x's tangent plane.
double pointToTriangleFormFactor(const glm::dvec3& x, const glm::dvec3& n, const glm::dvec3& a, const glm::dvec3& b,
                                 const glm::dvec3& c);

}  // namespace gi
