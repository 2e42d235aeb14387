// The narrow ray-query contract the algorithms use. Embree implements it in
// production; a brute-force caster cross-checks it in tests.
#pragma once
#include <cstdint>
#include <limits>
#include <memory>

#include <glm/glm.hpp>

namespace gi {

struct Scene;

struct Ray {
  glm::vec3 o{0.f};
  float tnear = 0.f;
  glm::vec3 d{0.f, 0.f, 1.f};
  float tfar = std::numeric_limits<float>::infinity();
};

constexpr uint32_t kNoHit = 0xffffffffu;

struct Hit {
  float t = std::numeric_limits<float>::infinity();
  uint32_t face = kNoHit;  // index into Scene::triangles
  float u = 0.f, v = 0.f;  // barycentrics of vertices 1 and 2
  glm::vec3 ng{0.f};       // geometric normal (unnormalised, winding order)
  bool valid() const { return face != kNoHit; }
};

class RayCaster {
 public:
  virtual ~RayCaster() = default;
  virtual Hit intersect(const Ray& r) const = 0;
  virtual bool occluded(const Ray& r) const = 0;
  // occ[i] = 1 if rays[i] hits anything in (tnear, tfar). Thread-safe.
  virtual void occludedBatch(const Ray* rays, size_t n, uint8_t* occ) const {
    for (size_t i = 0; i < n; ++i) occ[i] = occluded(rays[i]) ? 1 : 0;
  }
  // Rays sharing one origin (tnear 0) and one tfar: the shape of every
  // per-vertex estimator. occ[i] = 1 if direction i is blocked.
  virtual void occludedFan(const glm::vec3& o, const glm::vec3* dirs, size_t n, float tfar, uint8_t* occ) const {
    Ray r;
    r.o = o;
    r.tfar = tfar;
    for (size_t i = 0; i < n; ++i) { r.d = dirs[i]; occ[i] = occluded(r) ? 1 : 0; }
  }
  virtual void intersectBatch(const Ray* rays, size_t n, Hit* hits) const {
    for (size_t i = 0; i < n; ++i) hits[i] = intersect(rays[i]);
  }
  // The reversed copy of a face (the same three corners in the other turn:
  // a two-sided surface, or two solids touching), or kNoHit. Where a ray
  // meets such a face's back, the hits above report the copy's front (the
  // same point); a caller that wants the back it crossed (thickness: where a
  // ray leaves a solid) asks here.
  virtual uint32_t reversedCopy(uint32_t face) const {
    (void)face;
    return kNoHit;
  }
  // The face count of the scene it was built for (kUnknownFaces: not known).
  static constexpr size_t kUnknownFaces = ~size_t(0);
  virtual size_t sceneFaces() const { return kUnknownFaces; }
};

// Throws std::invalid_argument where the caster was built for a scene of
// another face count: its hits would name faces the scene does not have (a
// library caller's mistake; every entry point taking a scene and a caster
// checks it).
void checkCasterFor(const Scene& s, const RayCaster& caster);

struct Rng;
// Whether x (normal n) sees a random point of triangle (a, b, c) drawn with
// the density of the point-to-triangle form factor's kernel, cos(theta_x)
// over the solid angle (a direction uniform in the spherical triangle, Arvo
// 1995, kept with probability cos(theta_x)): its mean is the kernel-weighted
// visibility, so that F x it is the occluded factor (a point uniform by
// area weighs the triangle's far, hidden part as much as its near, bright
// one: a long triangle half hidden read 52% low at 4 points a patch and 81%
// at 1,024). One shadow ray stopping short of the triangle's plane.
bool visibleByFormFactorKernel(const RayCaster& caster, const glm::vec3& x, const glm::vec3& n, const glm::vec3& a,
                               const glm::vec3& b, const glm::vec3& c, Rng& rng, float eps);

enum class BatchMode { Single, Packet8, Stream };  // how batches reach Embree

// Builds over the scene's usable faces (see usableFaceMask).
std::unique_ptr<RayCaster> makeEmbreeCaster(const Scene& s, BatchMode mode = BatchMode::Packet8);
// O(n) per ray; for tests on small scenes.
std::unique_ptr<RayCaster> makeBruteForceCaster(const Scene& s);

}  // namespace gi
