// The shared AO estimator (gi/ao_shared.h): rays per vertex, pooling by
// Lepski's rule, adaptive rounds.
#include "gi/ao_shared.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include "ambient_internal.h"
#include "ao_pool_internal.h"
#include "gi/huge_pages.h"
#include "gi/sampling.h"

namespace gi {

using namespace pooling;

namespace {

constexpr int kRound = 32;

// Rays [start, start + count) of the sequence of the mesh's vertex vi, the
// same as the per-vertex estimator's (key, warp and frame), added to r.
void castRays(const RayCaster& caster, const AmbientOptions& o, float tfar, uint32_t vi, const glm::vec3& org,
              const glm::vec3& offset, const glm::vec3& n, uint32_t start, uint32_t count, VertexRays& r) {
  const Frame frame(n);
  SobolOwenStream seq(hash3(vi, o.seed, 0x41u));
  seq.seek(start);
  float u0[kRound], u1[kRound], lx[kRound], ly[kRound], lz[kRound];
  glm::vec3 dirs[kRound];
  uint8_t occ[kRound];
  Ray rays[kRound];
  Hit hits[kRound];
  const bool obscurance = o.mode == AmbientMode::Obscurance;
  for (uint32_t done = 0; done < count;) {
    const int m = int(std::min<uint32_t>(kRound, count - done));
    seq.nextBlock(m, u0, u1);
    cosineHemisphereBlock(m, u0, u1, lx, ly, lz);
    for (int j = 0; j < m; ++j) dirs[j] = frame.t * lx[j] + frame.b * ly[j] + frame.n * lz[j];
    if (obscurance) {
      for (int j = 0; j < m; ++j) { rays[j].o = org; rays[j].d = dirs[j]; rays[j].tnear = 0.f; rays[j].tfar = tfar; }
      caster.intersectBatch(rays, size_t(m), hits);
    } else {
      caster.occludedFan(org, dirs, size_t(m), tfar, occ);
    }
    for (int j = 0; j < m; ++j) {
      const double f = obscurance ? obscuranceOf(hits[j], dirs[j], offset, o.maxDistance, double(o.falloffExponent))
                                  : (occ[j] ? 0.0 : 1.0);
      r.sum += f;
      if (o.bentNormals && f > 0.0) r.bent += dirs[j] * float(f);
    }
    done += uint32_t(m);
  }
  r.n += count;
}

// The sum of f(i) over the vertices, in parallel (f may also update vertex
// i's own entries; integer sums: the same in any order).
template <class F>
size_t countVertices(size_t nv, F&& f) {
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, nv, 1 << 14), size_t(0),
      [&](const tbb::blocked_range<size_t>& r, size_t acc) {
        for (size_t i = r.begin(); i < r.end(); ++i) acc += f(i);
        return acc;
      },
      [](size_t a, size_t b) { return a + b; });
}

// How many slices parallelBlocks cuts `work` into: one per `perSlice`, 1 to 64.
size_t slices(size_t work, size_t perSlice) { return std::clamp<size_t>(work / perSlice, 1, 64); }

