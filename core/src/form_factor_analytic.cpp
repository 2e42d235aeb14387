#include "gi/form_factor_analytic.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "gi/form_factors.h"
#include "gi/sampling.h"

namespace gi {

double lambertEdgeTerm(const glm::dvec3& v0, const glm::dvec3& v1, const glm::dvec3& n) {
  if (glm::dot(v0, v0) == 0 || glm::dot(v1, v1) == 0) return 0.0;  // x on the polygon's corner
  const glm::dvec3 cr = glm::cross(v0, v1);
  const double lc = glm::length(cr);
  if (lc == 0) return 0.0;
  return std::atan2(lc, glm::dot(v0, v1)) * glm::dot(n, cr) / lc;
}

double pointToTriangleFormFactor(const glm::dvec3& x, const glm::dvec3& n, const glm::dvec3& a, const glm::dvec3& b,
                                 const glm::dvec3& c) {
  // Clip the triangle to n . (p - x) >= 0 (Sutherland-Hodgman, one plane).
  const glm::dvec3 in[3] = {a - x, b - x, c - x};
  glm::dvec3 poly[4];
  int m = 0;
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3& p = in[k];
    const glm::dvec3& q = in[(k + 1) % 3];
    const double dp = glm::dot(n, p), dq = glm::dot(n, q);
    if (dp >= 0) poly[m++] = p;
    if ((dp >= 0) != (dq >= 0)) poly[m++] = p + (q - p) * (dp / (dp - dq));
  }
  if (m < 3) return 0.0;
  double sum = 0;
  for (int k = 0; k < m; ++k) sum += lambertEdgeTerm(poly[k], poly[(k + 1) % m], n);
  return std::fabs(sum) / (2.0 * M_PI);
}

