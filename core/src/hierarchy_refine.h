// Internal to the hierarchical solver: the link refinement (BF criterion,
// separation, receiver cones; depth first on all threads, best first under
// a budget), used by hierarchical.cpp; defined in hierarchy_refine.cpp.
#pragma once
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "hierarchy_nodes.h"

namespace gi::hierarchy {

constexpr float kReceiverConeCos = 0.985f;  // 10 degrees
constexpr double kSeparation = 0.5;
// A link into a cluster that some of the cluster's points receive from
// and others not stays only while it may carry at most this share of the
// BF threshold (Refiner::acceptable).
// 1/16: a room behind a coarse partition within 3% of the flat solution
// (1/4: 12%; 1/64: 2%), at 1.6 times the time in a room of 64 pillars
// (1/4: 1.13; 1/64: 2.6).
constexpr double kPartialShare = 1.0 / 16.0;

// What the refiner needs to look along a link (Refiner::partlyVisible).
struct VisibilityProbe {
  const RayCaster& caster;
  float eps;
  tbb::enumerable_thread_specific<NodePointCache>& points;
  std::atomic<uint64_t> rays{0};
};

struct Refiner {
  const Geometry& g;
  const Tree& t;
  const std::vector<double>& Rmax;  // per node: max luminance of R over its triangles
  double threshold;                  // epsilon x emitted power
  size_t maxLinks;
  std::vector<Link>& out;
  std::vector<uint8_t>* fresh;       // 1: F still to compute (null: all fresh, not recorded)
  VisibilityProbe* probe = nullptr;  // null: the scene has no occluders
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
  //
  // A receiving cluster also spreads what it gathers over triangles that
  // may not see the source at all: one that reaches past an occluder's
  // edge (the ceiling and walls where a partition stops short of them) or
  // past a flat source's plane. The BF threshold is global, so in a room
  // lit only through such a gap every link may carry a large share of what
  // arrives there: the half of a room behind a coarse partition read 24%
  // too bright against the flat solver. So a link into a cluster is looked
  // along from each of the cluster's 16 points (a ray to a source point it
  // can receive from, or none where it can receive from no source point),
  // and where some points receive and others do not it is split until it
  // may carry at most kPartialShare of the threshold or its receiver is a
  // triangle (`HierarchicalRadiosity.ThinPartitionStopsTheLight`). A link
  // looked along and found whole is marked (Link::kProbed) and not looked
  // along again in later rounds.
  static bool wideReceiver(const Node& n) { return !n.leaf() && n.coneCos < kReceiverConeCos; }
  // `probedBefore`: the link was found whole before; `probedNow`, if given,
  // is set when it is found whole here.
  bool acceptable(uint32_t p, uint32_t q, bool probedBefore = false, bool* probedNow = nullptr) const {
    const Node &np = t.nodes[p], &nq = t.nodes[q];
    if (np.leaf() && nq.leaf()) return true;
    if (wideReceiver(np)) return false;
    const double dist = glm::length(np.c - nq.c), d = dist - np.r - nq.r;
    // Clusters far enough apart that the kernel varies little over them
    // (the 16-point rule's error falls as ((r_p + r_q) / dist)^2).
    if (!(d > 0) || np.r + nq.r > kSeparation * dist) return false;
    const double Fmax = std::min(1.0, nq.A / (M_PI * d * d)), power = np.A * Fmax * Rmax[q];
    if (!(power <= threshold)) return false;
    if (np.leaf() || !probe || probedBefore || power <= kPartialShare * threshold) return true;
    if (partlyVisible(p, q)) return false;
    if (probedNow) *probedNow = true;
    return true;
  }
  static Link marked(Link l, bool probed) {
    if (probed) l.samples |= Link::kProbed;
    return l;
  }
  bool partlyVisible(uint32_t p, uint32_t q) const;

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
    bool self = false, acceptable = false, probed = false;
    int children = 0;
    Candidate child[4];
  };
  void decide(const Candidate& c, Decision& d) const {
    const Node &np = t.nodes[c.p], &nq = t.nodes[c.q];
    d.self = c.p == c.q;
    d.acceptable = d.probed = false;
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
    d.acceptable = acceptable(c.p, c.q, false, &d.probed);
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
            if (c.old != kNoHit) add(marked(old[c.old], d.probed), false);
            else add(marked(Link{c.p, c.q, 0.f}, d.probed), true);
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
    bool probed = false;
    if (acceptable(p, q, false, &probed)) {  // (the budget: refineInParts)
      add(marked(Link{p, q, 0.f}, probed), true);
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

// Refiner::refine(p0, q0) on all threads, with the same links in the same
// order as one thread.
void refineDepthFirst(Refiner& ref, uint32_t p0, uint32_t q0);
// A later round on all threads: each old link kept where it is acceptable,
// else refined; the same links in the same order as one thread.
void refineAgain(Refiner& ref, const std::vector<Link>& old);

}  // namespace gi::hierarchy
