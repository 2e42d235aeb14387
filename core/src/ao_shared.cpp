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
#include "gi/huge_pages.h"
#include "gi/sampling.h"

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

namespace {

// Weighted sums of one pool for the first-order fit f(d) = a + g.d over the
// tangent-plane offsets d of its vertices (weights: their ray counts).
struct PoolSums {
  double W = 0, Y = 0;            // sum n, sum of ray values
  double X[2] = {0, 0};           // sum n d
  double XX[3] = {0, 0, 0};       // sum n d d^T (xx, xy, yy)
  double XY[2] = {0, 0};          // sum d y (y = the vertex's sum of ray values)
  double VW = 0;                  // sum n var (unbounded values)
  void add(double n, double y, double dx, double dy, double var) {
    W += n; Y += y; VW += n * var;
    X[0] += n * dx; X[1] += n * dy;
    XX[0] += n * dx * dx; XX[1] += n * dx * dy; XX[2] += n * dy * dy;
    XY[0] += dx * y; XY[1] += dy * y;
  }
};

// The fitted value at d = 0 and its variance over v: least squares of the
// vertices' means with weights n (their variances are v / n), i.e.
// a = Y/W - g.xbar, Var(a) = v (1/W + xbar^T C^-1 xbar) with C the centred
// second moments. Too few or collinear vertices for a slope: the mean.
struct Fit {
  double a = 0, varOverV = 0;
};
Fit fit(const PoolSums& s) {
  Fit f;
  f.a = s.Y / s.W;
  f.varOverV = 1.0 / s.W;
  const double mx = s.X[0] / s.W, my = s.X[1] / s.W;
  const double cxx = s.XX[0] - s.W * mx * mx, cxy = s.XX[1] - s.W * mx * my, cyy = s.XX[2] - s.W * my * my;
  const double det = cxx * cyy - cxy * cxy, tr = cxx + cyy;
  if (!(tr > 0.0) || det <= 1e-3 * tr * tr) return f;  // no spread in some direction: no slope
  const double ry = s.XY[0] - mx * s.Y, rz = s.XY[1] - my * s.Y;
  const double gx = (cyy * ry - cxy * rz) / det, gy = (cxx * rz - cxy * ry) / det;
  f.a = s.Y / s.W - (gx * mx + gy * my);
  f.varOverV = 1.0 / s.W + (cyy * mx * mx - 2.0 * cxy * mx * my + cxx * my * my) / det;
  return f;
}


// Lepski's choice of scale for one vertex with own rays `own`. ring(h, grown,
// db) adds ring h's vertices (those pooled at scale h and not before) to
// grown and their unoccluded directions to db, and returns how many there
// were (0: no ring h). Both ways of listing the rings (a search each time,
// or lists kept across rounds) go through here in the same order, so they
// give the same bits.
template <class Ring>
Pooled chooseScale(const VertexRays& own, const PoolOptions& o, Ring&& ring) {
  constexpr int kMaxScales = 65;
  double A[kMaxScales], VarV[kMaxScales], V[kMaxScales];  // estimate, its variance / v, and v, per accepted scale
  PoolSums sums;
  sums.add(own.n, own.sum, 0.0, 0.0, own.var);
  Pooled p;
  p.vertices = 1;
  p.bent = own.bent;
  if (own.n == 0) return p;
  auto vOf = [&o](const PoolSums& s) {
    if (!o.bounded) return s.VW / s.W;  // the pool's mean sample variance
    const double pt = (s.Y + 1.0) / (s.W + 2.0);  // Laplace: never 0 after rays that all agreed
    return pt * (1.0 - pt);
  };
  A[0] = sums.Y / sums.W;
  VarV[0] = 1.0 / sums.W;
  V[0] = vOf(sums);
  int chosen = 0;
  // Bounded values: the variance per ray reported is the largest of the
  // pools examined (the chosen scale, the larger ones pooled on the way and
  // the first one Lepski's rule refused). A small pool whose rays happened to
  // agree (no occluded ray among 56, under neighbours that do see occlusion)
  // would otherwise report a small error and stop the vertex early with a
  // value biased towards 1 (measured on a 470k-vertex scan at a target of
  // 0.02: +0.029 mean error on such vertices, errors 1.4 times the reported
  // ones in the band of AO 0.95 to 0.98).
  double vMax = V[0];
  const bool test = o.fixedRings < 0;
  const int R = std::min(test ? o.maxRings : o.fixedRings, kMaxScales - 1);
  for (int h = 1; h <= R; ++h) {
    PoolSums grown = sums;
    glm::vec3 db(0.f);
    const uint32_t added = ring(h, grown, db);
    if (added == 0) break;
    const Fit f = fit(grown);
    const double v = vOf(grown);
    vMax = std::max(vMax, v);
    // Lepski: the new estimate within gamma standard errors of every smaller
    // scale's. For nested least-squares fits of one model the larger is the
    // efficient one, so Var(a_h' - a_h) = Var(a_h') - Var(a_h) (Hausman 1978).
    bool agree = true;
    for (int s = 0; s <= chosen && agree && test; ++s) {
      // Unbounded values: each estimate's variance with its own pool's
      // variance per ray (a vertex whose own rays all agreed, hidden under
      // an object, keeps its value however its neighbours' rays spread).
      const double var = o.bounded ? std::max(0.0, v * (VarV[s] - f.varOverV))
                                   : std::max(0.0, V[s] * VarV[s] - v * f.varOverV);
      agree = std::fabs(f.a - A[s]) <= o.gamma * std::sqrt(var);
    }
    if (test && !agree) break;
    chosen = h;
    A[h] = f.a;
    VarV[h] = f.varOverV;
    V[h] = v;
    sums = grown;
    p.vertices += added;
    p.bent += db;
  }
  p.value = float(o.bounded ? std::clamp(A[chosen], 0.0, 1.0) : std::max(A[chosen], 0.0));
  p.stdError = float(std::sqrt((o.bounded ? vMax : V[chosen]) * VarV[chosen]));
  p.rays = uint32_t(sums.W);
  p.rings = chosen;
  return p;
}

// Breadth-first rings around i through vertices that may be pooled with it
// (poolable, with rays, normal within the tolerance). startRings begins the
// search; each nextRing leaves the next ring in sc.frontier (empty: no more).
void startRings(uint32_t i, size_t vertexCount, PoolScratch& sc) {
  if (sc.stamp.size() != vertexCount) { sc.stamp.assign(vertexCount, 0); sc.now = 0; }
  if (++sc.now == 0) { std::fill(sc.stamp.begin(), sc.stamp.end(), 0); sc.now = 1; }
  sc.stamp[i] = sc.now;
  sc.frontier.assign(1, i);
}

// Who may join a vertex's rings (poolable, with rays) and its normal: read
// from the run's arrays, or from one packed array (one read per neighbour,
// for building every vertex's lists at once). Both give the same rings.
struct ArrayNodes {
  const std::vector<glm::vec3>& normals;
  const std::vector<VertexRays>& rays;
  const std::vector<uint8_t>& poolable;
  glm::vec3 normal(uint32_t u) const { return normals[u]; }
  bool usable(uint32_t u) const { return poolable[u] && rays[u].n != 0; }
  size_t size() const { return normals.size(); }
};
struct PackedNodes {
  struct Node {
    glm::vec3 n;
    uint32_t usable;
  };
  std::vector<Node> nodes;
  glm::vec3 normal(uint32_t u) const { return nodes[u].n; }
  bool usable(uint32_t u) const { return nodes[u].usable != 0; }
  size_t size() const { return nodes.size(); }
};

template <class Nodes>
void nextRing(uint32_t i, const VertexGraph& g, const Nodes& nodes, const PoolOptions& o, PoolScratch& sc) {
  const uint32_t now = sc.now;
  const glm::vec3 ni = nodes.normal(i);
  sc.next.clear();
  for (uint32_t v : sc.frontier)
    for (uint32_t k = g.offset[v]; k < g.offset[v + 1]; ++k) {
      const uint32_t u = g.nbr[k];
      if (sc.stamp[u] == now) continue;
      sc.stamp[u] = now;
      if (!nodes.usable(u) || glm::dot(nodes.normal(u), ni) < o.normalCos) continue;
      sc.next.push_back(u);
    }
  sc.frontier.swap(sc.next);
}

// Calls visit(h, u) for every vertex u of ring h = 1, ..., maxRings in the
// order poolVertex pools them, and returns the number of rings found (the
// search stops at an empty ring, as poolVertex does).
template <class Nodes, class Visit>
int searchRings(uint32_t i, const VertexGraph& g, const Nodes& nodes, const PoolOptions& o, int maxRings,
                PoolScratch& sc, Visit&& visit) {
  startRings(i, nodes.size(), sc);
  int h = 1;
  for (; h <= maxRings; ++h) {
    nextRing(i, g, nodes, o, sc);
    if (sc.frontier.empty()) break;
    for (uint32_t u : sc.frontier) visit(h, u);
  }
  return h - 1;
}

}  // namespace