// Every vertex's rings (searchRings), kept across rounds. They depend on the
// geometry and on which vertices have rays, which the first round settles
// (counts only grow after it), so later rounds pool by walking a list
// instead of searching the mesh again: one read per pooled vertex instead of
// a visit to every edge around it. Per vertex: [rings, count of ring 1, ...,
// count of the last ring, the vertices of ring 1, of ring 2, ...].
class RingLists {
 public:
  // The lists of the vertices with mine[i] = 1; false (none kept) if they
  // would take more than maxBytes. onList(i, list) is called with each
  // vertex's list as soon as it is written (while it is in the cache: the
  // first round pools there).
  template <class OnList>
  bool build(const VertexGraph& g, const std::vector<glm::vec3>& normals, const std::vector<VertexRays>& rays,
             const std::vector<uint8_t>& poolable, const std::vector<uint8_t>& mine, const PoolOptions& o,
             size_t maxBytes, OnList&& onList) {
    const size_t nv = normals.size(), maxEntries = maxBytes / sizeof(uint32_t);
    const int R = std::min(o.maxRings, 64);
    // What the search reads of a neighbour, in one place: one read instead
    // of three arrays (the same rings: ArrayNodes).
    PackedNodes nodes;
    nodes.nodes.resize(nv);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t u = r.begin(); u < r.end(); ++u)
        nodes.nodes[u] = {normals[u], uint32_t(poolable[u] && rays[u].n != 0)};
    });
    std::vector<std::pair<std::vector<uint32_t>*, size_t>> at(nv, {nullptr, 0});
    std::atomic<size_t> entries{0};
    tbb::enumerable_thread_specific<PoolScratch> scratch;
    tbb::enumerable_thread_specific<std::vector<uint32_t>> members;
    // Each thread's share of the expected entries (a regular triangulation:
    // 6h vertices in ring h, so 3R(R+1) in R rings, plus R + 1 counts), and a
    // quarter more. Reserved, not touched: pages a list never reaches cost
    // nothing (measured at 470k vertices: building the lists 0.34 -> 0.25 s).
    const size_t threads = size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
    const size_t reserve = std::min(maxEntries, nv * size_t(1 + R + 3 * R * (R + 1)) * 5 / 4) / threads + 4096;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 1024), [&](const tbb::blocked_range<size_t>& r) {
      if (entries.load(std::memory_order_relaxed) > maxEntries) return;
      std::vector<uint32_t>& list = lists_.local();
      if (list.capacity() == 0) list.reserve(reserve);  // no copies while the lists grow
      std::vector<uint32_t>& ring = members.local();
      PoolScratch& sc = scratch.local();
      uint32_t counts[65];
      const size_t before = list.size();
      for (size_t i = r.begin(); i < r.end(); ++i) {
        if (!mine[i]) continue;
        ring.clear();
        std::fill(counts, counts + R + 1, 0u);
        const int rings = searchRings(uint32_t(i), g, nodes, o, R, sc, [&](int h, uint32_t u) {
          ++counts[h];
          ring.push_back(u);
        });
        const size_t start = list.size();
        at[i] = {&list, start};
        list.push_back(uint32_t(rings));
        list.insert(list.end(), counts + 1, counts + 1 + rings);
        list.insert(list.end(), ring.begin(), ring.end());
        onList(uint32_t(i), list.data() + start);
      }
      entries += list.size() - before;
    });
    if (entries.load() > maxEntries) {
      lists_.clear();
      return false;
    }
    head_.assign(nv, nullptr);
    for (size_t i = 0; i < nv; ++i)
      if (at[i].first) head_[i] = at[i].first->data() + at[i].second;
    return true;
  }
  const uint32_t* operator[](size_t i) const { return head_[i]; }

 private:
  tbb::enumerable_thread_specific<std::vector<uint32_t>> lists_;
  std::vector<const uint32_t*> head_;
};

// What pooling reads of a neighbour, in one place (one cache line or two).
struct PoolPoint {
  glm::vec3 p;
  uint32_t n = 0;
  double sum = 0.0;
};

// poolVertex over vertex i's listed rings: the same sums in the same order.
Pooled poolListed(uint32_t i, const uint32_t* list, const std::vector<PoolPoint>& pts,
                  const std::vector<glm::vec3>& normals, const std::vector<VertexRays>& rays, bool bent,
                  const PoolOptions& o) {
  const glm::vec3 pi = pts[i].p;
  const Frame frame(normals[i]);
  const uint32_t rings = list[0];
  const uint32_t* member = list + 1 + rings;
  return chooseScale(rays[i], o, [&](int h, PoolSums& grown, BentSums& db) -> uint32_t {
    if (uint32_t(h) > rings) return 0;
    const uint32_t count = list[h];
    for (uint32_t k = 0; k < count; ++k) {
      const PoolPoint& q = pts[member[k]];
      const glm::vec3 d = q.p - pi;
      const double dx = glm::dot(d, frame.t), dy = glm::dot(d, frame.b);
      grown.add(q.n, q.sum, dx, dy, 0.0);  // AO: bounded values
      if (bent) db.add(rays[member[k]].bent, dx, dy);  // zero unless bent normals are asked for
    }
    member += count;
    return count;
  });
}

}  // namespace

