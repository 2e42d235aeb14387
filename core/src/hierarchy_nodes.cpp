// The cluster tree of the hierarchical solver, its nodes' quadrature points
// and the link form factors with visibility rays (see gi/hierarchical.h for
// the equation and the citations, hierarchy_nodes.h for the types).
#include "hierarchy_nodes.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "gi/form_factor_analytic.h"
#include "gi/run.h"
#include "gi/sampling.h"
#include "hit_origin.h"

namespace gi::hierarchy {

Tree buildTree(const Geometry& g) {
  Tree t;
  const size_t nf = g.s.faceCount();
  for (uint32_t f = 0; f < nf; ++f)
    if (g.A[f] > 0) t.order.push_back(f);
  t.leafOf.assign(nf, kNoHit);
  if (t.order.empty()) return t;
  t.nodes.assign(2 * t.order.size() - 1, Node{});
  struct Job { uint32_t node, first, count; int level; };
  std::vector<Job> stack;
  stack.push_back({0, 0, uint32_t(t.order.size()), 1});
  while (!stack.empty()) {
    const Job j = stack.back();
    stack.pop_back();
    t.depth = std::max(t.depth, j.level);
    glm::dvec3 lo(1e300), hi(-1e300), clo(1e300), chi(-1e300);
    double A = 0;
    for (uint32_t k = j.first; k < j.first + j.count; ++k) {
      const uint32_t f = t.order[k];
      const glm::uvec3 tri = g.s.triangles[f];
      for (int v = 0; v < 3; ++v) {
        lo = glm::min(lo, glm::dvec3(g.s.positions[tri[v]]));
        hi = glm::max(hi, glm::dvec3(g.s.positions[tri[v]]));
      }
      clo = glm::min(clo, g.centroid[f]);
      chi = glm::max(chi, g.centroid[f]);
      A += g.A[f];
    }
    Node& nd = t.nodes[j.node];
    nd.c = 0.5 * (lo + hi);
    nd.r = 0.5 * glm::length(hi - lo);
    nd.A = A;
    nd.lo = glm::vec3(lo);
    nd.hi = glm::vec3(hi);
    nd.first = j.first;
    nd.count = j.count;
    if (j.count == 1) {
      t.leafOf[t.order[j.first]] = j.node;
      continue;
    }
    // Median split of the centroids along the longest axis.
    const glm::dvec3 ext = chi - clo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const uint32_t mid = j.first + j.count / 2;
    std::nth_element(t.order.begin() + j.first, t.order.begin() + mid, t.order.begin() + j.first + j.count,
                     [&](uint32_t a, uint32_t b) {
                       return g.centroid[a][axis] < g.centroid[b][axis] ||
                              (g.centroid[a][axis] == g.centroid[b][axis] && a < b);
                     });
    // Preorder: a subtree of c triangles holds the 2c - 1 nodes from its
    // root on; the left subtree follows the parent, the right follows it.
    const uint32_t nl = mid - j.first, nr = j.count - nl;
    const uint32_t left = j.node + 1;
    const uint32_t right = left + 2 * nl - 1;
    Node& parent = t.nodes[j.node];
    parent.left = left;
    parent.right = right;
    t.nodes[left].parent = t.nodes[right].parent = j.node;
    stack.push_back({right, mid, nr, j.level + 1});
    stack.push_back({left, j.first, nl, j.level + 1});
  }
  // Planar nodes, bottom-up: a whole wall's clusters exchange no light with
  // each other, and are culled without descending to their triangles.
  for (size_t k = t.nodes.size(); k-- > 0;) {
    Node& nd = t.nodes[k];
    if (nd.leaf()) {
      const uint32_t f = t.order[nd.first];
      nd.planar = true;
      nd.x0 = g.centroid[f];
      nd.n = nd.axis = g.n[f];
      continue;
    }
    const Node &l = t.nodes[nd.left], &r = t.nodes[nd.right];
    const glm::vec3 sum = float(l.A) * l.axis + float(r.A) * r.axis;
    nd.axis = glm::length(sum) > 1e-12f ? glm::normalize(sum) : l.axis;
    auto half = [&](const Node& c) {  // the child's cone seen from the new axis
      return std::acos(std::clamp(glm::dot(nd.axis, c.axis), -1.f, 1.f)) + std::acos(std::clamp(c.coneCos, -1.f, 1.f));
    };
    nd.coneCos = std::cos(std::min(float(M_PI), std::max(half(l), half(r))));
    nd.planar = l.planar && r.planar && glm::dot(l.n, r.n) > 1.f - 1e-6f &&
                std::fabs(glm::dot(glm::dvec3(l.n), r.x0 - l.x0)) <= 1e-6 * (nd.r + glm::length(nd.c)) &&
                std::fabs(glm::dot(glm::dvec3(r.n), l.x0 - r.x0)) <= 1e-6 * (nd.r + glm::length(nd.c));
    nd.x0 = l.x0;
    nd.n = l.n;
  }
  t.Acum.resize(t.order.size() + 1, 0.0);
  for (size_t k = 0; k < t.order.size(); ++k) t.Acum[k + 1] = t.Acum[k] + g.A[t.order[k]];
  return t;
}

// The centroid of sub-triangle k (0..15) of (a, b, c) split twice at its
// edge midpoints; k's low base-4 digit picks the first split's quarter, so
// any four consecutive k lie in four different quarters.
static glm::dvec3 subCentroid(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, int k) {
  for (int level = 0; level < 2; ++level, k /= 4) {
    const glm::dvec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
    switch (k % 4) {
      case 0: b = ab; c = ca; break;
      case 1: a = ab; c = bc; break;
      case 2: a = ca; b = bc; break;
      default: a = ab; b = bc; c = ca; break;
    }
  }
  return (a + b + c) / 3.0;
}

// The node's 16 quadrature points, stratified by area: point k lies at the
// area fraction (k + 1/2) / 16 of the node's triangles in tree order, at the
// centroid of the sub-triangle holding that fraction of its triangle (a
// triangle: its 16 sub-triangle centroids), with its triangle's normal.
void nodePoints(const Geometry& g, const Tree& t, const Node& nd, glm::dvec3 x[kPoints], glm::vec3 n[kPoints],
                uint32_t faces[kPoints]) {
  const double base = t.Acum[nd.first];
  for (int k = 0; k < kPoints; ++k) {
    const int stratum = (k % 4) * 4 + k / 4;  // consecutive k spread over the node
    const double target = base + nd.A * (stratum + 0.5) / kPoints;
    auto it = std::upper_bound(t.Acum.begin() + nd.first + 1, t.Acum.begin() + nd.first + nd.count + 1, target);
    size_t pos = size_t(it - t.Acum.begin()) - 1;
    pos = std::min<size_t>(pos, nd.first + nd.count - 1);
    const uint32_t f = t.order[pos];
    const double w = std::clamp((target - t.Acum[pos]) / g.A[f], 0.0, 0.999999);
    const glm::uvec3 tri = g.s.triangles[f];
    const int sub = int(w * kPoints);
    x[k] = subCentroid(glm::dvec3(g.s.positions[tri.x]), glm::dvec3(g.s.positions[tri.y]),
                       glm::dvec3(g.s.positions[tri.z]), (sub % 4) * 4 + sub / 4);
    n[k] = g.n[f];
    if (faces) faces[k] = f;
  }
}

bool moveToSeenParts(const Geometry& g, const uint32_t faces[kPoints], NodePointSet& e) {
  if (!g.seen) return true;
  bool keep[kPoints];
  uint32_t usedFace[kPoints], used[kPoints];  // per triangle met, its open points taken so far
  int nUsed = 0, kept = 0;
  for (int k = 0; k < kPoints; ++k) {
    const uint32_t f = faces[k];
    const float a = (*g.seen)[f];
    keep[k] = a >= 1.f;
    if (a > 0.f && a < 1.f && !(*g.seenPoints)[f].empty()) {
      const std::vector<glm::vec3>& open = (*g.seenPoints)[f];
      int u = 0;
      while (u < nUsed && usedFace[u] != f) ++u;
      if (u == nUsed) usedFace[nUsed] = f, used[nUsed++] = 0;
      e.x[k] = glm::dvec3(open[used[u]++ % open.size()]);
      keep[k] = true;
    }
    kept += keep[k];
  }
  if (kept == 0) return false;
  for (int k = 0; k < kPoints; ++k) {
    if (keep[k]) continue;
    int j = (k + 1) % kPoints;
    while (!keep[j]) j = (j + 1) % kPoints;
    e.x[k] = e.x[j];
    e.n[k] = e.n[j];
  }
  return true;
}

bool boxBehind(const Node& box, const glm::dvec3& x0, const glm::vec3& n) {
  double best = -1e300;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 corner((k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y, (k & 4) ? box.hi.z : box.lo.z);
    best = std::max(best, glm::dot(glm::dvec3(n), corner - x0));
  }
  return best <= 1e-6 * (box.r + glm::length(box.c)) + 1e-30;  // float positions: relative rounding
}

// F_pq for one link: the exact unoccluded triangle-to-triangle factor for
// two triangles (gi/form_factor_analytic.h); between a cluster and a
// triangle, the exact point-to-triangle factor from the cluster's 16 points
// (by reciprocity when the cluster is the source); between two clusters the
// mean of the point kernel cos cos / (pi r^2) A_q over the 16 x 16 point pairs
// (the cluster's elements keep their own orientation: Smits et al. 1994); times
// the fraction of linkRays visibility rays between paired points that pass.
// A cluster source remembers which rays passed (Link::samples): the sweep
// then gathers the radiosity at their source points, not the cluster's area
// mean, because bright and visible go together (a triangle in a nook is both
// darker and hidden), and the area mean times the visible fraction carries
// too little (7-8% on the links from clusters in the Cornell-like room).
//
// A ray pairs a source point with a receiver point that exchange light (the
// first in a fixed cycle from the ray's own receiver point); source points
// that face away from the whole receiver are passed over for the next
// ones, up to all 16 of a cluster (a source's point that no receiver point
// sees carries nothing in F either). Only pairs fixed in advance were tried
// until 5 December 2026, and where none of the four exchanged light (a
// cluster of both faces of a thin partition, its four ray points all on
// the far face) the link kept its unoccluded factor and gathered the
// cluster's area mean, bright far face included: a room lit only through a
// gap above such a partition received +15% against the path-traced
// reference, where the flat solver gave -0.5% (+3.6% with this alone,
// +2.3% with the refiner's look along links into clusters: Refiner::
// acceptable; `HierarchicalRadiosity.ThinPartitionStopsTheLight`).
bool linkRay(const NodePointSet& pp, const NodePointSet& pq, int i, int j, float eps, Ray& r) {
  const glm::vec3 o = glm::vec3(pp.x[i]) + pp.n[i] * eps;
  const glm::vec3 e = glm::vec3(pq.x[j]) + pq.n[j] * eps;
  const glm::vec3 d = e - o;
  const float len = glm::length(d);
  if (!(len > 0)) return false;
  if (glm::dot(pp.n[i], d) <= 0 || glm::dot(pq.n[j], d) >= 0) return false;
  r.o = o;
  r.d = d / len;
  r.tfar = len * (1.f - 1e-4f) - eps;
  return true;
}

bool linkPartlyVisible(const Geometry& g, const Tree& t, const RayCaster& caster, uint32_t p, uint32_t q, float eps,
                       uint64_t& rays, NodePointCache& points) {
  const NodePointSet &pp = points.receiver(g, t, p), &pq = points.source(g, t, q);
  bool passed = false, blocked = false;
  Ray r;
  for (int i = 0; i < kPoints && !(passed && blocked); ++i) {
    // Receiver point i with the first source point (from its own in the
    // rays' order) that it exchanges light with; none: it receives nothing.
    int j = raySourcePoint(i), tries = 0;
    while (!linkRay(pp, pq, i, j, eps, r) && ++tries < kPoints) j = (j + 1) % kPoints;
    if (tries == kPoints) {
      blocked = true;
      continue;
    }
    ++rays;
    (caster.occluded(r) ? blocked : passed) = true;
  }
  return passed && blocked;
}

void linkFormFactor(const Geometry& g, const Tree& t, const RayCaster& caster, Link& link, int linkRays,
                    bool unoccluded, float eps, uint64_t& rays, NodePointCache& points) {
  const uint32_t p = link.p, q = link.q;
  const Node &np = t.nodes[p], &nq = t.nodes[q];
  const NodePointSet &pp = points.receiver(g, t, p), &pq = points.source(g, t, q);
  const glm::dvec3 *xp = pp.x, *xq = pq.x;
  const glm::vec3 *npn = pp.n, *nqn = pq.n;
  auto corners = [&](const Node& nd, glm::dvec3 v[3]) {
    const glm::uvec3 tri = g.s.triangles[t.order[nd.first]];
    for (int k = 0; k < 3; ++k) v[k] = glm::dvec3(g.s.positions[tri[k]]);
  };
  // From points x (normals n) of a cluster to a triangle: the exact
  // point-to-triangle factor, 0 where the triangle turns its back on x or
  // x lies in its plane (up to the ray offset, as for the analytic form
  // factors: a point of a two-sided surface's reversed copy may lie inside
  // the triangle, where the factor's contour integral gives 1, not 0).
  auto toTriangle = [&](const glm::dvec3 x[kPoints], const glm::vec3 n[kPoints], const Node& tri) {
    glm::dvec3 v[3];
    corners(tri, v);
    const glm::dvec3 tn(g.n[t.order[tri.first]]);
    double sum = 0;
    for (int k = 0; k < kPoints; ++k)
      if (glm::dot(tn, x[k] - v[0]) > double(eps))
        sum += pointToTriangleFormFactor(x[k], glm::dvec3(n[k]), v[0], v[1], v[2]);
    return sum / kPoints;
  };
  double F = 0;
  if (np.leaf() && nq.leaf()) {
    glm::dvec3 a[3], b[3];
    corners(np, a);
    corners(nq, b);
    // Either triangle wholly behind or in the other's plane, up to the ray
    // offset (as the analytic form factors): 0. Without it a two-sided
    // surface's reversed copy, its corners rounded a hair in front of the
    // face, filled the face's whole hemisphere (F about 1).
    const glm::dvec3 na(g.n[t.order[np.first]]), nb(g.n[t.order[nq.first]]);
    if (heightAbovePlane(na, a[0], b[0], b[1], b[2]) > double(eps) && heightAbovePlane(nb, b[0], a[0], a[1], a[2]) > double(eps))
      F = triangleToTriangleFormFactor(a, b, 1, 1e-2, 3);
  } else if (nq.leaf()) {
    F = toTriangle(xp, npn, nq);  // exact over the source triangle, 16 points of the receiving cluster
  } else if (np.leaf()) {
    F = nq.A / np.A * toTriangle(xq, nqn, np);  // reciprocity: A_p F_pq = A_q F_qp
  } else {
    for (int i = 0; i < kPoints; ++i)
      for (int j = 0; j < kPoints; ++j) {
        const glm::dvec3 d = xq[j] - xp[i];
        const double r2 = glm::dot(d, d);
        if (!(r2 > 0)) continue;
        const double ci = glm::dot(glm::dvec3(npn[i]), d), cj = -glm::dot(glm::dvec3(nqn[j]), d);
        // Each point off the other's plane by more than the ray offset (as
        // above): two points of a two-sided surface's sides, a rounding
        // apart, would otherwise give ci cj / r^4 of any size.
        if (ci <= double(eps) || cj <= double(eps)) continue;
        F += ci * cj / (M_PI * r2 * r2);
      }
    F *= nq.A / double(kPoints * kPoints);
  }
  F = std::min(F, 1.0);
  link.F = 0.f;
  const uint32_t probed = link.samples & Link::kProbed;  // the refiner's mark stays
  link.samples = Link::kAreaMean | probed;
  if (!(F > 0)) return;
  link.F = float(F);
  if (unoccluded) return;
  Ray r;
  // A cluster source: the mask names the source points some passing ray
  // reached, bit sourceBit(j) for point j (up to kPoints rays, each point at
  // most once; beyond, the points again). Its F is per named point: the
  // visible share times the mean radiosity of the points named (with one ray
  // a point, F / rays per passing ray). The area mean of such a source
  // (what links with more than 16 rays gathered until 5 December 2026)
  // counts the triangles no ray reached, a partition's bright far face
  // among them: +230% to +360% behind a window at 17 or 32 link rays.
  //
  // The visible share weighs each ray by the point kernel of its pair,
  // cos cos / r^4: the share of the factor that passes, not of the point
  // pairs. Counted by pairs (until 5 December 2026) a long source whose far
  // part is hidden and near part seen, whose factor nearly all comes from
  // the near part, passed a fraction of the light (a small square beside a
  // long triangle under a plate: its radiosity 0.121 against 0.225 for the
  // flat solvers; an outside audit).
  const bool sampled = !nq.leaf();
  const int lastK = linkRays <= kPoints ? kPoints : linkRays + kPoints;
  int pass = 0, cast = 0;
  double wCast = 0, wPass = 0;
  uint32_t mask = 0;
  for (int k = 0; k < lastK && cast < linkRays; ++k) {
    const int j = raySourcePoint(k);
    int i = rayReceiverPoint(k), tries = 0;
    while (!linkRay(pp, pq, i, j, eps, r) && ++tries < kPoints) i = (i + 1) % kPoints;
    if (tries == kPoints) continue;  // source point j sees no point of the receiver
    const glm::dvec3 d = pq.x[j] - pp.x[i];
    const double r2 = glm::dot(d, d);
    const double w = glm::dot(glm::dvec3(pp.n[i]), d) * -glm::dot(glm::dvec3(pq.n[j]), d) / (r2 * r2);
    ++cast;
    wCast += w;
    if (caster.occluded(r)) continue;
    ++pass;
    wPass += w;
    mask |= 1u << sourceBit(j);
  }
  rays += uint64_t(cast);
  if (!cast) return;
  const double share = wCast > 0 ? wPass / wCast : double(pass) / double(cast);
  if (sampled) {
    // The visible share times the mean radiosity of the points named.
    const int named = __builtin_popcount(mask);
    link.F = named > 0 ? float(F * share / double(named)) : 0.f;
    link.samples = mask | probed;
  } else {
    link.F = float(F * share);
  }
}

std::vector<float> rowClosures(const Geometry& g, const RayCaster& caster, int rays, uint32_t seed, float eps,
                               uint64_t& cast) {
  const size_t nf = g.s.faceCount();
  std::vector<float> c(nf, 0.f);
  if (rays <= 0) return c;
  parallelBlocks(nf, Progress(nullptr), "", [&](size_t b, size_t e) {
    Ray ray;
    for (size_t f = b; f < e; ++f) {
      if (!(g.A[f] > 0)) continue;
      const Frame frame(g.n[f]);
      const PaddedSobol smp(hash3(uint32_t(f), seed, 0xc105u));
      const FacePoints points(g.s, uint32_t(f), g.n[f], eps, caster);
      int hits = 0;
      for (int k = 0; k < rays; ++k) {
        ray.o = points.at(smp(uint32_t(k), 0)) + g.n[f] * eps;
        ray.d = frame.toWorld(cosineHemisphere(smp(uint32_t(k), 1)));
        ray.tnear = 0.f;
        ray.tfar = std::numeric_limits<float>::infinity();
        const Hit h = caster.intersect(ray);
        hits += h.valid() && h.face != f && g.A[h.face] > 0 && glm::dot(ray.d, g.n[h.face]) < 0.f;
      }
      c[f] = hits == rays ? 1.f : float(double(hits) / rays);
    }
  });
  cast += uint64_t(rays) * uint64_t(std::count_if(g.A.begin(), g.A.end(), [](double a) { return a > 0; }));
  return c;
}

}  // namespace gi::hierarchy
