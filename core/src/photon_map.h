// A kd-tree (nanoflann) over a subset of the photons and the density
// estimates read from it. Internal to the photon-mapping sources.
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <nanoflann.hpp>

#include "gi/color.h"
#include "gi/photon.h"
#include "photon_internal.h"
#include "photon_surface.h"

namespace gi {

enum class PhotonKernel {
  Uniform,  // H ~ sum Phi / A(r)  (A = pi r^2 on a plane)
  Cone,     // Jensen 1996: w = 1 - d / (k r), k = 1.1, over int w dA  (pi r^2 (1 - 2 / (3 k)) on a plane)
};

// Which photons an estimate reads: their path kinds (bits 1 << PhotonPath)
// and the fewest hits their paths had left (needs the map's hitsLeft).
struct PhotonOnly {
  unsigned paths = 7u;
  int minHitsLeft = 0;
  bool widen = true;      // search past the 2k nearest while fewer than k are on this side
  uint32_t skipEvery = 0;  // if > 0: the map's photons i (photon(i)) with i % skipEvery == 0 left out
  // If set: only the photons a ray from `from` (the estimate's point lifted
  // off its surface) reaches, each lifted by eps along its normal. Where
  // another surface rises inside the estimate's sphere, photons behind it
  // lit the point through it: a floor vertex under a glossy block read the
  // caustic the block throws around its foot (an outside audit).
  const RayCaster* visibleFrom = nullptr;
  glm::vec3 from{0.f};
  float eps = 0.f;
};

class PhotonMap {
 public:
  // Photons whose path kind has its bit set in `pathMask` (1 << PhotonPath),
  // but for those whose path had no hits left (`hitsLeft`, if given, one
  // count per photon as tracePhotons writes it: 0 at a path's last allowed
  // hit). `surface` normalises the estimates (it must outlive the map, and
  // so must `hitsLeft`).
  PhotonMap(const std::vector<Photon>& all, unsigned pathMask, const GatherSurface& surface,
            const std::vector<uint8_t>* hitsLeft = nullptr)
      : surface_(surface), left_(hitsLeft), cloud_{all, {}} {
    for (uint32_t i = 0; i < all.size(); ++i)
      if ((pathMask & (1u << all[i].path)) && !(hitsLeft && (*hitsLeft)[i] == 0)) cloud_.idx.push_back(i);
    // Positions copied together: the build reads them many times over.
    cloud_.pts.resize(cloud_.idx.size());
    for (size_t k = 0; k < cloud_.idx.size(); ++k) cloud_.pts[k] = all[cloud_.idx[k]].p;
    tree_ = std::make_unique<Tree>(3, cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tree_->buildIndex();
    glm::dvec3 sum(0.0);
    for (uint32_t i : cloud_.idx) sum += glm::dvec3(all[i].power);
    meanPower_ = cloud_.idx.empty() ? glm::vec3(0.f) : glm::vec3(sum / double(cloud_.idx.size()));
  }
  size_t size() const { return cloud_.idx.size(); }
  // The map's i-th photon (i < size()).
  const Photon& photon(size_t i) const { return cloud_.all[cloud_.idx[i]]; }
  // Index and tree; the photons themselves belong to the caller's vector.
  size_t memoryBytes() const {
    return cloud_.idx.capacity() * sizeof(uint32_t) + cloud_.pts.capacity() * sizeof(glm::vec3) + tree_->usedMemory(*tree_);
  }

  // Irradiance at x (unit normal n) from the k nearest photons on the same
  // side within sqrt(r2max), over the area of the counted surface within
  // their radius (photon_surface.h; pi r^2 on a plane all around x). *noise
  // gets the Poisson standard error of noiseWeight . H (the luminance of H
  // by default; the luminance of rho H with noiseWeight = rho times the
  // luminance weights: the two differ where both are coloured, and a
  // coloured room's error bars were 2.5 to 4 times too small, an outside
  // audit), *photons the number of photons used;
  // byPath (3 entries, or null) gets the same estimate's terms added by the
  // photons' path kind (they sum to the result within float rounding).
  // `only` narrows the photons read (their path kinds, the hits their paths
  // had left); *radius gets the estimate's radius (0 without photons),
  // *twoLeft (needs hitsLeft) the part of the estimate from the photons
  // whose paths had two or more hits left.
  glm::vec3 irradiance(const glm::vec3& x, const glm::vec3& n, int k, float r2max, PhotonKernel kernel,
                       double* noise = nullptr, int* photons = nullptr, glm::vec3* byPath = nullptr,
                       const PhotonOnly& only = PhotonOnly(), float* radius = nullptr,
                       glm::vec3* twoLeft = nullptr, const glm::vec3& noiseWeight = glm::vec3(kLuminanceWeights)) const {
    if (photons) *photons = 0;
    if (radius) *radius = 0.f;
    if (twoLeft) *twoLeft = glm::vec3(0.f);
    if (size() == 0 || k < 1) return glm::vec3(0.f);
    Query q;
    nearestSameSide(x, n, k, r2max, q, only);
    if (photons) *photons = q.used;
    if (q.used == 0) {
      // No photon within the radius cap: the density could be up to about
      // one photon there, which the search cannot tell from none; that is
      // its standard error (it read 0: vertices missing all their indirect
      // light, -82% in a room lit through a window at 2,000 photons, had
      // error bars of 0; an outside audit).
      if (noise && r2max < HUGE_VALF) {
        const float rMax = std::sqrt(r2max);
        double area = surface_.area(x, n, rMax);
        if (!(area > 0.0)) area = M_PI * double(r2max);
        *noise = double(glm::dot(noiseWeight, meanPower_)) / area;
      }
      return glm::vec3(0.f);
    }
    float r2 = q.d2[q.used - 1];
    if (q.used < k) {
      // Fewer than k on this side: the density is that of the whole ball
      // examined, up to r2max if the search reached past it, else up to the
      // farthest candidate (the rest lay on other surfaces).
      r2 = q.exhausted && r2max < HUGE_VALF ? r2max : q.farthest2;
    }
    r2 = std::max(r2, surface_.minRadius2());
    const float r = std::sqrt(r2);
    if (radius) *radius = r;
    // When the k-th photon sets the radius it lies on the disk's edge, and
    // counting it gives k / (pi r_k^2) photons per unit area, whose mean is
    // k / (k - 1) times the density (pi r_k^2 times the density is Gamma(k)
    // distributed for a Poisson process, and E[1 / Gamma(k)] = 1 / (k - 1)):
    // 8% too high at k = 16, 1.6% at the default 64. The k - 1 photons inside
    // give the density without that bias (the k-nearest-neighbour density
    // estimate of Loftsgaarden and Quesenberry 1965). Found by an outside
    // check: a closed box's reflected light 1.33 times too high at k = 4.
    // k = 1 keeps its one photon (no estimate of that form has a mean).
    const int counted = q.used == k && k >= 2 ? q.used - 1 : q.used;
    glm::dvec3 sum(0.0), sumTwo(0.0);
    glm::dvec3 sumPath[3] = {glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0)};
    double sumL2 = 0.0;
    for (int m = 0; m < counted; ++m) {
      const float w = kernel == PhotonKernel::Cone ? std::max(0.f, 1.f - std::sqrt(q.d2[m]) / (kCone * r)) : 1.f;
      sum += double(w) * glm::dvec3(q.ph[m]->power);
      if (byPath) sumPath[q.ph[m]->path] += double(w) * glm::dvec3(q.ph[m]->power);
      if (twoLeft && left_ && (*left_)[size_t(q.ph[m] - cloud_.all.data())] >= 2)
        sumTwo += double(w) * glm::dvec3(q.ph[m]->power);
      const double l = double(w) * glm::dot(noiseWeight, q.ph[m]->power);
      sumL2 += l * l;
    }
    double area = kernel == PhotonKernel::Cone ? surface_.coneArea(x, n, r, kCone) : surface_.area(x, n, r);
    // The gather point's own faces hold it; no area only for a point off every counted face.
    if (!(area > 0.0)) area = M_PI * double(r2) * (kernel == PhotonKernel::Cone ? 1.0 - 2.0 / (3.0 * kCone) : 1.0);
    if (noise) *noise = std::sqrt(sumL2) / area;
    if (byPath)
      for (int p = 0; p < 3; ++p) byPath[p] += glm::vec3(sumPath[p] / area);
    if (twoLeft) *twoLeft = glm::vec3(sumTwo / area);
    return glm::vec3(sum / area);
  }