namespace {

struct Tri {
  glm::dvec3 a, b, c;
  glm::dvec3 centroid() const { return (a + b + c) / 3.0; }
  // Distance from the centroid to the farthest corner.
  double radius() const {
    const glm::dvec3 m = centroid();
    return std::sqrt(std::max({glm::dot(a - m, a - m), glm::dot(b - m, b - m), glm::dot(c - m, c - m)}));
  }
  // Midpoint subdivision: three corner quarters and the middle one, all similar to this.
  std::array<Tri, 4> quarters() const {
    const glm::dvec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
    return {Tri{a, ab, ca}, Tri{ab, b, bc}, Tri{ca, bc, c}, Tri{ab, bc, ca}};
  }
};

std::vector<Tri> baseTriangles(const Tri& t, int level) {
  std::vector<Tri> out{t};
  for (int l = 0; l < level; ++l) {
    std::vector<Tri> next;
    next.reserve(out.size() * 4);
    for (const Tri& s : out)
      for (const Tri& q : s.quarters()) next.push_back(q);
    out.swap(next);
  }
  return out;
}

double distanceToSegment(const glm::dvec3& x, const glm::dvec3& p, const glm::dvec3& q) {
  const glm::dvec3 d = q - p;
  const double dd = glm::dot(d, d);
  const double u = dd > 0 ? std::clamp(glm::dot(x - p, d) / dd, 0.0, 1.0) : 0.0;
  return glm::length(x - (p + u * d));
}

// Where the midpoint rule cannot see its error: g changes across the
// target's edges within a band as wide as the height h above the target's
// plane, and across a target narrower than a sub-triangle, and a
// sub-triangle whose sample points all miss such a band passes the
// comparison (two plates 0.01 apart read F = 1.009 for 0.980; a strip 0.001
// high at a common edge, -62%). So a sub-triangle is split whatever its
// points say where its extent w across the nearest of the target's edges
// (in its own plane, perpendicular to that edge) exceeds 3 h at its
// centroid (a band narrower than itself; faces meeting at a common edge at
// more than about 20 degrees are left to the comparison, which handles
// them) or the target's smallest altitude, and that edge passes within 2 w
// of its centroid, unless even all of g there stays below the tolerance:
// F <= A / (pi d^2) from any point at least d from a target of area A (d
// bounded below by h less the sub-triangle's radius). The extent across
// the edge, not the radius: a sliver along an edge keeps its shape under
// midpoint subdivision, and measured by its length it was split to the
// last level everywhere (a 192-patch tube took 355 s). A corner within
// onPlane (the scene's ray offset) of the target's plane is on it: a
// sub-triangle with a side on a common edge has its centroid's w = 3 h / sin
// of the faces' angle, so the rule would split it to the budget wherever
// rounding (corners of a refined mesh, stored as floats) lifts that side
// off the plane; the factor there is nearly constant across the edge (the
// target's edge is seen at the same angle from every distance), which the
// comparison handles (a patch of a sheared room beside its emitting
// ceiling took 16,390 splits, 12 evaluations each).
struct TargetEdges {
  std::array<glm::dvec3, 2> own[3];
  const std::array<glm::dvec3, 2>* edges = own;
  size_t count = 3;
  glm::dvec3 unitNormal{0.0}, origin{0.0};
  double area = 0, narrowest = 0, onPlane = 0;
  TargetEdges(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double onPlane_)
      : own{{a, b}, {b, c}, {c, a}}, origin(a), onPlane(onPlane_) {
    const glm::dvec3 cr = glm::cross(b - a, c - a);
    area = 0.5 * glm::length(cr);
    unitNormal = area > 0 ? cr / (2.0 * area) : glm::dvec3(0.0);
    const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    narrowest = longest > 0 ? area / longest : 0.0;  // half the smallest altitude
  }
  TargetEdges(const FormFactorTarget& t, double onPlane_)
      : edges(t.edges.data()), count(t.edges.size()), unitNormal(t.normal), origin(t.origin), area(t.area),
        narrowest(t.narrowest), onPlane(onPlane_) {}
  TargetEdges(const TargetEdges&) = delete;
  TargetEdges& operator=(const TargetEdges&) = delete;
  bool mustSplit(const Tri& t, double tolPerShare) const {
    if (count == 0) return false;
    const glm::dvec3 m = t.centroid();
    size_t k = 0;
    double edge = std::numeric_limits<double>::infinity();
    for (size_t e = 0; e < count; ++e)
      if (const double d = distanceToSegment(m, edges[e][0], edges[e][1]); d < edge) edge = d, k = e;
    const glm::dvec3 along = edges[k][1] - edges[k][0];
    glm::dvec3 across = glm::cross(glm::cross(t.b - t.a, t.c - t.a), along);  // in t's plane, perpendicular to the edge
    const double l = glm::length(across);
    double w = 2.0 * t.radius();  // t's plane perpendicular to the edge: every direction in it is across
    if (l > 0) {
      across /= l;
      const double xa = glm::dot(t.a, across), xb = glm::dot(t.b, across), xc = glm::dot(t.c, across);
      w = std::max({xa, xb, xc}) - std::min({xa, xb, xc});
    }
    if (edge >= 2.0 * w) return false;
    // The band: only where the whole sub-triangle is on one side of the
    // target's plane (one that crosses it has g going to 0 along the
    // crossing, which the comparison follows, as at a common edge).
    auto side = [&](const glm::dvec3& x) { return glm::dot(unitNormal, x - origin); };
    const double h = std::fabs(side(m));
    const double ha = side(t.a), hb = side(t.b), hc = side(t.c);
    const bool oneSide =
        (ha > onPlane && hb > onPlane && hc > onPlane) || (ha < -onPlane && hb < -onPlane && hc < -onPlane);
    if ((!oneSide || w <= 3.0 * h) && w <= narrowest) return false;
    const double d = h - t.radius();
    return d <= 0 || area / (M_PI * d * d) > tolPerShare;
  }
};

// w x (mean of g over t), given the one-point estimate wg = w g(centroid):
// the quarters' estimate is accepted where it differs from the one-point one
// by at most tolPerShare x w (the midpoint rule's error falls by about 4 per
// level for a smooth integrand, so that difference is about 3 times the
// quarters' error; the corner quarters' centroids average to t's, so a
// linear integrand gives no difference); elsewhere, and while levels are left, each quarter is
// refined in turn. The integrand is continuous (the point-to-triangle factor
// goes to 0 where x reaches either plane) but its slope is unbounded along a
// common edge, which is where the splitting concentrates.
constexpr int kEdgeLevels = 6;

// At most this many sub-triangles a pair splits, for the comparison and the
// target's edges together (12 evaluations each): a bound on the cost of any
// configuration the rules above misjudge (the catalogue's hardest case,
// plates 0.01 apart, splits about 9,000 per triangle pair; a patch beside a
// light at a common edge, under 100; without a shared bound, a hostile
// pair could split 38,000).
constexpr long kSplitBudget = 16384;

// A sliver source keeps its shape under midpoint subdivision, so the part of
// it near a target (a strip 1 wide meeting a wall at its short end, 1,500
// long) is reached only after log2 of its aspect ratio levels, and with
// splits in proportion to it: at 16,384 splits and 14 levels the strip's
// factor read 49% low, one 3,000 long 77% (an outside audit). Slivers of
// aspect ratio A (longest side over the altitude to it) above kFreeAspect
// get A / kFreeAspect times the budget (at most kMaxBudgetScale) and log2(A
// / kFreeAspect) more levels; what is still cut short is counted and said.
constexpr double kFreeAspect = 256.0;
constexpr double kMaxBudgetScale = 64.0;

struct Allowance {
  long budget = kSplitBudget;
  int extraLevels = 0;
};
Allowance allowanceFor(const Tri& t) {
  const double ab = glm::length(t.b - t.a), bc = glm::length(t.c - t.b), ca = glm::length(t.a - t.c);
  const double longest = std::max({ab, bc, ca}), area = 0.5 * glm::length(glm::cross(t.b - t.a, t.c - t.a));
  const double aspect = area > 0 ? longest * longest / (2.0 * area) : 1.0;
  Allowance a;
  if (!(aspect > kFreeAspect)) return a;
  const double scale = std::min(aspect / kFreeAspect, kMaxBudgetScale);
  a.budget = long(double(kSplitBudget) * scale);
  a.extraLevels = int(std::ceil(std::log2(scale)));
  return a;
}

// target: null for the comparison alone (levelsLeft levels: it splits while
// levelsLeft > 1); else the comparison splits while levelsLeft > kEdgeLevels
// + 1 (as many levels as without a target) and the target's edges for
// kEdgeLevels more, while *splitBudget lasts (null: no budget).
// *cut (if given) is set where a split was wanted and no level or budget
// was left: the estimate there may miss the tolerance.
template <class G>
double refine(const Tri& t, double w, double wg, const G& g, const TargetEdges* target, long* splitBudget,
              int levelsLeft, double tolPerShare, bool* cut = nullptr) {
  const auto q = t.quarters();
  // The middle quarter's centroid is t's own: its value is known.
  double wq[4] = {0.25 * w * g(q[0].centroid()), 0.25 * w * g(q[1].centroid()), 0.25 * w * g(q[2].centroid()), 0.25 * wg};
  double sum = wq[0] + wq[1] + wq[2] + wq[3];
  // The comparison splits for up to levelsLeft levels, the target's edges
  // for kEdgeLevels more (a strip 0.001 high at a common edge needs 11).
  const bool compared = levelsLeft > (target ? kEdgeLevels + 1 : 1) && std::fabs(sum - wg) > tolPerShare * w;
  if (levelsLeft <= 1 || (splitBudget && *splitBudget <= 0)) {
    if (cut && (std::fabs(sum - wg) > tolPerShare * w || (target && target->mustSplit(t, tolPerShare)))) *cut = true;
    return sum;
  }
  if (!compared && (!target || !target->mustSplit(t, tolPerShare))) return sum;
  if (splitBudget) --*splitBudget;
  sum = 0;
  for (int k = 0; k < 4; ++k)
    sum += refine(q[k], 0.25 * w, wq[k], g, target, splitBudget, levelsLeft - 1, tolPerShare, cut);
  return sum;
}

// The refinement: each split must change a sub-triangle's estimate by less
// than kRelTol x max(F, kFloorF) x (its share of the area), F the pair's base
// estimate (about kRelTol / 3 of F in all, 0.2% on the catalogue cases); the
// floor keeps pairs that hardly matter (F below 1e-3) from being refined
// much. At most kMaxRefine levels beyond the base: a common edge takes
// about 3 x 2^k quarters at level k, and a thin patch meeting another at a
// common edge needs 7 to 8 levels in all for 0.1%.
constexpr double kRelTol = 1e-2;
constexpr double kFloorF = 1e-3;
constexpr int kMaxRefine = 8;
// Only pairs whose bounding spheres are closer than kNear base sub-triangle
// radii are refined. Farther, the base rule's relative error, about
// (r / d)^2 / 4 (12% for unit squares one apart with one point, r / d =
// 0.7), is below 1.6% and falls as 1 / d^2: refining every pair would double
// the cost of the 1.5k-patch Cornell box for little (measured).
constexpr double kNear = 4.0;
// meanOverTriangle takes the centroid alone beyond this many of the source's
// radii, four base points beyond this many of theirs, and refines closer:
// the one-point rule's error, about (r / d)^2 / 4, is below 0.1% beyond.
constexpr double kMeanNear = 16.0;

}  // namespace

