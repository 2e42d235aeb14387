// Brute-force ray caster: Möller-Trumbore against every usable face, in
// double precision. Slow, simple, independent of Embree: a test oracle.
#include <cmath>
#include <memory>
#include <vector>

#include "face_twins.h"
#include "gi/raycaster.h"
#include "gi/sampling.h"
#include "gi/scene.h"

namespace gi {
namespace {

class BruteForceCaster final : public RayCaster {
 public:
  // The faces with a reversed copy, as the Embree caster finds them.
  explicit BruteForceCaster(const Scene& s) : s_(s), ok_(usableFaceMask(s)), twins_(sceneFaceTwins(s)) {}
  size_t sceneFaces() const override { return ok_.size(); }
  Hit intersect(const Ray& r) const override {
    Hit best;
    best.t = r.tfar;
    for (size_t f = 0; f < ok_.size(); ++f) {
      if (!ok_[f]) continue;
      const auto& t = s_.triangles[f];
      glm::dvec3 a(s_.positions[t.x]), b(s_.positions[t.y]), c(s_.positions[t.z]);
      glm::dvec3 o(r.o), d(r.d), e1 = b - a, e2 = c - a;
      glm::dvec3 pv = glm::cross(d, e2);
      double det = glm::dot(e1, pv);
      if (det == 0.0) continue;
      double inv = 1.0 / det;
      glm::dvec3 tv = o - a;
      double u = glm::dot(tv, pv) * inv;
      if (u < 0.0 || u > 1.0) continue;
      glm::dvec3 qv = glm::cross(tv, e1);
      double v = glm::dot(d, qv) * inv;
      if (v < 0.0 || u + v > 1.0) continue;
      double tt = glm::dot(e2, qv) * inv;
      if (tt > r.tnear && tt < best.t) {
        best.t = float(tt); best.face = uint32_t(f); best.u = float(u); best.v = float(v);
        best.ng = glm::vec3(glm::cross(e1, e2));
      }
    }
    if (!best.valid()) best.t = std::numeric_limits<float>::infinity();
    else toFront(*twins_.twins, twins_.primOf[best.face], r.d, best, [this](uint32_t p) { return twins_.faceOf[p]; });
    return best;
  }
  bool occluded(const Ray& r) const override { return intersect(r).valid(); }
  uint32_t reversedCopy(uint32_t face) const override { return twins_.copyOf(face); }

 private:
  const Scene& s_;
  std::vector<uint8_t> ok_;
  SceneFaceTwins twins_;
};

}  // namespace

std::unique_ptr<RayCaster> makeBruteForceCaster(const Scene& s) { return std::make_unique<BruteForceCaster>(s); }

}  // namespace gi
