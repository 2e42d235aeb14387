#include "gi/patch_seen.h"

#include <atomic>
#include <cmath>

#include "gi/sampling.h"
#include "hit_origin.h"

namespace gi {

namespace {

// Whether point k of patch i is buried: none of up to kRaysPerPoint
// cosine-weighted rays meets the front of another face or leaves the scene
// (the first that does proves it open). `rays` counts those cast; an open
// point is added to `open` (on the face) when given.
bool pointBuried(const FacePoints& on, const RayCaster& caster, size_t i, const glm::vec3& n, const Frame& frame,
                 float eps, const PaddedSobol& points, uint32_t k, uint32_t seed, uint64_t& rays,
                 std::vector<glm::vec3>* open = nullptr) {
  const glm::vec3 x = on.at(points(k, 0));
  Ray ray;
  ray.o = x + n * eps;
  // Directions of their own per point: the point's rays stratify its hemisphere.
  const PaddedSobol dirs(hash3(uint32_t(i), seed ^ k, 0x5e3du));
  for (uint32_t r = 0; r < uint32_t(PatchSeen::kRaysPerPoint); ++r) {
    ray.d = frame.toWorld(cosineHemisphere(dirs(r, 0)));
    ray.tnear = 0.f;
    ray.tfar = std::numeric_limits<float>::infinity();
    const Hit h = caster.intersect(ray);
    ++rays;
    if (!h.valid() || (h.face != i && glm::dot(ray.d, h.ng) < 0.f)) {
      if (open) open->push_back(x);
      return false;
    }
  }
  return true;
}

}  // namespace

PatchSeen patchSeenFractions(const Scene& s, const RayCaster& caster, uint32_t seed,
                             const std::vector<glm::vec3>* direct, const Progress& progress) {
  checkCasterFor(s, caster);
  const size_t n = s.faceCount();
  const auto ok = usableFaceMask(s);
  const float eps = float(sceneScale(s).rayEpsilon);
  PatchSeen out;
  out.fraction.assign(n, 1.f);
  out.seenPoints.assign(n, {});
  std::atomic<uint64_t> rays{0};
  parallelBlocks(n, progress, "seen parts of patches", [&](size_t b, size_t e) {
    uint64_t r = 0;
    for (size_t i = b; i < e; ++i) {
      if (!ok[i] || s.faceEmission(i) != glm::vec3(0.f)) continue;
      const glm::vec3 nrm = glm::normalize(faceNormalUnnormalized(s, i));
      const Frame frame(nrm);
      const PaddedSobol points(hash3(uint32_t(i), seed, 0x5e3cu));
      const FacePoints on(s, uint32_t(i), nrm, eps, caster);
      // The first points of the sequence screen the patch; where one is
      // buried the estimate takes kPoints (the screen's among them).
      int buried = 0;
      std::vector<glm::vec3> open;
      for (uint32_t k = 0; k < uint32_t(PatchSeen::kScreenPoints); ++k)
        buried += pointBuried(on, caster, i, nrm, frame, eps, points, k, seed, r, &open);
      if (buried == 0) continue;
      // Every screening point buried: the patch is taken as wholly buried
      // (a seen part under 1/16 of it goes with it), which spares a large
      // mesh's hidden inner faces the 64 points of 32 rays each.
      const bool lit = direct && (*direct)[i] != glm::vec3(0.f);
      if (buried == PatchSeen::kScreenPoints && !lit) {
        out.fraction[i] = 0.f;
        continue;
      }
      for (uint32_t k = PatchSeen::kScreenPoints; k < uint32_t(PatchSeen::kPoints); ++k)
        buried += pointBuried(on, caster, i, nrm, frame, eps, points, k, seed, r, &open);
      out.fraction[i] = float(1.0 - double(buried) / PatchSeen::kPoints);
      if (out.fraction[i] > 0.f) out.seenPoints[i] = std::move(open);
    }
    rays += r;
  });
  out.rays = rays.load();
  for (size_t i = 0; i < n; ++i) {
    const float a = out.fraction[i];
    if (ok[i]) out.area += faceArea(s, i);
    if (a >= 1.f) continue;
    (a > 0.f ? out.partial : out.buried) += 1;
    out.buriedArea += (1.0 - a) * faceArea(s, i);
  }
  return out;
}

}  // namespace gi