int analyticBaseLevel(int points) {
  int level = 0;
  while (level < 6 && (4 << (2 * level)) <= points) ++level;
  return level;
}

double triangleToTriangleFormFactor(const glm::dvec3 s[3], const glm::dvec3 t[3], int baseLevel, double relTol,
                                    int maxRefine) {
  const glm::dvec3 n = glm::normalize(glm::cross(s[1] - s[0], s[2] - s[0]));
  const glm::dvec3 nt = glm::cross(t[1] - t[0], t[2] - t[0]);
  auto g = [&](const glm::dvec3& x) {
    return glm::dot(nt, x - t[0]) > 0 ? pointToTriangleFormFactor(x, n, t[0], t[1], t[2]) : 0.0;
  };
  const std::vector<Tri> base = baseTriangles(Tri{s[0], s[1], s[2]}, baseLevel);
  const double w = 1.0 / double(base.size());
  std::vector<double> wg(base.size());
  double Fbase = 0;
  for (size_t k = 0; k < base.size(); ++k) Fbase += (wg[k] = w * g(base[k].centroid()));
  const double tolPerShare = relTol * std::max(Fbase, FormFactors::kNegligibleF);
  // The comparison alone: the hierarchy splits its links itself (and its
  // furnace and closure were measured with this rule).
  double F = 0;
  for (size_t k = 0; k < base.size(); ++k) F += refine(base[k], w, wg[k], g, nullptr, nullptr, maxRefine, tolPerShare);
  return F;
}

