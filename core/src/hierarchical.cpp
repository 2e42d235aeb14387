// Hierarchical radiosity with clustering (see gi/hierarchical.h for the
// equation and the citations): the rounds of link refinement, the closure's
// balance and the push-pull Jacobi sweeps; the cluster tree, the link form
// factors and the closure rays are in hierarchy_nodes.cpp, the refinement
// in hierarchy_refine.cpp.
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
#include "hierarchy_refine.h"

namespace gi {
namespace {

using namespace hierarchy;

constexpr int kBalanceRounds = 8;
// Closure rays in all, at most, where they serve the energy account alone.
constexpr double kAccountRays = 8e6;
// An energy balance off by more than this warns (see the energy account).
// Lowered from 5% after an outside audit: a sealed room parted by a block
// read +4.3% on average (+9% at one patch) at rho 0.991, with a balance of
// 4.3% and no word; shadow_leak's 2.9% is a real +2.7% of absorbed power.
constexpr double kHierarchicalBalanceWarning = 0.02;

}  // namespace

HierarchicalSolution solveHierarchical(const Scene& s, const RayCaster& caster, const std::vector<glm::vec3>& Hd,
                                       const HierarchySettings& set, int bounces, double tolerance, int maxIterations,
                                       const Progress& progress) {
  checkCasterFor(s, caster);
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
  // The seen share of each triangle (1 where none is given), its seen area,
  // and the direct light of its seen part.
  const bool partSeen = !set.seen.empty();
  if (partSeen && (set.seen.size() != nf || (!set.seenPoints.empty() && set.seenPoints.size() != nf)))
    throw std::invalid_argument("HierarchySettings: seen shares and seen points must be one per triangle");
  // Without the open points a node spreads what it gathers over its seen part.
  if (partSeen && !set.seenPoints.empty()) g.seen = &set.seen, g.seenPoints = &set.seenPoints;
  auto seenShare = [&](size_t f) { return partSeen ? double(set.seen[f]) : 1.0; };
  if (partSeen)
    for (size_t f = 0; f < nf; ++f) S[f] = seenShare(f) > 0 ? S[f] / float(seenShare(f)) : glm::vec3(0.f);
  P += set.enteringPower;
  HierarchicalSolution sol;
  progress.report(0.0, "cluster tree");  // serial stages: named, so a long one shows what runs
  const Tree t = buildTree(g);
  const size_t nn = t.nodes.size();
  // Per node, the seen area under it and its share of the node's area.
  std::vector<double> seenA(nn, 0.0), seenOf(nn, 1.0);
  for (size_t k = nn; k-- > 0;) {
    const Node& nd = t.nodes[k];
    seenA[k] = nd.leaf() ? g.A[t.order[nd.first]] * seenShare(t.order[nd.first]) : seenA[nd.left] + seenA[nd.right];
    seenOf[k] = nd.A > 0 ? seenA[k] / nd.A : 1.0;
  }
  // Whether a node gathers at points on its seen part (moveToSeenParts);
  // one none of whose points lies there spreads what its buried points
  // gather over its seen part, as all nodes did before.
  std::vector<uint8_t> gathersOnSeen(nn, uint8_t(!partSeen || g.seen));
  if (g.seen)
    parallelBlocks(nn, Progress(nullptr), "", [&](size_t b, size_t e) {
      NodePointSet pts;
      uint32_t faces[kPoints];
      for (size_t k = b; k < e; ++k) {
        if (seenOf[k] >= 1.0) continue;
        nodePoints(g, t, t.nodes[k], pts.x, pts.n, faces);
        gathersOnSeen[k] = moveToSeenParts(g, faces, pts);
      }
    });
  sol.R = S;
  sol.H.assign(nf, glm::vec3(0.f));
  if (nn == 0 || !(P > 0)) return sol;
  const bool unoccluded = pairwiseUnoccluded(s);
  const float eps = float(sceneScale(s).rayEpsilon);

  std::vector<Link> links;
  // The triangle under source point raySourcePoint(k) of every node, for the
  // rays a link remembers (any of its points may be one; none without
  // occluders).
  const size_t nSampled = unoccluded ? 0 : size_t(kPoints);
  // kHierarchyBytesPerNode counts 16 sampled source points per node.
  const double baseBytes = double(nn) * (kHierarchyBytesPerNode + 4.0 * (double(nSampled) - 16.0));
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
  // What each triangle's row must sum to (gi/hierarchical.h: closure). The
  // rows are balanced only in a room without occluders; elsewhere the rays
  // serve the energy account alone, a sum over all triangles, which needs
  // far fewer of them a triangle on a large mesh: at most kAccountRays in
  // all there (at least 4 a triangle). At 1M triangles 64 a triangle took
  // 20 s of a scan room's 37 (its other rays are shorter and cheaper).
  Timer closureTimer;
  uint64_t closureRays = 0;
  progress.report(0.0, "closure rays");
  const double accountShare = std::max(4.0, kAccountRays / double(std::max<size_t>(nf, 1)));
  const int closurePerTriangle = unoccluded ? set.closureRays : int(std::min(double(set.closureRays), accountShare));
  const std::vector<float> closure = rowClosures(g, caster, closurePerTriangle, set.seed, eps, closureRays);
  const double closureSeconds = closureTimer.seconds();
  // Each triangle's factor on what it gathers (its row) and on what it
  // sends (its column), balanced against the closure.
  std::vector<double> rowScale(nf, 1.0), colScale(nf, 1.0);
  std::vector<glm::vec3> Rc;  // R times colScale: what the links carry in a closed room
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
        // The mean over the seen part (rays from a receiver land there).
        Rbar[k] = seenA[k] > 0 ? (seenA[nd.left] * Rbar[nd.left] + seenA[nd.right] * Rbar[nd.right]) / seenA[k]
                               : glm::dvec3(0.0);
        Rmax[k] = std::max(Rmax[nd.left], Rmax[nd.right]);
      }
    }
  };
  // Each thread's kept node points, for all the rounds (one per task would
  // refill megabytes for a few thousand links: small scenes ran 1.5x slower).
  tbb::enumerable_thread_specific<NodePointCache> pointCaches;
  VisibilityProbe probe{caster, eps, pointCaches};
  // The links refined against the current R: new ones get their F computed
  // (in parallel; each link's rays are fixed by its nodes: deterministic).
  auto refineLinks = [&](bool first, const std::vector<glm::vec3>& Rcur, const Progress& pr) {
    std::vector<Link> next;
    std::vector<uint8_t> nextFresh;
    // Power relative to all the light leaving surfaces (emitted and reflected:
    // in a bright room the reflected power is many times the emitted).
    double leaving = P;
    for (size_t f = 0; f < nf; ++f) leaving += g.A[f] * seenShare(f) * luminance(Rcur[f]);
    Refiner ref{g, t, Rmax, set.epsilon * leaving, maxLinks, next, &nextFresh, unoccluded ? nullptr : &probe};
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
          bool probed = false;
          if (ref.acceptable(links[k].p, links[k].q, (links[k].samples & Link::kProbed) != 0, &probed))
            ref.add(Refiner::marked(links[k], probed), false);
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
  bool closedRoom = false;  // the links closed (below): rows and columns scaled
  auto sweep = [&](const std::vector<glm::vec3>& Rin, std::vector<glm::vec3>& H) {
    if (closedRoom)
      for (size_t f = 0; f < nf; ++f) Rc[f] = glm::vec3(glm::dvec3(Rin[f]) * colScale[f]);
    const std::vector<glm::vec3>& R = closedRoom ? Rc : Rin;
    pull(R);
    parallelBlocks(nn, Progress(nullptr), "", [&](size_t b, size_t e) {
      for (size_t k = b; k < e; ++k) {
        glm::dvec3 h(0.0);
        for (size_t m = start[k]; m < start[k + 1]; ++m) {
          const Link& l = links[m];
          if (l.areaMean()) {
            h += double(l.F) * Rbar[l.q];
          } else {
            glm::dvec3 r(0.0);
            for (uint32_t bits = l.samples & Link::kSampleBits; bits; bits &= bits - 1)
              r += glm::dvec3(R[srcTri[size_t(l.q) * nSampled + size_t(__builtin_ctz(bits))]]);
            h += double(l.F) * r;
          }
        }
        // A link's factor is the mean over the receiver's points, which lie
        // on its seen part (what it brings falls there) unless none does.
        Hg[k] = gathersOnSeen[k] ? h : seenOf[k] > 0 ? h / seenOf[k] : glm::dvec3(0.0);
      }
    });
    for (size_t k = 0; k < nn; ++k) {  // preorder: parents first
      const Node& nd = t.nodes[k];
      Hacc[k] = Hg[k] + (k ? Hacc[nd.parent] : glm::dvec3(0.0));
      if (nd.leaf())  // a triangle taken as wholly buried receives nothing (as in the flat solvers)
        H[t.order[nd.first]] = seenShare(t.order[nd.first]) > 0
                                   ? glm::vec3(closedRoom ? Hacc[k] * rowScale[t.order[nd.first]] : Hacc[k])
                                   : glm::vec3(0.f);
    }
  };
  // The links closed (gi/hierarchical.h) in a closed room without
  // occluders: every closure ray of every triangle hit a surface (G = 1)
  // and no link needs visibility rays. Row factors r (what a triangle
  // gathers) and column factors c (what it sends), alternately (Sinkhorn's
  // balancing of r F c), bring the row sums sum_j r_i F_ij c_j (the
  // furnace: a uniform R gives a uniform H) and the column sums sum_i A_i
  // r_i F_ij c_j / A_j (energy: all the power a triangle sends arrives
  // somewhere) to 1; the balance ends on the columns. In a closed box of
  // 3,072 triangles lit from a patch of its ceiling, at rho 0.99: the rows
  // alone leave the mean R 1% low (the links are not reciprocal), rows and
  // columns 6e-5 (the direct light's own error).
  // Elsewhere the links' sums are kept, and the energy balance indicates
  // how far they are off: all that was tried did worse than the links
  // alone somewhere.
  //  - Rows and columns into the interval of two binomial errors around G,
  //    in a room with a hole at rho 0.991: +0.8% absorbed at 64 rays, -9%
  //    at 256, +31% at 16 (+12% with the links alone); a triangle none of
  //    whose rays hit anything had its row set to 0.
  //  - With occluders, column factors from the links' few source points
  //    (per triangle or per cluster of up to a few hundred rays) made the
  //    Cornell box's patch values worse (11% RMS from the flat solution's
  //    at 6,200 patches, against 5.6% without); spread by area they
  //    created 0.6% of the absorbed power; rows closed alone lost 1.5% to
  //    6% of it in rooms with a window, a lamp or a scan (the links alone:
  //    within 1.2%), rows only kept below 1 lost 2.5% to 25%.
  //  - One factor on every row, the rays' mean G over the links' mean sum
  //    (area-weighted): further from the flat solution's absorbed power
  //    in all five rooms tried (a closed room with a lamp at rho 0.956:
  //    -2.3% against +1.2%; a window: -1.6% against +0.2%).
  size_t rowsMoved = 0;
  double rowMoveRms = 0;
  auto columnSums = [&](std::vector<double>& col) {
    std::vector<double> W(nn), Y(nn, 0.0);
    for (size_t k = nn; k-- > 0;) {  // W: sum of A_i r_i under each node
      const Node& nd = t.nodes[k];
      W[k] = nd.leaf() ? g.A[t.order[nd.first]] * rowScale[t.order[nd.first]] : W[nd.left] + W[nd.right];
    }
    std::fill(col.begin(), col.end(), 0.0);
    for (const Link& l : links) Y[l.q] += double(l.F) * W[l.p] / t.nodes[l.q].A;
    for (size_t k = 0; k < nn; ++k) {  // preorder: an area-mean link reaches every triangle under its source
      const Node& nd = t.nodes[k];
      if (k) Y[k] += Y[nd.parent];
      if (nd.leaf()) col[t.order[nd.first]] += Y[k];
    }
  };
  auto closeRows = [&] {
    std::fill(rowScale.begin(), rowScale.end(), 1.0);
    std::fill(colScale.begin(), colScale.end(), 1.0);
    closedRoom = set.closureRays > 0 && unoccluded;
    for (size_t f = 0; f < nf && closedRoom; ++f) closedRoom = !(g.A[f] > 0) || closure[f] == 1.f;
    rowsMoved = 0;
    rowMoveRms = 0;
    if (!closedRoom) return;
    Rc.resize(nf);
    index();
    const std::vector<glm::vec3> ones(nf, glm::vec3(1.f));
    std::vector<glm::vec3> sums(nf);
    std::vector<double> colSum(nf);
    double moves = 0, rows = 0;
    for (int round = 0; round < kBalanceRounds; ++round) {
      std::fill(rowScale.begin(), rowScale.end(), 1.0);
      sweep(ones, sums);
      for (size_t f = 0; f < nf; ++f) {
        if (!(g.A[f] > 0) || !(sums[f].x > 0)) continue;
        rowScale[f] = 1.0 / sums[f].x;
        if (round == 0) {  // the links' own rows
          moves += (1.0 - sums[f].x) * (1.0 - sums[f].x);
          rows += 1;
          rowsMoved += sums[f].x != 1.0;
        }
      }
      columnSums(colSum);
      for (size_t f = 0; f < nf; ++f) colScale[f] = g.A[f] > 0 && colSum[f] > 0 ? 1.0 / colSum[f] : 1.0;
    }
    rowMoveRms = rows > 0 ? std::sqrt(moves / rows) : 0.0;
  };

  const bool fixed = bounces >= 0;
  const int maxSweeps = fixed ? bounces : (maxIterations > 0 ? maxIterations : autoIterations(rhoMax, tolerance));
  std::vector<glm::vec3> Rn(nf), H(nf, glm::vec3(0.f));
  auto solveSweeps = [&](int sweeps, const Progress& pr) {
    Timer st;
    index();
    if (fixed) sol.Rbounces.assign(size_t(std::max(0, sweeps)), {});
    for (int it = 0; it < sweeps; ++it) {
      sol.Rprev = sol.R;
      if (fixed && keptBounce(it + 1, sweeps)) sol.Rbounces[size_t(it)] = sol.R;  // R^(it + 1)
      sweep(sol.R, H);
      double change = 0;
      for (size_t f = 0; f < nf; ++f) {
        Rn[f] = g.A[f] > 0 ? S[f] + s.faceRho(f) * H[f] : glm::vec3(0.f);
        change += g.A[f] * seenShare(f) * std::fabs(luminance(Rn[f] - sol.R[f]));
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
  closeRows();
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
      closeRows();
      solveSweeps(maxSweeps, part(rounds, 0.7, 1.0));
    }
    sol.Rprev = sol.R;
  }
  // What the vertices gather from, and the indirect irradiance it gives.
  sweep(sol.Rprev, sol.H);
  if (!fixed && sol.residual >= tolerance) {
    char b[240];
    std::snprintf(b, sizeof b,
                  "not converged: hierarchical solve stopped at max_iterations = %d sweeps per refinement round (%d "
                  "rounds) with the residual %.3g above the tolerance %.3g",
                  maxSweeps, rounds, sol.residual, tolerance);
    sol.stats.warn(b);
  }
  if (budgetHit && capped)
    sol.stats.note("links capped at " + std::to_string(maxLinks) + " (max_links): refined best first, the " +
                   "links that may carry the most power split first; some carry more than epsilon of the power");
  else if (budgetHit)
    sol.stats.warn("link refinement stopped at the memory budget (" + std::to_string(links.size()) +
                   " links): some links carry more than epsilon of the power; raise memory_budget_mb");
  // Energy account: emitted power = absorbed + escaped; absorbed from the
  // total irradiance (direct + indirect) of every triangle; escaped: the
  // emitted power the direct light does not bring onto a surface, and the
  // share 1 - G of each triangle's reflected power that its closure rays
  // saw escape. Links whose rows and columns sum to G balance the two
  // exactly at convergence; the difference is what the links create or
  // lose.
  double absorbed = 0, reflected = 0, escaped = P;
  for (size_t f = 0; f < nf; ++f) {
    if (!(g.A[f] > 0)) continue;
    const double As = g.A[f] * seenShare(f);  // the seen part's (Hd is the whole triangle's mean)
    absorbed += luminance((glm::vec3(1.f) - s.faceRho(f)) * (float(g.A[f]) * Hd[f] + float(As) * sol.H[f]));
    reflected += As * luminance(sol.R[f]);
    // The closure rays from buried points met back faces: G of the seen part.
    const double G = seenShare(f) > 0 ? std::min(1.0, double(closure[f]) / seenShare(f)) : 1.0;
    escaped += As * luminance(sol.R[f]) * (1.0 - G) - g.A[f] * luminance(Hd[f]);
  }
  size_t leafLinks = 0;
  for (const Link& l : links) leafLinks += (t.nodes[l.p].leaf() && t.nodes[l.q].leaf()) ? 1 : 0;
  const double unit2 = s.unit * s.unit;
  sol.stats.add("emitted_power_W", P * unit2);
  if (set.enteringPower > 0) sol.stats.add("sky_sun_power_W", set.enteringPower * unit2);  // as the flat solvers say
  sol.stats.add("absorbed_power_W", absorbed * unit2);
  sol.stats.add("reflected_power_W", reflected * unit2);
  const bool converged = fixed || sol.residual < tolerance;
  if (set.closureRays > 0 && !fixed) {  // what escapes is known from the closure rays; all bounces
    sol.stats.add("escaped_power_W", escaped * unit2);
    const double balance = std::fabs(P - absorbed - escaped) / P;
    sol.stats.add("energy_balance_error", balance);
    // With its sign (it was lost): > 0, light created; < 0, lost.
    sol.stats.add("energy_created_fraction", (absorbed + escaped - P) / P);
    // Where the links cannot be closed (occluders, open rooms) their sums
    // stand, and at high reflectance what they create or lose is magnified
    // by 1 / (1 - rho): a sealed room parted by a block read 109% (twice the
    // physical maximum) at rho 0.991 with no word. The indicator itself is
    // rough (5.8% where the absorbed power was 1.2% off), hence 5%.
    // A solve stopped at max_iterations has said so: its missing light is
    // no fault of the links (they were blamed; an outside audit).
    if (balance > kHierarchicalBalanceWarning && converged) {
      char b[400];
      std::snprintf(b, sizeof b,
                    "energy balance off by %.1f%% (the rays' count of what escapes against the power absorbed): the "
                    "hierarchical links %s light here (their sums are not closed where occluders stand, and high "
                    "reflectance magnifies it); the flat solvers (Gauss-Seidel) conserve it",
                    100.0 * balance, absorbed + escaped > P ? "create" : "lose");
      sol.stats.warn(b);
    }
  }
  sol.stats.add("closure_rays", double(closureRays));
  sol.stats.add("closure_seconds", closureSeconds);
  if (closedRoom) {
    sol.stats.add("rows_closed", double(rowsMoved));
    sol.stats.add("row_closure_rms", rowMoveRms);
    sol.stats.note("closed room without occluders: the links' rows and columns closed to 1 (closure_rays)");
  }
  sol.stats.add("hierarchy_nodes", double(nn));
  sol.stats.add("hierarchy_levels", double(t.depth));
  sol.stats.add("links", double(links.size()));
  sol.stats.add("links_patch_to_patch", double(leafLinks));
  sol.stats.add("link_splits", double(splits));
  sol.stats.add("refinement_rounds", double(rounds));
  sol.stats.add("link_rays", double(rays));
  sol.stats.add("probe_rays", double(probe.rays.load()));
  sol.stats.add("link_form_factor_seconds", ffSeconds);
  sol.stats.add("link_refinement_seconds", refineSeconds);
  sol.stats.add("hierarchy_sweep_seconds", solveSeconds);
  sol.stats.add("hierarchy_MB", (baseBytes + double(links.size()) * kHierarchyBytesPerLink) / 1048576.0);
  sol.stats.add("hierarchy_seconds", timer.seconds());
  return sol;
}

}  // namespace gi
