// The vertex adjacency of the usable faces (gi/vertex_graph.h).
#include "gi/vertex_graph.h"

#include <algorithm>
#include <atomic>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gi {

VertexGraph VertexGraph::build(const Scene& s, const std::vector<uint8_t>* usable) {
  const size_t nv = s.vertexCount();
  std::vector<uint8_t> own;
  const std::vector<uint8_t>& ok = usableFaces(s, usable, own);
  VertexGraph g;
  // Every corner lists the face's other two corners, in parallel: the counts
  // and the slots are taken atomically, so the order within a vertex's range
  // varies from run to run, and the sort below makes it the same.
  std::vector<std::atomic<uint32_t>> count(nv + 1);
  const auto faces = tbb::blocked_range<size_t>(0, s.faceCount(), 1 << 14);
  tbb::parallel_for(faces, [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f < r.end(); ++f)
      if (ok[f])
        for (int k = 0; k < 3; ++k) count[s.triangles[f][k] + 1].fetch_add(2, std::memory_order_relaxed);
  });
  g.offset.assign(nv + 1, 0);
  for (size_t v = 0; v < nv; ++v) g.offset[v + 1] = g.offset[v] + count[v + 1].load(std::memory_order_relaxed);
  for (size_t v = 0; v < nv; ++v) count[v].store(g.offset[v], std::memory_order_relaxed);  // now each vertex's next slot
  g.nbr.resize(g.offset[nv]);
  tbb::parallel_for(faces, [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f < r.end(); ++f) {
      if (!ok[f]) continue;
      const auto& t = s.triangles[f];
      for (int k = 0; k < 3; ++k) {
        const uint32_t slot = count[t[k]].fetch_add(2, std::memory_order_relaxed);
        g.nbr[slot] = t[(k + 1) % 3];
        g.nbr[slot + 1] = t[(k + 2) % 3];
      }
    }
  });
  // Each neighbour once (a manifold vertex lists each twice): sorted and
  // made unique within each vertex's range in parallel, then packed.
  std::vector<uint32_t> unique(nv + 1, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v < r.end(); ++v) {
      const auto b = g.nbr.begin() + g.offset[v], e = g.nbr.begin() + g.offset[v + 1];
      std::sort(b, e);
      unique[v + 1] = uint32_t(std::unique(b, e) - b);
    }
  });
  for (size_t v = 0; v < nv; ++v) unique[v + 1] += unique[v];
  std::vector<uint32_t> packed(unique[nv]);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v < r.end(); ++v)
      std::copy_n(g.nbr.begin() + g.offset[v], unique[v + 1] - unique[v], packed.begin() + unique[v]);
  });
  g.offset.swap(unique);
  g.nbr.swap(packed);
  return g;
}

void atLeastRingMean(const VertexGraph& g, const std::vector<uint8_t>& use, std::vector<double>& x) {
  const size_t nv = x.size();
  std::vector<double> mean = x;
  for (int ring = 0; ring < 2; ++ring) {  // a mean over the 1-ring, twice: about two rings
    std::vector<double> wider(nv);
    for (size_t v = 0; v < nv; ++v) {
      if (!use[v]) continue;
      double sum = mean[v];
      size_t n = 1;
      for (uint32_t k = g.offset[v]; k < g.offset[v + 1]; ++k)
        if (use[g.nbr[k]]) sum += mean[g.nbr[k]], ++n;
      wider[v] = sum / double(n);
    }
    mean.swap(wider);
  }
  for (size_t v = 0; v < nv; ++v)
    if (use[v]) x[v] = std::max(x[v], mean[v]);
}

}  // namespace gi
