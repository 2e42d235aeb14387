// Hierarchical radiosity with clustering (see gi/hierarchical.h for the
// equation and the citations): BF link refinement and the push-pull Jacobi
// sweeps; the cluster tree and the link form factors are in
// hierarchy_nodes.cpp.
#include "gi/hierarchical.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "gi/color.h"
#include "gi/form_factor_analytic.h"
#include "gi/radiosity.h"
#include "gi/scene_setup.h"
#include "hierarchy_nodes.h"

namespace gi {
namespace {

using namespace hierarchy;

constexpr float kReceiverConeCos = 0.985f;  // 10 degrees
constexpr double kSeparation = 0.5;

struct Refiner {
  const Geometry& g;
  const Tree& t;
  const std::vector<double>& Rmax;  // per node: max luminance of R over its triangles
  double threshold;                  // epsilon x emitted power
  size_t maxLinks;
  std::vector<Link>& out;
  std::vector<uint8_t>* fresh;       // 1: F still to compute (null: all fresh, not recorded)
  uint64_t splits = 0;
  bool budgetHit = false;
  // A part of a refinement on all threads (refineInParts): the
  // links made by all parts together, published every kPublish, and the
  // flag that stops every part once they pass the budget.
  std::atomic<size_t>* made = nullptr;
  std::atomic<bool>* stop = nullptr;
  size_t unpublished = 0;
  static constexpr size_t kPublish = 4096;

  // Whether a link p <- q may stay as it is (BF criterion and separation).
  // A receiving cluster spreads what it gathers evenly over its triangles,
  // which is right only for triangles facing alike: receivers are
  // triangles or clusters whose normals lie within kReceiverCone of their
  // axis (a wall, a gently curved piece of a scan); sources may be any
  // cluster, their triangles keep their own orientation in F.
  static bool wideReceiver(const Node& n) { return !n.leaf() && n.coneCos < kReceiverConeCos; }
  bool acceptable(uint32_t p, uint32_t q) const {
    const Node &np = t.nodes[p], &nq = t.nodes[q];
    if (np.leaf() && nq.leaf()) return true;
    if (wideReceiver(np)) return false;
    const double dist = glm::length(np.c - nq.c), d = dist - np.r - nq.r;
    // Clusters far enough apart that the kernel varies little over them
    // (the 16-point rule's error falls as ((r_p + r_q) / dist)^2).
    if (!(d > 0) || np.r + nq.r > kSeparation * dist) return false;
    const double Fmax = std::min(1.0, nq.A / (M_PI * d * d));
    return np.A * Fmax * Rmax[q] <= threshold;
  }

  // A planar node (a triangle, or a flat piece of a wall) sees nothing of a
  // node wholly behind or in its plane, and vice versa.
  bool culled(uint32_t p, uint32_t q) const {
    const Node &np = t.nodes[p], &nq = t.nodes[q];
    return (np.planar && boxBehind(nq, np.x0, np.n)) || (nq.planar && boxBehind(np, nq.x0, nq.n));
  }

  void add(const Link& l, bool isFresh) {
    out.push_back(l);
    if (fresh) fresh->push_back(isFresh ? 1 : 0);
    if (made && ++unpublished == kPublish) {
      if (made->fetch_add(kPublish, std::memory_order_relaxed) + kPublish > maxLinks)
        stop->store(true, std::memory_order_relaxed);
      unpublished = 0;
    }
  }

  // The power a link may carry (what BF refinement bounds): the order in
  // which a budget-limited refinement splits.
  double power(uint32_t p, uint32_t q) const {
    const Node &np = t.nodes[p], &nq = t.nodes[q];
    const double d = glm::length(np.c - nq.c) - np.r - nq.r;
    const double Fmax = d > 0 ? std::min(1.0, nq.A / (M_PI * d * d)) : 1.0;
    return np.A * Fmax * Rmax[q];
  }

  // Which node of an unacceptable link is split: a wide receiver, else the larger.
  bool splitsReceiver(const Node& np, const Node& nq) const {
    return !np.leaf() && (wideReceiver(np) || nq.leaf() || np.r >= nq.r);
  }

