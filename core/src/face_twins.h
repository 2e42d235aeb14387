// The faces of two-sided surfaces, for the ray casters: a face and its
// reversed copy (the same three corner positions in the opposite turn) lie
// in one plane, so a ray meets both at the same distance and a caster
// reports whichever it tests first (Embree: an order of its tree; the brute
// caster: the smaller of two roundings). Met from behind, the reported face
// is black to every estimator ("the back of a face is black") while its copy
// is lit: light that reached the copy's front was lost at random, about 3%
// of a furnace's radiosity with one sheet in the box (B = E / (1 - rho) must
// hold at every vertex, whatever the geometry). FaceTwins finds the copies,
// and toFront() turns a hit on a face's back into the hit on its copy's
// front: the same point, distance and plane, the copy's face, winding and
// barycentrics.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "gi/raycaster.h"
#include "gi/scene.h"

namespace gi {

class FaceTwins {
 public:
  // xyz: three floats per vertex; idx: three vertex indices per primitive
  // (every one usable: finite, non-degenerate). O(n log n), in parallel.
  FaceTwins(const float* xyz, const uint32_t* idx, size_t primitives);
  bool any() const { return any_; }
  // The reversed copy of primitive p, or kNoHit.
  uint32_t twin(uint32_t p) const { return any_ ? twin_[p] : kNoHit; }
  // Barycentrics (u, v of corners 1 and 2) of a point of primitive p in its
  // twin's corners.
  void twinBarycentrics(uint32_t p, float& u, float& v) const {
    const float w[3] = {1.f - u - v, u, v};
    const uint8_t m = corner_[p];
    u = w[m & 3u];
    v = w[(m >> 2) & 3u];
  }

 private:
  bool any_ = false;
  std::vector<uint32_t> twin_;
  std::vector<uint8_t> corner_;  // which of p's corners the twin's corners 1 and 2 are (2 bits each)
};

// The twins of a scene's usable faces (primitive k is face faceOf[k]).
struct SceneFaceTwins {
  std::vector<uint32_t> faceOf, primOf;  // primitives to faces, faces to primitives (kNoHit: unusable)
  std::unique_ptr<FaceTwins> twins;
  uint32_t copyOf(size_t face) const {  // the face's reversed copy, or kNoHit
    const uint32_t p = face < primOf.size() ? primOf[face] : kNoHit;
    const uint32_t t = p == kNoHit ? kNoHit : twins->twin(p);
    return t == kNoHit ? kNoHit : faceOf[t];
  }
};
SceneFaceTwins sceneFaceTwins(const Scene& s);

// A hit h of a ray along d on primitive `prim` (face faceOf(prim)), met from
// behind (d . ng > 0) on a face with a reversed copy: becomes the hit on the
// copy's front. Anything else is left as it is.
template <class FaceOf>
inline void toFront(const FaceTwins& twins, uint32_t prim, const glm::vec3& d, Hit& h, FaceOf faceOf) {
  if (!(d.x * h.ng.x + d.y * h.ng.y + d.z * h.ng.z > 0.f)) return;
  const uint32_t t = twins.twin(prim);
  if (t == kNoHit) return;
  twins.twinBarycentrics(prim, h.u, h.v);
  h.face = faceOf(t);
  h.ng = -h.ng;
}

}  // namespace gi
