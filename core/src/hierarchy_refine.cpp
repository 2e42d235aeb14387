// The link refinement of the hierarchical solver (see gi/hierarchical.h for
// the equation and the citations, hierarchy_refine.h for the Refiner).
#include "hierarchy_refine.h"

#include <algorithm>

namespace gi::hierarchy {
namespace {

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
      Refiner part{ref.g, ref.t, ref.Rmax, ref.threshold, ref.maxLinks, parts[i], &partFresh[i], ref.probe};
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

}  // namespace

bool Refiner::partlyVisible(uint32_t p, uint32_t q) const {
  uint64_t cast = 0;
  const bool partly = linkPartlyVisible(g, t, probe->caster, p, q, probe->eps, cast, probe->points.local());
  probe->rays.fetch_add(cast, std::memory_order_relaxed);
  return partly;
}

// Refiner::refine(p0, q0) on all threads, with the same links in the same
// order: the recursion's first levels are unfolded, in its order (each
// pair as best first decides it), into at least kParts independent pairs
// (kept links among them), refined in parts.
void refineDepthFirst(Refiner& ref, uint32_t p0, uint32_t q0) {
  struct Item {
    uint32_t p, q;
    bool link;    // acceptable: a link as it is
    bool probed;  // and found whole (Link::kProbed)
  };
  std::vector<Item> frontier{{p0, q0, false, false}}, next;
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
        next.push_back({it.p, it.q, true, d.probed});
        continue;
      }
      splits += d.self ? 0 : 1;
      for (int k = 0; k < d.children; ++k) next.push_back({d.child[k].p, d.child[k].q, false, false});
    }
    frontier.swap(next);
  }
  refineInParts(ref, frontier.size(), [&](size_t i, Refiner& part) {
    if (frontier[i].link) part.add(Refiner::marked(Link{frontier[i].p, frontier[i].q, 0.f}, frontier[i].probed), true);
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
      bool probed = false;
      if (part.acceptable(old[k].p, old[k].q, (old[k].samples & Link::kProbed) != 0, &probed))
        part.add(Refiner::marked(old[k], probed), false);
      else part.refine(old[k].p, old[k].q);
    }
  });
}

}  // namespace gi::hierarchy