  // Budget-limited refinement, best first: the link that may carry the most
  // power is split first (to within an eighth of an octave: candidates are
  // kept in buckets of power, 2^(1/8) apart, each a stack), so that where
  // the budget stops the refinement the coarse links left are the weakest
  // ones everywhere (depth-first order would leave whole parts of the scene
  // on coarse links). A bucket queue instead of a binary heap: pushing and
  // popping are O(1), where the heap's O(log n) cache misses over tens of
  // millions of candidates took most of a 1M-triangle run's refinement.
  // `start`: the links to refine (kept ones carry their index into `old`,
  // fresh ones kNoHit); the links made are added to out.
  struct Candidate {
    double power;
    uint32_t p, q, old;
  };
  struct BucketQueue {
    static constexpr int kPerOctave = 8, kBuckets = 8192;  // 2^(-512) .. 2^(512); infinity: the top one
    std::vector<std::vector<Candidate>> bucket = std::vector<std::vector<Candidate>>(kBuckets);
    int top = -1;
    size_t size = 0;
    static int index(double power) {
      if (!(power < std::numeric_limits<double>::infinity())) return kBuckets - 1;
      if (!(power > 0)) return 0;
      return std::clamp(int(std::floor(std::log2(power) * kPerOctave)) + kBuckets / 2, 0, kBuckets - 2);
    }
    void push(const Candidate& c) {
      const int b = index(c.power);
      bucket[size_t(b)].push_back(c);
      top = std::max(top, b);
      ++size;
    }
    int topBucket() {  // the highest non-empty bucket (size > 0)
      while (bucket[size_t(top)].empty()) --top;
      return top;
    }
    Candidate pop() {
      std::vector<Candidate>& b = bucket[size_t(topBucket())];
      const Candidate c = b.back();
      b.pop_back();
      if (b.empty()) std::vector<Candidate>().swap(b);  // its memory back: the peak stays the heap's
      --size;
      return c;
    }
  };
  // What a popped candidate becomes, decided without touching the queue or
  // the links (so that a batch is decided in parallel): a self pair's
  // children, or whether the link is acceptable and, if not, the two
  // children of its split (culled ones dropped, their power computed).
  struct Decision {
    bool self = false, acceptable = false;
    int children = 0;
    Candidate child[4];
  };
  void decide(const Candidate& c, Decision& d) const {
    const Node &np = t.nodes[c.p], &nq = t.nodes[c.q];
    d.self = c.p == c.q;
    d.acceptable = false;
    d.children = 0;
    const auto child = [&](uint32_t p, uint32_t q) {
      if (p != q && culled(p, q)) return;
      d.child[d.children++] = {p == q ? std::numeric_limits<double>::infinity() : power(p, q), p, q, kNoHit};
    };
    if (d.self) {  // a node with itself is always split (as refine does)
      if (np.leaf()) return;
      for (uint32_t a : {np.left, np.right})
        for (uint32_t b : {np.left, np.right}) child(a, b);
      return;
    }
    d.acceptable = acceptable(c.p, c.q);
    if (d.acceptable) return;
    if (splitsReceiver(np, nq)) {
      child(np.left, c.q);
      child(np.right, c.q);
    } else {
      child(c.p, nq.left);
      child(c.p, nq.right);
    }
  }
  // The candidates are taken from the top bucket in batches of up to
  // kBatch (all within an eighth of an octave of each other), decided in
  // parallel (the nodes' reads, which wait on memory, are most of the
  // time), then applied in order: the links, the budget and the queue see
  // them one by one, so the result does not depend on the threads.
  static constexpr size_t kBatch = 4096, kParallelBatch = 512;
  void refineBestFirst(const std::vector<Candidate>& start, const std::vector<Link>& old) {
    BucketQueue queue;
    for (const Candidate& c : start) queue.push(c);
    std::vector<Candidate> batch;
    std::vector<Decision> dec;
    while (queue.size) {
      batch.clear();
      const int top = queue.topBucket();
      while (batch.size() < kBatch && queue.size && queue.topBucket() == top) batch.push_back(queue.pop());
      dec.resize(batch.size());
      if (batch.size() >= kParallelBatch)
        tbb::parallel_for(tbb::blocked_range<size_t>(0, batch.size(), 128), [&](const tbb::blocked_range<size_t>& r) {
          for (size_t i = r.begin(); i < r.end(); ++i) decide(batch[i], dec[i]);
        });
      else
        for (size_t i = 0; i < batch.size(); ++i) decide(batch[i], dec[i]);
      for (size_t i = 0; i < batch.size(); ++i) {
        const Candidate& c = batch[i];
        const Decision& d = dec[i];
        if (!d.self) {
          const size_t waiting = queue.size + (batch.size() - i - 1);
          if (d.acceptable || out.size() + waiting + 1 >= maxLinks) {
            budgetHit |= !d.acceptable;
            if (c.old != kNoHit) add(old[c.old], false);
            else add(Link{c.p, c.q, 0.f}, true);
            continue;
          }
          ++splits;
        }
        for (int k = 0; k < d.children; ++k) queue.push(d.child[k]);
      }
    }
  }
  // Links covering every triangle pair of (p, q), split where needed.
  void refine(uint32_t p, uint32_t q) {
    if (stop && stop->load(std::memory_order_relaxed)) return;
    if (p == q) {  // a node with itself: a flat triangle sees nothing of itself
      const Node& n = t.nodes[p];
      if (n.leaf()) return;
      refine(n.left, n.left);
      refine(n.left, n.right);
      refine(n.right, n.left);
      refine(n.right, n.right);
      return;
    }
    if (culled(p, q)) return;
    if (acceptable(p, q)) {  // (the budget: refineInParts)
      add(Link{p, q, 0.f}, true);
      return;
    }
    ++splits;
    const Node &np = t.nodes[p], &nq = t.nodes[q];
    if (splitsReceiver(np, nq)) {
      refine(np.left, q);
      refine(np.right, q);
    } else {
      refine(p, nq.left);
      refine(p, nq.right);
    }
  }
};

// Refinement on all threads with the result of one: `work(i, part)` fills
// part i of nParts with its links (kept or refined), the parts run on any
// thread, each into its own links, and are joined in order. No part sees
// the budget alone: the parts count their links together and all stop
// once they pass it; then ref.budgetHit is set and no link is added (the
// caller refines again, best first, as after a sequential pass that hit it).
constexpr size_t kParts = 1024;
template <class Work>
void refineInParts(Refiner& ref, size_t nParts, const Work& work) {
  std::vector<std::vector<Link>> parts(nParts);
  std::vector<std::vector<uint8_t>> partFresh(nParts);
  std::vector<uint64_t> partSplits(nParts, 0);
  std::atomic<size_t> made{0};
  std::atomic<bool> stop{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nParts, 1), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      if (stop.load(std::memory_order_relaxed)) return;
      Refiner part{ref.g, ref.t, ref.Rmax, ref.threshold, ref.maxLinks, parts[i], &partFresh[i]};
      part.made = &made;
      part.stop = &stop;
      work(i, part);
      partSplits[i] = part.splits;
    }
  });
  size_t total = 0;
  for (const auto& part : parts) total += part.size();
  if (stop.load() || ref.out.size() + total > ref.maxLinks) {
    ref.budgetHit = true;
    return;
  }
  ref.out.reserve(ref.out.size() + total);
  if (ref.fresh) ref.fresh->reserve(ref.fresh->size() + total);
  for (size_t i = 0; i < nParts; ++i) {
    ref.out.insert(ref.out.end(), parts[i].begin(), parts[i].end());
    if (ref.fresh) ref.fresh->insert(ref.fresh->end(), partFresh[i].begin(), partFresh[i].end());
    std::vector<Link>().swap(parts[i]);
    std::vector<uint8_t>().swap(partFresh[i]);
    ref.splits += partSplits[i];
  }
}