double meanOverTriangle(const glm::dvec3 s[3], const std::function<double(const glm::dvec3&)>& g,
                        const FormFactorTarget& target, double inPlane, glm::dvec3* best) {
  const Tri src{s[0], s[1], s[2]};
  if (best) *best = src.centroid();
  const glm::dvec3 cr = glm::cross(s[1] - s[0], s[2] - s[0]);
  const double l = glm::length(cr);
  if (!(l > 0.0)) return 0.0;
  const glm::dvec3 n = cr / l;
  double front = -std::numeric_limits<double>::infinity();
  for (const auto& e : target.edges) front = std::max(front, glm::dot(n, e[0] - s[0]));
  if (front <= inPlane) return 0.0;
  if (!target.twoSided && heightAbovePlane(target.normal, target.origin, s[0], s[1], s[2]) <= inPlane) return 0.0;
  // Far from the target, the centroid alone: its error, about (r / d)^2 / 4, is below 0.1%.
  const double d = glm::length(src.centroid() - target.centre) - src.radius() - target.radius;
  if (d >= kMeanNear * src.radius()) return g(src.centroid());
  const std::vector<Tri> base = baseTriangles(src, 1);
  const double w = 1.0 / double(base.size());
  std::vector<double> wg(base.size());
  double Fbase = 0, top = -1;
  for (size_t k = 0; k < base.size(); ++k) {
    const glm::dvec3 x = base[k].centroid();
    Fbase += (wg[k] = w * g(x));
    if (best && wg[k] > top) top = wg[k], *best = x;
  }
  if (d >= kMeanNear * 0.5 * src.radius()) return Fbase;
  const double tolPerShare = kRelTol * std::max(Fbase, kFloorF);
  const TargetEdges edges(target, inPlane);
  long splitBudget = kSplitBudget;
  double F = 0;
  for (size_t k = 0; k < base.size(); ++k)
    F += refine(base[k], w, wg[k], g, &edges, &splitBudget, kMaxRefine + kEdgeLevels, tolPerShare);
  return F;
}

