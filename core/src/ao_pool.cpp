// Pooling one vertex's neighbours (gi/ao_shared.h): poolVertex by a search
// of the rings, and poolMeans for the final gather.
#include <atomic>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ao_pool_internal.h"
#include "gi/ao_shared.h"
#include "gi/sampling.h"

namespace gi {

using namespace pooling;

Pooled poolVertex(uint32_t i, const VertexGraph& g, const std::vector<glm::vec3>& positions,
                  const std::vector<glm::vec3>& normals, const std::vector<VertexRays>& rays,
                  const std::vector<uint8_t>& poolable, const PoolOptions& o, PoolScratch& sc) {
  const glm::vec3 pi = positions[i];
  const Frame frame(normals[i]);
  return chooseScale(rays[i], o, [&](int h, PoolSums& grown, BentSums& db) -> uint32_t {
    if (h == 1) startRings(i, normals.size(), sc);
    nextRing(i, g, ArrayNodes{normals, rays, poolable}, o, sc);
    for (uint32_t u : sc.frontier) {
      const glm::vec3 d = positions[u] - pi;
      const double dx = glm::dot(d, frame.t), dy = glm::dot(d, frame.b);
      grown.add(rays[u].n, rays[u].sum, dx, dy, rays[u].var);
      db.add(rays[u].bent, dx, dy);
    }
    return uint32_t(sc.frontier.size());
  });
}

std::vector<glm::vec3> poolMeans(const Scene& s, const std::vector<glm::vec3>& normals,
                                 const std::vector<glm::vec3>& means, const std::vector<VertexRays>& lumIn,
                                 const PoolOptions& o, const VertexPart& part, RunStats* stats) {
  const size_t nv = s.vertexCount();
  std::vector<VertexRays> lum(lumIn);
  std::vector<glm::vec3> own(means);
  if (!part.all()) {
    if (!part.sumOverParts) throw std::logic_error("pooling split over parts needs their sum (VertexPart::sumOverParts)");
    // One non-zero term per vertex (its part's): the sums are exact.
    std::vector<double> x(6 * nv, 0.0);
    for (size_t v = 0; v < nv; ++v)
      if (part.contains(v, nv) && lum[v].n > 0) {
        double* e = &x[6 * v];
        e[0] = lum[v].n, e[1] = lum[v].sum, e[2] = lum[v].var, e[3] = own[v].r, e[4] = own[v].g, e[5] = own[v].b;
      }
    part.sumOverParts(x);
    for (size_t v = 0; v < nv; ++v) {
      const double* e = &x[6 * v];
      lum[v] = VertexRays{uint32_t(e[0]), e[1], e[2], glm::vec3(0.f)};
      own[v] = glm::vec3(float(e[3]), float(e[4]), float(e[5]));
    }
  }
  std::vector<uint8_t> poolable(nv);
  for (size_t v = 0; v < nv; ++v) poolable[v] = lum[v].n > 0;
  // Each channel as sums of rays for the fit (the variances are not used at
  // a fixed scale).
  std::vector<VertexRays> channel[3];
  for (int c = 0; c < 3; ++c) {
    channel[c].resize(nv);
    for (size_t v = 0; v < nv; ++v) channel[c][v] = VertexRays{lum[v].n, double(own[v][c]) * lum[v].n, 0.0, glm::vec3(0.f)};
  }
  const VertexGraph g = VertexGraph::build(s);
  std::vector<glm::vec3> out(means);
  std::atomic<uint64_t> pooled{0}, counted{0};
  parallelBlocks(nv, Progress(nullptr), "pooling", [&](size_t b, size_t e) {
    PoolScratch sc;
    uint64_t pv = 0, n = 0;
    for (size_t v = b; v < e; ++v) {
      if (!poolable[v] || !part.contains(v, nv)) continue;
      const Pooled p = poolVertex(uint32_t(v), g, s.positions, normals, lum, poolable, o, sc);
      PoolOptions at = o;
      at.fixedRings = p.rings;
      for (int c = 0; c < 3; ++c)
        out[v][c] = poolVertex(uint32_t(v), g, s.positions, normals, channel[c], poolable, at, sc).value;
      pv += p.vertices, ++n;
    }
    pooled += pv, counted += n;
  });
  if (stats && counted.load() > 0) stats->add("gather_pool_vertices", double(pooled.load()) / double(counted.load()));
  return out;
}

}  // namespace gi
