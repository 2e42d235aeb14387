// The share of each patch that the rest of the scene can see.
//
// A patch cut without regard to the objects standing on it (a floor under a
// block) has part of its area buried: no ray from another surface lands
// there, and no light reaches it. The area means a radiosity solver works
// with (the patch's direct irradiance, its form-factor row, its radiosity
// B_i) average over the whole patch, the buried part included with no light,
// while every ray that lands on the patch from elsewhere lands on the seen
// part, whose radiosity is B_i / a_i for a seen share a_i. Reading B_i there
// understates the light the patch sends by the factor a_i: on the Cornell
// box with 50 mm patches the final gather's vertices came out 0.4 to 0.6%
// dark on average, and the error halves with the patch size (a first-order
// discretisation error, 1% at 100 mm).
//
// The radiosity filter's flat solvers therefore work with the seen part of
// each patch (Galerkin on the domain the light can reach): its area a_i A_i,
// its direct irradiance H_i / a_i and its row F_ij / a_i, which are the
// means over the seen points when the buried points contribute nothing.
// A point is buried when it is enclosed: each of kRaysPerPoint
// cosine-weighted rays from it meets the back of a face (the inside of the
// block). One ray that meets the front of another face, or leaves the
// scene, proves it open, so an open scene's points (lit through a small
// solid angle, most rays escaping) are never taken for buried; an
// enclosure with a hole is, unless one of the rays finds the hole (a point
// that sees a share v of the outside through it: probability
// (1 - v)^kRaysPerPoint), and light through such a hole is small.
#pragma once
#include <cstdint>
#include <vector>

#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/scene.h"

namespace gi {

struct PatchSeen {
  static constexpr int kScreenPoints = 16;   // points tried on every patch (all buried: the patch is)
  static constexpr int kPoints = 64;         // on a patch where some of them were buried
  static constexpr int kRaysPerPoint = 32;   // at most, per point
  std::vector<float> fraction;  // per face: the share of its area seen (1 for emitters and unusable faces)
  // Per face with 0 < share < 1: its points found open (on the face, not
  // lifted), uniform over the seen part; empty for every other face. The
  // seen part's own light is estimated there (seenPartDirectIrradiance):
  // the patch mean over the share is a ratio of two estimates from different
  // points, unbounded where the share is small.
  std::vector<std::vector<glm::vec3>> seenPoints;
  size_t partial = 0;           // patches with 0 < share < 1
  size_t buried = 0;            // patches with share 0
  double buriedArea = 0;        // sum of (1 - share) A over the patches (local units)
  double area = 0;              // of all usable faces (local units)
  uint64_t rays = 0;
  bool any() const { return partial + buried > 0; }
};

// Every usable, non-emitting face. Deterministic per (face, seed).
// `direct` (optional, per face): a face with direct light has a seen part,
// so it is never taken as wholly buried from its screening points alone.
PatchSeen patchSeenFractions(const Scene& s, const RayCaster& caster, uint32_t seed,
                             const std::vector<glm::vec3>* direct = nullptr,
                             const Progress& progress = Progress(nullptr));

}  // namespace gi
