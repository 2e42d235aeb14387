#include "gi/form_factor_analytic.h"

#include <algorithm>
#include <cmath>

namespace gi {

double pointToTriangleFormFactor(const glm::dvec3& x, const glm::dvec3& n, const glm::dvec3& a, const glm::dvec3& b,
                                 const glm::dvec3& c) {
  // Clip the triangle to n . (p - x) >= 0 (Sutherland-Hodgman, one plane).
  const glm::dvec3 in[3] = {a - x, b - x, c - x};
  glm::dvec3 poly[4];
  int m = 0;
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3& p = in[k];
    const glm::dvec3& q = in[(k + 1) % 3];
    const double dp = glm::dot(n, p), dq = glm::dot(n, q);
    if (dp >= 0) poly[m++] = p;
    if ((dp >= 0) != (dq >= 0)) poly[m++] = p + (q - p) * (dp / (dp - dq));
  }
  if (m < 3) return 0.0;
  double sum = 0;
  for (int k = 0; k < m; ++k) {
    const glm::dvec3 v0 = poly[k], v1 = poly[(k + 1) % m];
    const double l0 = glm::length(v0), l1 = glm::length(v1);
    if (l0 == 0 || l1 == 0) continue;  // x on the polygon's corner: that edge adds nothing
    const glm::dvec3 cr = glm::cross(v0, v1);
    const double lc = glm::length(cr);
    if (lc == 0) continue;
    const double theta = std::atan2(lc, glm::dot(v0, v1));
    sum += theta * glm::dot(n, cr) / lc;
  }
  return std::fabs(sum) / (2.0 * M_PI);
}

}  // namespace gi