FormFactorRow FormFactors::analyticRow(uint32_t i) const {
  FormFactorRow r;
  const auto& ti = s_.triangles[i];
  const Tri src{glm::dvec3(s_.positions[ti.x]), glm::dvec3(s_.positions[ti.y]), glm::dvec3(s_.positions[ti.z])};
  const glm::dvec3 n(normal_[i]);
  const int level = analyticBaseLevel(set_.analyticPoints);
  const std::vector<Tri> base = baseTriangles(src, level);
  const double w = 1.0 / double(base.size());
  const double rBase = radius_[i] / double(1 << level);
  std::vector<glm::dvec3> xs(base.size());
  std::vector<glm::vec3> lifted(base.size());  // visibility rays start off the surface
  for (size_t k = 0; k < base.size(); ++k) {
    xs[k] = base[k].centroid();
    lifted[k] = glm::vec3(xs[k]) + normal_[i] * eps_;
  }
  Rng rng(hash3(i, set_.seed, 0xf4u));
  std::vector<double> wg(base.size());
  double total = 0;
  uint64_t rays = 0, far = 0, cutPairs = 0;
  const Allowance allowance = allowanceFor(src);
  for (uint32_t j = 0; j < uint32_t(s_.faceCount()); ++j) {
    if (j == i || !ok_[j]) continue;
    // Far pairs: F <= A_j / (pi d^2) < kNegligibleF for any point of i, with
    // d a lower bound of the distance between the two triangles' bounding
    // spheres. Such a factor changes across i by less than i's size over d
    // (1/1800 or less), so i's centroid and one visibility ray give it. (They
    // were dropped: each is negligible, but a far plate cut into many small
    // faces lost its whole factor, and a receiver that sees only far faces
    // received nothing; an outside audit.)
    const double d = glm::length(centroid_[i] - centroid_[j]) - radius_[i] - radius_[j];
    const bool farPair = d > 0 && area_[j] / (M_PI * d * d) < kNegligibleF;
    const auto& tj = s_.triangles[j];
    const glm::dvec3 pa(s_.positions[tj.x]), pb(s_.positions[tj.y]), pc(s_.positions[tj.z]);
    // j wholly behind (or in) i's plane, or i wholly behind j's: F = 0 at
    // every point of i. "In" up to the scene's ray offset: coplanar faces
    // whose corners were rounded off the plane (a face and its duplicate,
    // refined) are coplanar, as the rays, which start that far off the
    // surface, see them; otherwise the rounding gives such a pair F of about
    // 0.5 and refines it to the last level (measured).
    const double inPlane = double(eps_);
    if (heightAbovePlane(n, src.a, pa, pb, pc) <= inPlane) continue;
    const glm::dvec3 nj(normal_[j]);
    if (heightAbovePlane(nj, pa, src.a, src.b, src.c) <= inPlane) continue;
    auto g = [&](const glm::dvec3& x) {
      return glm::dot(nj, x - pa) > 0 ? pointToTriangleFormFactor(x, n, pa, pb, pc) : 0.0;  // 0 where j faces away
    };
    if (farPair) {
      ++far;
      const double f = g(centroid_[i]);
      if (!(f > 0)) continue;
      if (!unoccluded_) {
        ++rays;
        const glm::vec3 from = glm::vec3(centroid_[i]) + normal_[i] * eps_;
        if (!visibleByFormFactorKernel(caster_, from, normal_[i], s_.positions[tj.x], s_.positions[tj.y],
                                       s_.positions[tj.z], rng, eps_))
          continue;
      }
      r.j.push_back(j);
      r.F.push_back(float(f));
      total += f;
      continue;
    }
    double Fbase = 0;
    for (size_t k = 0; k < base.size(); ++k) Fbase += (wg[k] = w * g(xs[k]));
    const bool near = d < kNear * rBase;
    const double tolPerShare = kRelTol * std::max(Fbase, kFloorF);
    const TargetEdges target(pa, pb, pc, inPlane);
    long splitBudget = allowance.budget;
    bool cut = false;
    double F = 0;
    for (size_t k = 0; k < base.size(); ++k) {
      const double f = near ? refine(base[k], w, wg[k], g, &target, &splitBudget,
                                     kMaxRefine + kEdgeLevels + allowance.extraLevels, tolPerShare, &cut)
                            : wg[k];
      if (f <= 0) continue;
      // Visibility: one ray per base point to a point of j drawn by the
      // form factor's kernel, for all of that base sub-triangle's refined
      // quarters (as many rays as before refinement).
      if (!unoccluded_) {
        ++rays;
        if (!visibleByFormFactorKernel(caster_, lifted[k], normal_[i], s_.positions[tj.x], s_.positions[tj.y],
                                       s_.positions[tj.z], rng, eps_))
          continue;
      }
      F += f;
    }
    cutPairs += cut && F > 0;
    if (F > 0) {
      r.j.push_back(j);
      r.F.push_back(float(F));
      total += F;
    }
  }
  rays_[i] += rays;
  farPairs_[i] += far;
  cutPairs_[i] += cutPairs;
  r.escaped = float(std::max(0.0, 1.0 - total));
  return r;
}

}  // namespace gi
