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

namespace gi {

enum class PhotonKernel {
  Uniform,  // H ~ sum Phi / (pi r^2)
  Cone,     // Jensen 1996: w = 1 - d / (k r), k = 1.1, normalised by (1 - 2 / (3 k))
};

class PhotonMap {
 public:
  // Photons whose path kind has its bit set in `pathMask` (1 << PhotonPath).
  PhotonMap(const std::vector<Photon>& all, unsigned pathMask) : cloud_{all, {}} {
    for (uint32_t i = 0; i < all.size(); ++i)
      if (pathMask & (1u << all[i].path)) cloud_.idx.push_back(i);
    // Positions copied together: the build reads them many times over.
    cloud_.pts.resize(cloud_.idx.size());
    for (size_t k = 0; k < cloud_.idx.size(); ++k) cloud_.pts[k] = all[cloud_.idx[k]].p;
    tree_ = std::make_unique<Tree>(3, cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tree_->buildIndex();
  }
  size_t size() const { return cloud_.idx.size(); }
  // Index and tree; the photons themselves belong to the caller's vector.
  size_t memoryBytes() const {
    return cloud_.idx.capacity() * sizeof(uint32_t) + cloud_.pts.capacity() * sizeof(glm::vec3) + tree_->usedMemory(*tree_);
  }

  // Irradiance at x (unit normal n) from the k nearest photons on the same
  // side within sqrt(r2max). *noise gets the Poisson standard error.
  glm::vec3 irradiance(const glm::vec3& x, const glm::vec3& n, int k, float r2max, PhotonKernel kernel,
                       double* noise = nullptr) const {
    if (size() == 0 || k < 1) return glm::vec3(0.f);
    // More than k: photons on the other side are dropped.
    const size_t want = std::min<size_t>({size(), size_t(k) * 2, kMaxQuery});
    uint32_t idx[kMaxQuery];
    float d2[kMaxQuery];
    const float q[3] = {x.x, x.y, x.z};
    const size_t found = tree_->knnSearch(q, want, idx, d2);
    float d2raw[kMaxQuery];
    std::copy(d2, d2 + found, d2raw);
    int used = 0;
    float r2 = 0.f;
    const Photon* ph[kMaxQuery];
    for (size_t m = 0; m < found && used < k; ++m) {
      if (d2[m] > r2max) break;
      const Photon& p = cloud_.all[cloud_.idx[idx[m]]];
      if (glm::dot(p.normal(), n) < 0.5f) continue;  // other side or another surface
      ph[used] = &p;
      d2[used] = d2[m];
      r2 = d2[m];
      ++used;
    }
    if (used == 0) return glm::vec3(0.f);
    if (used < k) {
      // Fewer than k on this side among the candidates: the density is that
      // of the whole disk examined — up to r2max if the search reached past
      // it, else up to the farthest candidate (the rest lay on other surfaces).
      const bool exhausted = found < want || d2raw[found - 1] > r2max;
      r2 = exhausted && r2max < HUGE_VALF ? r2max : d2raw[found - 1];
    }
    r2 = std::max(r2, 1e-30f);
    const float r = std::sqrt(r2);
    glm::dvec3 sum(0.0);
    double sumL2 = 0.0;
    constexpr float kCone = 1.1f;
    for (int m = 0; m < used; ++m) {
      const float w = kernel == PhotonKernel::Cone ? std::max(0.f, 1.f - std::sqrt(d2[m]) / (kCone * r)) : 1.f;
      sum += double(w) * glm::dvec3(ph[m]->power);
      const double l = double(w) * luminance(ph[m]->power);
      sumL2 += l * l;
    }
    double area = M_PI * double(r2);
    if (kernel == PhotonKernel::Cone) area *= 1.0 - 2.0 / (3.0 * kCone);
    if (noise) *noise = std::sqrt(sumL2) / area;
    return glm::vec3(sum / area);
  }

  // Distance^2 to the k-th nearest photon on the same side (HUGE_VALF if fewer).
  float kthRadius2(const glm::vec3& x, const glm::vec3& n, int k) const {
    if (size() == 0) return HUGE_VALF;
    const size_t want = std::min<size_t>({size(), size_t(k) * 2, kMaxQuery});
    uint32_t idx[kMaxQuery];
    float d2[kMaxQuery];
    const float q[3] = {x.x, x.y, x.z};
    const size_t found = tree_->knnSearch(q, want, idx, d2);
    int used = 0;
    for (size_t m = 0; m < found; ++m) {
      if (glm::dot(cloud_.all[cloud_.idx[idx[m]]].normal(), n) < 0.5f) continue;
      if (++used == k) return d2[m];
    }
    return HUGE_VALF;
  }

 private:
  static constexpr size_t kMaxQuery = 1024;
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
