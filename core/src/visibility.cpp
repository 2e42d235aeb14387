// Visibility between a point and a triangle by one shadow ray: the
// visibility term of the point-to-triangle factors (form factors, direct light).
#include <glm/glm.hpp>

#include "gi/raycaster.h"
#include "gi/sampling.h"

namespace gi {

bool visibleToRandomPoint(const RayCaster& caster, const glm::vec3& x, const glm::vec3& a, const glm::vec3& b,
                          const glm::vec3& c, Rng& rng, float eps) {
  const glm::vec2 ub = uniformTriangle({rng.next(), rng.next()});
  const glm::vec3 w = ub.x * a + ub.y * b + (1.f - ub.x - ub.y) * c - x;
  const float len = glm::length(w);
  if (!(len > 0.f)) return true;
  Ray ray;
  ray.o = x;
  ray.d = w / len;
  ray.tfar = len * (1.f - 1e-4f) - eps;
  return ray.tfar <= 0.f || !caster.occluded(ray);
}

}  // namespace gi
