// Positions stored as floats far from the origin (gi/scene.h,
// coarseFloatsWarning): the CLI's readers and MeshLab's bridge say so.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "gi/scene.h"

namespace gi {

// Coordinates stored as floats far from the origin (a scan in a national
// grid: 5e6 m with a resolution of 0.5 m) have lost what the file cannot
// give back: faces collapse or tilt (an outside audit: the bunny as floats
// at 1e7 had 1,714 of its 3,674 faces degenerate and its thickness 18.5%
// off, with no warning). Said where every coordinate is a float and the
// float step at the largest one exceeds 1e-4 of the bounding box's
// diagonal (fewer than 10,000 steps across the mesh).
std::optional<std::string> coarseFloatsWarning(const std::vector<glm::dvec3>& pts) {
  const glm::dvec3 huge(std::numeric_limits<double>::max());
  glm::dvec3 lo(huge), hi(-huge);
  double far = 0;
  for (const glm::dvec3& q : pts) {
    // A non-finite coordinate is no distance (it read "as far as inf, where
    // a float's step is -nan"): the scene's own checks say it.
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) continue;
    if (double(float(q.x)) != q.x || double(float(q.y)) != q.y || double(float(q.z)) != q.z) return std::nullopt;
    lo = glm::min(lo, q), hi = glm::max(hi, q);
    far = std::max({far, std::fabs(q.x), std::fabs(q.y), std::fabs(q.z)});
  }
  if (!(hi.x >= lo.x)) return std::nullopt;  // no finite point
  const float f = float(far);
  const double diagonal = glm::length(hi - lo),
               step = double(std::nextafter(f, std::numeric_limits<float>::infinity())) - double(f);
  if (!(diagonal > 0.0) || step <= 1e-4 * diagonal) return std::nullopt;
  char b[400];
  std::snprintf(b, sizeof b,
                "its coordinates are floats as far as %.3g from the origin, where a float's step is %.3g, %.2g%% of "
                "the mesh's diagonal (%.3g): the geometry is already rounded (faces may have collapsed or tilted)",
                far, step, 100.0 * step / diagonal, diagonal);
  return std::string(b);
}

}  // namespace gi