SharedStats computeSharedAmbient(const Scene& scene, const RayCaster& caster, const AmbientOptions& o,
                                 const std::vector<glm::vec3>& normals, const std::vector<glm::vec3>& origins,
                                 const std::vector<uint8_t>& poolable, const std::vector<uint8_t>& mine,
                                 const std::vector<uint8_t>& usable, AmbientResult& res, const Progress& progress) {
  // The estimator's arrays (the vertex graph, the rings' lists, the rays
  // and pools) are written once and then read near where they were last
  // read: 4 KiB pages, whose first touch costs less (gi/huge_pages.h).
  const HugePageAdvicePause smallPages;
  const size_t nv = scene.vertexCount();
  const VertexPart& part = o.vertices;
  const bool split = !part.all();
  if (split && !part.sumOverParts)
    throw std::logic_error("the shared AO estimator split over parts needs their sum (VertexPart::sumOverParts)");
  Timer graphTimer;
  const VertexGraph g = VertexGraph::build(scene, &usable);
  SharedStats st;
  st.poolSeconds = graphTimer.seconds();
  PoolOptions po;
  po.maxRings = o.shareRings;
  po.normalCos = std::cos(glm::radians(o.shareNormalAngleDeg));
  const float tfar = o.maxDistance > 0.0 ? float(o.maxDistance) : std::numeric_limits<float>::infinity();
  const bool adaptive = o.targetError > 0.0;
  const uint32_t first = uint32_t(adaptive ? std::min(o.minRays, o.maxRays) : o.raysPerVertex);
  std::vector<VertexRays> rays(nv);
  std::vector<uint32_t> want(nv, 0), pooledWith(nv, 0);  // pooledWith: ray counts at the last pooling
  for (size_t i = 0; i < nv; ++i)
    if (mine[i]) want[i] = first;
  std::vector<uint32_t> frontier;                                 // the vertices marked last
  tbb::enumerable_thread_specific<std::vector<uint32_t>> grown;   // and those they mark, per thread
  std::vector<std::atomic<uint32_t>> marked(nv);  // the round that last marked each vertex to pool again
  std::vector<Pooled> pooled(nv);
  std::vector<double> exchange;
  tbb::enumerable_thread_specific<PoolScratch> scratch;
  RingLists ringLists;
  bool listed = false;
  std::vector<PoolPoint> points;
  // Progress: rounds double the ray count, so the last rounds dominate; the
  // bar follows the rounds' share of the largest possible count.
  const double total = std::log2(double(adaptive ? std::max(o.maxRays, 1) : 1) / double(std::max(first, 1u))) + 1.0;
  for (int round = 0;; ++round) {
    const Progress bar = progress.sub(std::min(0.95, round / total), std::min(0.95, (round + 1) / total));
    Timer cast;
    // Slices of about a second of work each (progress and cancelling happen
    // between slices): each slice ends in a wait for the slowest thread,
    // which on a machine shared with other jobs costs a time slice of the
    // scheduler, and the later adaptive rounds cast few rays.
    const size_t work = countVertices(nv, [&](size_t i) -> size_t { return want[i] - std::min(want[i], rays[i].n); });
    parallelBlocks(nv, bar.sub(0.0, 0.8), "casting rays", [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i)
        if (want[i] > rays[i].n)
          castRays(caster, o, tfar, uint32_t(part.meshIndex(i)), origins[i], origins[i] - scene.positions[i], normals[i], rays[i].n,
                   want[i] - rays[i].n, rays[i]);
    }, slices(work, size_t(1) << 20));
    if (split) {
      // Every part gets every vertex's rays (each vertex's from the part it
      // belongs to; a representative another part's duplicates need is cast
      // there too, alike, but not sent twice; sums of one nonzero term are
      // exact): the pools are then the whole run's, bit for bit.
      exchange.assign(5 * nv, 0.0);
      for (size_t i = 0; i < nv; ++i)
        if (mine[i] && part.contains(i, nv)) {
          const VertexRays& r = rays[i];
          double* x = &exchange[5 * i];
          x[0] = r.n; x[1] = r.sum; x[2] = r.bent.x; x[3] = r.bent.y; x[4] = r.bent.z;
        }
      part.sumOverParts(exchange);
      for (size_t i = 0; i < nv; ++i)
        if (poolable[i] && !(mine[i] && part.contains(i, nv))) {
          const double* x = &exchange[5 * i];
          rays[i] = {uint32_t(x[0]), x[1], 0.0, glm::vec3(float(x[2]), float(x[3]), float(x[4]))};
        }
    }
    st.castSeconds += cast.seconds();
    Timer pool;
    if (listed)
      tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i) { points[i].n = rays[i].n; points[i].sum = rays[i].sum; }
      });
    bool pooledAll = false;
    if (round == 0) {
      // Lists of rings need every poolable vertex to have rays from now on.
      bool settled = true;
      for (size_t i = 0; i < nv; ++i) settled = settled && !(poolable[i] && rays[i].n == 0);
      if (settled) {
        points.resize(nv);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
          for (size_t i = r.begin(); i < r.end(); ++i) points[i] = {scene.positions[i], rays[i].n, rays[i].sum};
        });
        // The first pooling of every vertex happens as its list is written.
        listed = ringLists.build(g, normals, rays, poolable, mine, po, o.shareRingBytes,
                                 [&](uint32_t i, const uint32_t* list) {
                                   pooled[i] = poolListed(i, list, points, normals, rays, o.bentNormals, po);
                                 });
        pooledAll = listed;
      }
    }
    // Pooled (again): every vertex within reach of one whose rays changed,
    // found from those vertices outwards (late rounds change few), ring by
    // ring in parallel. Two threads may both take a vertex into the next
    // ring: it is then walked twice, which marks nothing more.
    const uint32_t stamp = uint32_t(round) + 1;
    for (auto& found : grown) found.clear();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<uint32_t>& out = grown.local();
      for (size_t i = r.begin(); i < r.end(); ++i)
        if (rays[i].n != pooledWith[i]) {
          pooledWith[i] = rays[i].n;
          marked[i].store(stamp, std::memory_order_relaxed);
          out.push_back(uint32_t(i));
        }
    });
    size_t marks = 0;
    for (int ring = 0; ring < po.maxRings && !pooledAll; ++ring) {
      frontier.clear();
      for (auto& found : grown) {
        frontier.insert(frontier.end(), found.begin(), found.end());
        found.clear();
      }
      if (frontier.empty()) break;
      marks += frontier.size();
      tbb::parallel_for(tbb::blocked_range<size_t>(0, frontier.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<uint32_t>& out = grown.local();
        for (size_t k = r.begin(); k < r.end(); ++k) {
          const uint32_t v = frontier[k];
          for (uint32_t e = g.offset[v]; e < g.offset[v + 1]; ++e) {
            const uint32_t u = g.nbr[e];
            if (marked[u].load(std::memory_order_relaxed) != stamp) {
              marked[u].store(stamp, std::memory_order_relaxed);
              out.push_back(u);
            }
          }
        }
      });
    }
    for (const auto& found : grown) marks += found.size();
    // This part's marked vertices, found by a scan of the marks in memory
    // order (a sort of the list cost 0.08 s a round at 1.9M vertices).
    if (!pooledAll)
      parallelBlocks(nv, bar.sub(0.8, 1.0), "sharing between neighbours", [&](size_t b, size_t e) {
        PoolScratch& sc = scratch.local();
        for (size_t i = b; i < e; ++i) {
          if (marked[i].load(std::memory_order_relaxed) != stamp || !mine[i]) continue;
          pooled[i] = listed ? poolListed(uint32_t(i), ringLists[i], points, normals, rays, o.bentNormals, po)
                             : poolVertex(uint32_t(i), g, scene.positions, normals, rays, poolable, po, sc);
        }
      }, slices(marks, size_t(1) << 16));
    ++st.rounds;
    st.poolSeconds += pool.seconds();
    if (!adaptive) break;
    // Vertices above the target cast twice their rays (all parts go on while any does).
    double more = double(countVertices(nv, [&](size_t i) -> size_t {
      if (!(mine[i] && pooled[i].stdError > o.targetError && rays[i].n < uint32_t(o.maxRays))) return 0;
      want[i] = std::min<uint32_t>(uint32_t(o.maxRays), 2 * rays[i].n);
      return 1;
    }));
    if (split) {
      std::vector<double> m{more};
      part.sumOverParts(m);
      more = m[0];
    }
    if (more == 0) break;
  }
  double pooledVertices = 0, rings = 0;
  size_t traced = 0;
  for (size_t i = 0; i < nv; ++i) {
    if (!mine[i]) continue;
    const Pooled& p = pooled[i];
    res.value[i] = p.value;
    res.stdError[i] = p.stdError;
    res.rays[i] = int(rays[i].n);
    if (o.bentNormals) res.bentNormal[i] = glm::length(p.bent) > 0.f ? glm::normalize(p.bent) : normals[i];
    pooledVertices += p.vertices;
    rings += p.rings;
    ++traced;
  }
  st.meanPooledVertices = traced ? pooledVertices / double(traced) : 0.0;
  st.meanRings = traced ? rings / double(traced) : 0.0;
  return st;
}

}  // namespace gi
