// A uniform grid over one pass's photons for progressive photon mapping's
// fixed-radius gathers: built in O(N log N) by sorting (cell key, index)
// pairs in parallel, several times faster than a kd-tree build, which would
// dominate a pass otherwise. Internal to the photon-mapping sources.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "gi/photon.h"
#include "photon_internal.h"

namespace gi {

class PhotonGrid {
 public:
  // Photons whose path kind is in pathMask, in cells of edge `cell` (> 0).
  PhotonGrid(const std::vector<Photon>& all, unsigned pathMask, float cell) : inv_(1.f / cell) {
    std::vector<uint32_t> keep;
    keep.reserve(all.size());
    for (uint32_t i = 0; i < all.size(); ++i)
      if (pathMask & (1u << all[i].path)) keep.push_back(i);
    std::vector<std::pair<uint64_t, uint32_t>> order(keep.size());
    tbb::parallel_for(size_t(0), keep.size(), [&](size_t k) { order[k] = {key(cellOf(all[keep[k]].p)), keep[k]}; });
    tbb::parallel_sort(order.begin(), order.end());  // (key, index) pairs: a total order, deterministic
    photons_.resize(order.size());
    tbb::parallel_for(size_t(0), order.size(), [&](size_t k) { photons_[k] = all[order[k].second]; });
    for (size_t k = 0; k < order.size(); ++k)
      if (k == 0 || order[k].first != order[k - 1].first) { keys_.push_back(order[k].first); starts_.push_back(uint32_t(k)); }
    starts_.push_back(uint32_t(order.size()));
  }
  size_t size() const { return photons_.size(); }
  size_t memoryBytes() const {
    return photons_.capacity() * sizeof(Photon) + keys_.capacity() * sizeof(uint64_t) + starts_.capacity() * sizeof(uint32_t);
  }
  // Flux and count of the photons within sqrt(r2) of x that arrived on n's
  // side and whose path kind is in `paths` (bits 1 << PhotonPath); byPath
  // (3 entries, or null) gets the flux by the photons' path kind.
  void gather(const glm::vec3& x, const glm::vec3& n, float r2, glm::dvec3& flux, size_t& count,
              glm::dvec3* byPath = nullptr, unsigned paths = 7u) const {
    if (byPath)
      for (int k = 0; k < 3; ++k) byPath[k] = glm::dvec3(0.0);
    flux = glm::dvec3(0.0);
    count = 0;
    const float r = std::sqrt(r2);
    const glm::ivec3 lo = cellOf(x - glm::vec3(r)), hi = cellOf(x + glm::vec3(r));
    for (int cz = lo.z; cz <= hi.z; ++cz)
      for (int cy = lo.y; cy <= hi.y; ++cy)
        for (int cx = lo.x; cx <= hi.x; ++cx) {
          const uint64_t k = key({cx, cy, cz});
          const auto it = std::lower_bound(keys_.begin(), keys_.end(), k);
          if (it == keys_.end() || *it != k) continue;
          const size_t c = size_t(it - keys_.begin());
          for (uint32_t m = starts_[c]; m < starts_[c + 1]; ++m) {
            const Photon& p = photons_[m];
            const glm::vec3 d = p.p - x;
            if (glm::dot(d, d) > r2 || glm::dot(p.normal(), n) < kSameSide || !((paths >> p.path) & 1u)) continue;
            flux += glm::dvec3(p.power);
            if (byPath) byPath[p.path] += glm::dvec3(p.power);
            ++count;
          }
        }
  }

 private:
  glm::ivec3 cellOf(const glm::vec3& p) const { return glm::ivec3(glm::floor(p * inv_)); }
  static uint64_t key(const glm::ivec3& c) {  // 21 bits per axis, offset to be positive
    auto u = [](int v) { return uint64_t(uint32_t(v + (1 << 20)) & 0x1fffffu); };
    return (u(c.x) << 42) | (u(c.y) << 21) | u(c.z);
  }
  float inv_;
  std::vector<Photon> photons_;  // sorted by cell
  std::vector<uint64_t> keys_;   // distinct cell keys, ascending
  std::vector<uint32_t> starts_; // photons_ range of keys_[c]: [starts_[c], starts_[c + 1])
};

}  // namespace gi