// Refiner::refine(p0, q0) on all threads, with the same links in the same
// order: the recursion's first levels are unfolded, in its order (each
// pair as best first decides it), into at least kParts independent pairs
// (kept links among them), refined in parts.
void refineDepthFirst(Refiner& ref, uint32_t p0, uint32_t q0) {
  struct Item {
    uint32_t p, q;
    bool link;  // acceptable: a link as it is
  };
  std::vector<Item> frontier{{p0, q0, false}}, next;
  uint64_t splits = 0;
  Refiner::Decision d;
  for (bool grew = true; grew && frontier.size() < kParts;) {
    grew = false;
    next.clear();
    for (const Item& it : frontier) {
      if (it.link) {
        next.push_back(it);
        continue;
      }
      ref.decide({0.0, it.p, it.q, kNoHit}, d);
      grew = true;
      if (!d.self && d.acceptable) {
        next.push_back({it.p, it.q, true});
        continue;
      }
      splits += d.self ? 0 : 1;
      for (int k = 0; k < d.children; ++k) next.push_back({d.child[k].p, d.child[k].q, false});
    }
    frontier.swap(next);
  }
  refineInParts(ref, frontier.size(), [&](size_t i, Refiner& part) {
    if (frontier[i].link) part.add(Link{frontier[i].p, frontier[i].q, 0.f}, true);
    else part.refine(frontier[i].p, frontier[i].q);
  });
  if (!ref.budgetHit) ref.splits += splits;
}