Pooled poolVertex(uint32_t i, const VertexGraph& g, const std::vector<glm::vec3>& positions,
                  const std::vector<glm::vec3>& normals, const std::vector<VertexRays>& rays,
                  const std::vector<uint8_t>& poolable, const PoolOptions& o, PoolScratch& sc) {
  const glm::vec3 pi = positions[i];
  const Frame frame(normals[i]);
  return chooseScale(rays[i], o, [&](int h, PoolSums& grown, glm::vec3& db) -> uint32_t {
    if (h == 1) startRings(i, normals.size(), sc);
    nextRing(i, g, ArrayNodes{normals, rays, poolable}, o, sc);
    for (uint32_t u : sc.frontier) {
      const glm::vec3 d = positions[u] - pi;
      grown.add(rays[u].n, rays[u].sum, glm::dot(d, frame.t), glm::dot(d, frame.b), rays[u].var);
      db += rays[u].bent;
    }
    return uint32_t(sc.frontier.size());
  });
}

namespace {

constexpr int kRound = 32;

// Rays [start, start + count) of the sequence of the mesh's vertex vi, the
// same as the per-vertex estimator's (key, warp and frame), added to r.
void castRays(const RayCaster& caster, const AmbientOptions& o, float tfar, uint32_t vi, const glm::vec3& org,
              const glm::vec3& n, uint32_t start, uint32_t count, VertexRays& r) {
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
      const double f = obscurance ? (hits[j].valid() ? std::pow(std::min(1.0, double(hits[j].t) / o.maxDistance),
                                                                 double(o.falloffExponent))
                                                     : 1.0)
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
  return chooseScale(rays[i], o, [&](int h, PoolSums& grown, glm::vec3& db) -> uint32_t {
    if (uint32_t(h) > rings) return 0;
    const uint32_t count = list[h];
    for (uint32_t k = 0; k < count; ++k) {
      const PoolPoint& q = pts[member[k]];
      const glm::vec3 d = q.p - pi;
      grown.add(q.n, q.sum, glm::dot(d, frame.t), glm::dot(d, frame.b), 0.0);  // AO: bounded values
      if (bent) db += rays[member[k]].bent;  // zero unless bent normals are asked for
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
          castRays(caster, o, tfar, uint32_t(part.meshIndex(i)), origins[i], normals[i], rays[i].n,
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
