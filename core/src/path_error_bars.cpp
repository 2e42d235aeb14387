// The reference's error bars: the variance pooled over a vertex's mesh ring
// (path_error_bars.h).
#include "path_error_bars.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gi::reference {

// cov: 6 numbers per vertex (as Cov); paths: nv counts.
RingVariance ringVariance(const VertexGraph& g, const double* cov, const std::vector<double>& paths) {
  const size_t nv = paths.size();
  RingVariance out;
  out.mean.assign(nv, Cov{});
  out.vertices.assign(nv, 0);
  // Each level's new vertices: the frontier's neighbours, sorted and made
  // unique, less those already in the ring (kept sorted: binary searches),
  // so a vertex of high valence (a fan's hub) costs R log R, not R^2.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 1024), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<uint32_t> ring, frontier, next, merged;
    for (size_t i = r.begin(); i < r.end(); ++i) {
      if (!(paths[i] >= 2)) continue;
      ring.assign(1, uint32_t(i));
      frontier.assign(1, uint32_t(i));
      uint32_t traced = 1;
      for (int level = 1; level <= 4 && !frontier.empty(); ++level) {
        if (level > 2 && traced >= kPooledVertices) break;
        next.clear();
        for (uint32_t a : frontier)
          for (uint32_t k = g.offset[a]; k < g.offset[a + 1]; ++k) next.push_back(g.nbr[k]);
        std::sort(next.begin(), next.end());
        next.erase(std::unique(next.begin(), next.end()), next.end());
        next.erase(std::remove_if(next.begin(), next.end(),
                                  [&](uint32_t j) { return std::binary_search(ring.begin(), ring.end(), j); }),
                   next.end());
        for (uint32_t j : next) traced += paths[j] >= 2;
        merged.resize(ring.size() + next.size());
        std::merge(ring.begin(), ring.end(), next.begin(), next.end(), merged.begin());
        ring.swap(merged);
        frontier.swap(next);
      }
      // The ring is sorted: sums in vertex order, the same bits in any thread.
      Cov sum{};
      uint32_t n = 0;
      for (uint32_t j : ring)
        if (paths[j] >= 2) {
          for (int c = 0; c < 6; ++c) sum[size_t(c)] += cov[6 * size_t(j) + size_t(c)];
          ++n;
        }
      for (int c = 0; c < 6; ++c) out.mean[i][size_t(c)] = sum[size_t(c)] / double(n);  // n >= 1: the vertex itself
      out.vertices[i] = n;
    }
  });
  return out;
}

// w^T C w for the symmetric 3 x 3 matrix C: the variance of w . H.
double quadratic(const Cov& C, const glm::dvec3& w) {
  return w.x * w.x * C[0] + w.y * w.y * C[1] + w.z * w.z * C[2] +
         2.0 * (w.x * w.y * C[3] + w.x * w.z * C[4] + w.y * w.z * C[5]);
}


}  // namespace gi::reference