// A later round on all threads, with the same links in the same order as
// one thread: each old link is kept where it is acceptable, else refined;
// the old links are cut into parts.
void refineAgain(Refiner& ref, const std::vector<Link>& old) {
  const size_t n = old.size(), nParts = std::min(n, kParts), step = nParts ? (n + nParts - 1) / nParts : 0;
  refineInParts(ref, nParts, [&](size_t i, Refiner& part) {
    for (size_t k = i * step; k < std::min(n, (i + 1) * step) && !part.stop->load(std::memory_order_relaxed); ++k) {
      if (part.acceptable(old[k].p, old[k].q)) part.add(old[k], false);
      else part.refine(old[k].p, old[k].q);
    }
  });
}

}  // namespace

HierarchicalSolution solveHierarchical(const Scene& s, const RayCaster& caster, const std::vector<glm::vec3>& Hd,
                                       const HierarchySettings& set, int bounces, double tolerance, int maxIterations,
                                       const Progress& progress) {
  Timer timer;
  const size_t nf = s.faceCount();
  if (Hd.size() != nf) throw std::logic_error("direct irradiance has the wrong size");
  Geometry g{s, {}, unitFaceNormals(s), {}};
  const auto ok = usableFaceMask(s);
  g.A.resize(nf);
  g.centroid.resize(nf);
  double P = 0, rhoMax = 0;
  std::vector<glm::vec3> S(nf, glm::vec3(0.f));
  for (size_t f = 0; f < nf; ++f) {
    const glm::uvec3 tri = s.triangles[f];
    g.A[f] = ok[f] ? faceArea(s, f) : 0.0;
    if (ok[f])
      g.centroid[f] = (glm::dvec3(s.positions[tri.x]) + glm::dvec3(s.positions[tri.y]) + glm::dvec3(s.positions[tri.z])) / 3.0;
    P += g.A[f] * luminance(s.faceEmission(f));
    const glm::vec3 rho = s.faceRho(f);
    if (g.A[f] > 0) rhoMax = std::max({rhoMax, double(rho.r), double(rho.g), double(rho.b)});
    S[f] = g.A[f] > 0 ? rho * Hd[f] : glm::vec3(0.f);
  }
  P += set.enteringPower;
  HierarchicalSolution sol;
  progress.report(0.0, "cluster tree");  // serial stages: named, so a long one shows what runs
  const Tree t = buildTree(g);
  const size_t nn = t.nodes.size();
  sol.R = S;
  sol.H.assign(nf, glm::vec3(0.f));
  if (nn == 0 || !(P > 0)) return sol;
  const bool unoccluded = pairwiseUnoccluded(s);
  const float eps = float(sceneScale(s).rayEpsilon);

  std::vector<Link> links;
  // The triangle under source point raySourcePoint(k) of every node, for the
  // rays a link remembers.
  const size_t nSampled = set.linkRays <= kMaxSampledRays ? size_t(std::max(0, set.linkRays)) : 0;
  // kHierarchyBytesPerNode counts 4 sampled source points per node.
  const double baseBytes = double(nn) * (kHierarchyBytesPerNode + 4.0 * (double(nSampled) - 4.0));
  const double byMemory = (set.memoryBytes - baseBytes) / kHierarchyBytesPerLink;
  const bool capped = set.maxLinks < byMemory;  // the link cap, not the memory, is the limit
  const size_t maxLinks = size_t(std::max(1.0, std::min(byMemory, set.maxLinks)));
  std::vector<uint32_t> srcTri(nn * nSampled, 0);
  if (!unoccluded)
    parallelBlocks(nn, Progress(nullptr), "", [&](size_t b, size_t e) {
      glm::dvec3 x[kPoints];
      glm::vec3 n[kPoints];
      uint32_t tri[kPoints];
      for (size_t k = b; k < e; ++k) {
        nodePoints(g, t, t.nodes[k], x, n, tri);
        for (size_t r = 0; r < nSampled; ++r) srcTri[k * nSampled + r] = tri[raySourcePoint(int(r))];
      }
    });
  std::vector<uint8_t> fresh;
  std::vector<double> Rmax(nn, 0.0);
  std::vector<glm::dvec3> Rbar(nn, glm::dvec3(0.0)), Hg(nn, glm::dvec3(0.0)), Hacc(nn, glm::dvec3(0.0));
  uint64_t rays = 0, splits = 0;
  double ffSeconds = 0, refineSeconds = 0, solveSeconds = 0;
  bool budgetHit = false;

  // Pull: area means of R and maxima of its luminance, bottom-up.
  auto pull = [&](const std::vector<glm::vec3>& R) {
    for (size_t k = nn; k-- > 0;) {
      const Node& nd = t.nodes[k];
      if (nd.leaf()) {
        const uint32_t f = t.order[nd.first];
        Rbar[k] = glm::dvec3(R[f]);
        Rmax[k] = luminance(R[f]);
      } else {
        const Node &l = t.nodes[nd.left], &r = t.nodes[nd.right];
        Rbar[k] = (l.A * Rbar[nd.left] + r.A * Rbar[nd.right]) / nd.A;
        Rmax[k] = std::max(Rmax[nd.left], Rmax[nd.right]);
      }
    }
  };
  // Each thread's kept node points, for all the rounds (one per task would
  // refill megabytes for a few thousand links: small scenes ran 1.5x slower).
  tbb::enumerable_thread_specific<NodePointCache> pointCaches;
  // The links refined against the current R: new ones get their F computed
  // (in parallel; each link's rays are fixed by its nodes: deterministic).
  auto refineLinks = [&](bool first, const std::vector<glm::vec3>& Rcur, const Progress& pr) {
    std::vector<Link> next;
    std::vector<uint8_t> nextFresh;
    // Power relative to all the light leaving surfaces (emitted and reflected:
    // in a bright room the reflected power is many times the emitted).
    double leaving = P;
    for (size_t f = 0; f < nf; ++f) leaving += g.A[f] * luminance(Rcur[f]);
    Refiner ref{g, t, Rmax, set.epsilon * leaving, maxLinks, next, &nextFresh};
    pr.report(0.0, "refining links");
    Timer rt;
    if (first) {
      refineDepthFirst(ref, 0, 0);
    } else {
      refineAgain(ref, links);
    }
    if (ref.budgetHit) {
      // The budget stopped the depth-first refinement: again, best first
      // (its links freed first: the heap takes their place).
      std::vector<Link>().swap(next);
      std::vector<uint8_t>().swap(nextFresh);
      ref.splits = 0;
      std::vector<Refiner::Candidate> start;
      if (first) {
        start.push_back({std::numeric_limits<double>::infinity(), 0, 0, kNoHit});
      } else {
        for (size_t k = 0; k < links.size(); ++k) {
          if (ref.acceptable(links[k].p, links[k].q)) ref.add(links[k], false);
          else start.push_back({ref.power(links[k].p, links[k].q), links[k].p, links[k].q, uint32_t(k)});
        }
      }
      ref.refineBestFirst(start, links);
    }
    const uint64_t newSplits = ref.splits;
    splits += newSplits;
    budgetHit |= ref.budgetHit;
    // Grouped by receiver (a stable counting sort: deterministic sums),
    // before the form factors, so that a receiver's points are computed once
    // per group.
    {
      std::vector<size_t> at(nn + 1, 0);
      for (const Link& l : next) ++at[l.p + 1];
      for (size_t k = 0; k < nn; ++k) at[k + 1] += at[k];
      links.resize(next.size());
      std::vector<uint8_t> fr(next.size());
      for (size_t k = 0; k < next.size(); ++k) {
        const size_t d = at[next[k].p]++;
        links[d] = next[k];
        fr[d] = nextFresh[k];
      }
      std::vector<Link>().swap(next);
      nextFresh.swap(fr);
    }
    refineSeconds += rt.seconds();
    Timer ft;
    std::atomic<uint64_t> ffRays{0};  // a count: its sum does not depend on the order
    parallelBlocks(links.size(), pr, "link form factors", [&](size_t b, size_t e) {
      NodePointCache& points = pointCaches.local();
      uint64_t r = 0;
      for (size_t k = b; k < e; ++k)
        if (nextFresh[k]) linkFormFactor(g, t, caster, links[k], set.linkRays, unoccluded, eps, r, points);
      ffRays += r;
    });
    rays += ffRays.load();
    ffSeconds += ft.seconds();
    return newSplits;
  };

  // One Jacobi sweep: gather on the links, push down, R <- S + rho H.
  std::vector<size_t> start;  // links of receiver node k: [start[k], start[k + 1])
  auto index = [&] {
    start.assign(nn + 1, 0);
    for (const Link& l : links) ++start[l.p + 1];
    for (size_t k = 0; k < nn; ++k) start[k + 1] += start[k];
  };
  auto sweep = [&](const std::vector<glm::vec3>& R, std::vector<glm::vec3>& H) {
    pull(R);
    parallelBlocks(nn, Progress(nullptr), "", [&](size_t b, size_t e) {
      for (size_t k = b; k < e; ++k) {
        glm::dvec3 h(0.0);
        for (size_t m = start[k]; m < start[k + 1]; ++m) {
          const Link& l = links[m];
          if (l.samples == Link::kAreaMean) {
            h += double(l.F) * Rbar[l.q];
          } else {
            glm::dvec3 r(0.0);
            for (uint32_t bits = l.samples; bits; bits &= bits - 1)
              r += glm::dvec3(R[srcTri[size_t(l.q) * nSampled + size_t(__builtin_ctz(bits))]]);
            h += double(l.F) * r;
          }
        }
        Hg[k] = h;
      }
    });
    for (size_t k = 0; k < nn; ++k) {  // preorder: parents first
      const Node& nd = t.nodes[k];
      Hacc[k] = Hg[k] + (k ? Hacc[nd.parent] : glm::dvec3(0.0));
      if (nd.leaf()) H[t.order[nd.first]] = glm::vec3(Hacc[k]);
    }
  };

  const bool fixed = bounces >= 0;
  const int maxSweeps = fixed ? bounces : (maxIterations > 0 ? maxIterations : autoIterations(rhoMax, tolerance));
  std::vector<glm::vec3> Rn(nf), H(nf, glm::vec3(0.f));
  auto solveSweeps = [&](int sweeps, const Progress& pr) {
    Timer st;
    index();
    for (int it = 0; it < sweeps; ++it) {
      sol.Rprev = sol.R;
      sweep(sol.R, H);
      double change = 0;
      for (size_t f = 0; f < nf; ++f) {
        Rn[f] = g.A[f] > 0 ? S[f] + s.faceRho(f) * H[f] : glm::vec3(0.f);
        change += g.A[f] * std::fabs(luminance(Rn[f] - sol.R[f]));
      }
      sol.R.swap(Rn);
      sol.residual = change / P;
      sol.residualHistory.push_back(sol.residual);
      ++sol.iterations;
      pr.report(fixed ? double(it + 1) / std::max(1, sweeps)
                      : std::min(1.0, std::log(sol.residual + 1e-300) / std::log(tolerance)), "solving");
      if (!fixed && sol.residual < tolerance) break;
    }
    solveSeconds += st.seconds();
  };

  sol.Rprev.assign(nf, glm::vec3(0.f));  // bounces = 0: no sweep, nothing indirect to gather
  pull(S);
  // Progress: round r (at most 4) takes [r / 4, (r + 1) / 4): its links'
  // form factors the first 70%, its sweeps the rest.
  auto part = [&](int round, double a, double b) { return progress.sub((round + a) / 4.0, (round + b) / 4.0); };
  refineLinks(true, S, fixed ? progress.sub(0.0, 0.7) : part(0, 0.0, 0.7));
  int rounds = 1;
  if (fixed) {
    solveSweeps(maxSweeps, progress.sub(0.7, 1.0));
  } else {
    // Refine again with the solved R (a brighter source needs finer links)
    // until no link is split; at most 4 rounds, and none after a round the
    // memory budget stopped (another would only trade links at the budget:
    // at 300k triangles twice the time for the same error).
    solveSweeps(maxSweeps, part(0, 0.7, 1.0));
    for (; rounds < 4 && !budgetHit; ++rounds) {
      pull(sol.R);
      if (refineLinks(false, sol.R, part(rounds, 0.0, 0.7)) == 0) break;
      solveSweeps(maxSweeps, part(rounds, 0.7, 1.0));
    }
    sol.Rprev = sol.R;
  }
  // What the vertices gather from, and the indirect irradiance it gives.
  sweep(sol.Rprev, sol.H);
  if (!fixed && sol.residual >= tolerance) {
    char b[200];
    std::snprintf(b, sizeof b, "not converged: hierarchical solve stopped at %d sweeps with the residual %.3g above the tolerance %.3g",
                  maxSweeps, sol.residual, tolerance);
    sol.stats.warn(b);
  }
  if (budgetHit && capped)
    sol.stats.note("links capped at " + std::to_string(maxLinks) + " (max_links): refined best first, the " +
                   "links that may carry the most power split first; some carry more than epsilon of the power");
  else if (budgetHit)
    sol.stats.warn("link refinement stopped at the memory budget (" + std::to_string(links.size()) +
                   " links): some links carry more than epsilon of the power; raise memory_budget_mb");
  // Energy account: emitted power = absorbed + escaped; absorbed from the
  // total irradiance (direct + indirect) of every triangle.
  double absorbed = 0, reflected = 0;
  for (size_t f = 0; f < nf; ++f) {
    if (!(g.A[f] > 0)) continue;
    absorbed += g.A[f] * luminance((glm::vec3(1.f) - s.faceRho(f)) * (Hd[f] + sol.H[f]));
    reflected += g.A[f] * luminance(sol.R[f]);
  }
  size_t leafLinks = 0;
  for (const Link& l : links) leafLinks += (t.nodes[l.p].leaf() && t.nodes[l.q].leaf()) ? 1 : 0;
  const double unit2 = s.unit * s.unit;
  sol.stats.add("emitted_power_W", P * unit2);
  sol.stats.add("absorbed_power_W", absorbed * unit2);
  sol.stats.add("reflected_power_W", reflected * unit2);
  sol.stats.add("hierarchy_nodes", double(nn));
  sol.stats.add("hierarchy_levels", double(t.depth));
  sol.stats.add("links", double(links.size()));
  sol.stats.add("links_patch_to_patch", double(leafLinks));
  sol.stats.add("link_splits", double(splits));
  sol.stats.add("refinement_rounds", double(rounds));
  sol.stats.add("link_rays", double(rays));
  sol.stats.add("link_form_factor_seconds", ffSeconds);
  sol.stats.add("link_refinement_seconds", refineSeconds);
  sol.stats.add("hierarchy_sweep_seconds", solveSeconds);
  sol.stats.add("hierarchy_MB", (baseBytes + double(links.size()) * kHierarchyBytesPerLink) / 1048576.0);
  sol.stats.add("hierarchy_seconds", timer.seconds());
  return sol;
}

}  // namespace gi