  // Distance^2 to the k-th nearest photon on the same side (HUGE_VALF if fewer).
  float kthRadius2(const glm::vec3& x, const glm::vec3& n, int k) const {
    if (size() == 0 || k < 1) return HUGE_VALF;
    Query q;
    nearestSameSide(x, n, k, HUGE_VALF, q);
    return q.used == k ? q.d2[k - 1] : HUGE_VALF;
  }

 private:
  glm::vec3 meanPower_{0.f};  // of the photons, for an estimate that finds none
  static constexpr size_t kMaxQuery = 1024;
  static constexpr float kCone = 1.1f;
  // The nearest photons on n's side (at most k, within r2max), nearest first.
  struct Query {
    const Photon* ph[kMaxQuery];
    float d2[kMaxQuery];
    int used = 0;
    bool exhausted = false;  // every photon within sqrt(farthest2) examined, and none beyond r2max left out
    float farthest2 = 0.f;   // distance^2 of the farthest candidate examined
  };
  // Candidates come from the kd-tree in any orientation: 2k first, then more
  // (up to kMaxQuery) while fewer than k (but some) lie on this side, as at a
  // crease or corner where most of the nearest photons are on the other faces.
  void nearestSameSide(const glm::vec3& x, const glm::vec3& n, int k, float r2max, Query& q,
                       const PhotonOnly& only = PhotonOnly()) const {
    const float p[3] = {x.x, x.y, x.z};
    uint32_t idx[kMaxQuery];
    float d2[kMaxQuery];
    size_t want = std::min<size_t>({size(), size_t(k) * 2, kMaxQuery});
    for (;;) {
      const size_t found = tree_->knnSearch(p, want, idx, d2);
      q.used = 0;
      bool pastCap = false;
      for (size_t m = 0; m < found && q.used < k; ++m) {
        if (d2[m] > r2max) { pastCap = true; break; }
        const uint32_t i = cloud_.idx[idx[m]];
        const Photon& ph = cloud_.all[i];
        if (glm::dot(ph.normal(), n) < kSameSide) continue;  // other side or another surface
        if (only.skipEvery && idx[m] % only.skipEvery == 0) continue;
        if (!((only.paths >> ph.path) & 1u) || (only.minHitsLeft > 0 && left_ && (*left_)[i] < only.minHitsLeft))
          continue;
        if (only.visibleFrom && !visible(only, ph)) continue;
        q.ph[q.used] = &ph;
        q.d2[q.used] = d2[m];
        ++q.used;
      }
      q.farthest2 = found ? d2[found - 1] : 0.f;
      q.exhausted = found < want || pastCap || (found && d2[found - 1] > r2max);
      if (q.used >= k || q.exhausted || !only.widen || want >= std::min<size_t>(size(), kMaxQuery)) return;
      // Enough candidates for k on this side at the share seen, with a
      // margin; where none of the 2k was on this side, four times as many
      // (up to kMaxQuery). A vertex at the top edge of a block's side, whose
      // nearest photons all lay on the brighter top, read 0 instead of 0.25
      // (z -72; 7 of the Cornell box's vertices at k = 8, at any photon
      // count; an outside audit).
      want = q.used == 0 ? std::min<size_t>({size(), want * 4, kMaxQuery})
                         : std::min<size_t>({size(), std::max(want * 2, want * size_t(k) * 5 / (size_t(q.used) * 4)), kMaxQuery});
    }
  }
  static bool visible(const PhotonOnly& only, const Photon& ph) {
    const glm::vec3 d = ph.p + ph.normal() * only.eps - only.from;
    const float len = glm::length(d);
    if (!(len > 0.f)) return true;
    Ray r;
    r.o = only.from;
    r.d = d / len;
    r.tfar = len * (1.f - 1e-4f);
    return !only.visibleFrom->occluded(r);
  }
  const GatherSurface& surface_;
  const std::vector<uint8_t>* left_;
  struct Cloud {
    const std::vector<Photon>& all;
    std::vector<uint32_t> idx;
    std::vector<glm::vec3> pts;  // positions of idx, contiguous
    size_t kdtree_get_point_count() const { return idx.size(); }
    float kdtree_get_pt(size_t i, size_t d) const { return pts[i][int(d)]; }
    template <class B> bool kdtree_get_bbox(B&) const { return false; }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3, uint32_t>;
  Cloud cloud_;
  std::unique_ptr<Tree> tree_;
};

}  // namespace gi
