#include "gi/luminaires.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "gi/color.h"
#include "gi/form_factor_analytic.h"
#include "gi/raycaster.h"
#include "gi/sampling.h"
#include "gi/sky.h"

namespace gi {

namespace {

uint64_t edgeKey(uint32_t a, uint32_t b) { return (uint64_t(a) << 32) | b; }

struct UnionFind {
  std::vector<uint32_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// Joins boundary edges (a, b), (b, c) where b is the end of only the one
// and the start of only the other and lies within tol of the line a-c (a
// subdivided side of the polygon): the contour terms of collinear pieces add
// up to the whole side's, so the factor is the same with fewer terms.
template <class Pos>
void mergeCollinear(std::vector<std::array<uint32_t, 2>>& edges, const Pos& pos, double tol) {
  std::unordered_map<uint32_t, int> in, out;
  std::unordered_map<uint32_t, size_t> from;
  for (size_t i = 0; i < edges.size(); ++i) {
    ++out[edges[i][0]];
    ++in[edges[i][1]];
    from[edges[i][0]] = i;
  }
  std::vector<uint8_t> dead(edges.size(), 0);
  for (size_t i = 0; i < edges.size(); ++i) {
    if (dead[i]) continue;
    for (size_t steps = 0; steps < edges.size(); ++steps) {
      const uint32_t b = edges[i][1];
      if (in[b] != 1 || out[b] != 1) break;
      const size_t j = from[b];
      if (j == i || dead[j]) break;
      const glm::dvec3 a = pos(edges[i][0]), c = pos(edges[j][1]), ac = c - a;
      const double len = glm::length(ac);
      if (!(len > 0) || glm::length(glm::cross(ac, pos(b) - a)) > tol * len || glm::dot(ac, pos(b) - a) <= 0) break;
      edges[i][1] = edges[j][1];
      dead[j] = 1;
    }
  }
  size_t m = 0;
  for (size_t i = 0; i < edges.size(); ++i)
    if (!dead[i]) edges[m++] = edges[i];
  edges.resize(m);
}

// The luminaire's bounding rectangle in its plane, u along its longest
// boundary edge, and its outline in the rectangle's coordinates.
void boundingRectangle(Luminaire& L) {
  if (L.boundary.empty() || L.boundary.size() > Luminaires::kRectEdges) return;
  glm::dvec3 along(0.0);
  for (const auto& e : L.boundary)
    if (glm::length(e[1] - e[0]) > glm::length(along)) along = e[1] - e[0];
  const glm::dvec3 u = glm::normalize(along - glm::dot(along, L.normal) * L.normal), v = glm::cross(L.normal, u);
  glm::dvec2 lo(1e300), hi(-1e300);
  for (const glm::dvec3& c : L.corners) {
    const glm::dvec2 q(glm::dot(c - L.origin, u), glm::dot(c - L.origin, v));
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  const glm::dvec2 ext = hi - lo;
  if (!(ext.x > 0 && ext.y > 0) || L.area < 0.25 * ext.x * ext.y) return;
  L.rectCorner = L.origin + lo.x * u + lo.y * v;
  L.u = ext.x * u;
  L.v = ext.y * v;
  auto local = [&](const glm::dvec3& p) {
    return glm::dvec2(glm::dot(p - L.rectCorner, u) / ext.x, glm::dot(p - L.rectCorner, v) / ext.y);
  };
  for (const auto& e : L.boundary) L.outline.push_back({local(e[0]), local(e[1])});
  L.rect = true;
}

}  // namespace

Luminaires::Luminaires(const Scene& s) : s_(s), planeTol_(kPlaneTolerance * sceneScale(s).diagonal) {
  const auto ok = usableFaceMask(s);
  std::vector<uint32_t> em;  // emitter faces, as EmitterSampler takes them
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f] && double(luminance(s.faceEmission(f))) * faceArea(s, f) > 0.0) em.push_back(uint32_t(f));
  faces_ = em.size();
  auto pos = [&](uint32_t v) { return glm::dvec3(s.positions[v]); };
  auto plane = [&](uint32_t f) { return glm::dvec3(faceNormalUnnormalized(s, f)); };
  auto offPlane = [&](uint32_t f, uint32_t v) {  // distance of vertex v from face f's plane
    const glm::dvec3 n = glm::normalize(plane(f));
    return std::fabs(glm::dot(n, pos(v) - pos(s.triangles[f][0])));
  };

  // Union-find over the shared edges: a neighbour across edge (a, b) has (b, a).
  std::unordered_map<uint64_t, uint32_t> edgeOf;
  edgeOf.reserve(3 * em.size());
  for (uint32_t k = 0; k < em.size(); ++k)
    for (int e = 0; e < 3; ++e) edgeOf.emplace(edgeKey(s.triangles[em[k]][e], s.triangles[em[k]][(e + 1) % 3]), k);
  UnionFind uf(em.size());
  for (uint32_t k = 0; k < em.size(); ++k) {
    const uint32_t f = em[k];
    for (int e = 0; e < 3; ++e) {
      const auto it = edgeOf.find(edgeKey(s.triangles[f][(e + 1) % 3], s.triangles[f][e]));
      if (it == edgeOf.end()) continue;
      const uint32_t g = em[it->second];
      if (s.faceEmission(g) != s.faceEmission(f) || glm::dot(plane(f), plane(g)) <= 0.0) continue;
      bool coplanar = true;
      for (int c = 0; c < 3; ++c) coplanar = coplanar && offPlane(f, s.triangles[g][c]) <= planeTol_;
      if (coplanar) uf.unite(k, it->second);
    }
  }
  std::vector<std::vector<uint32_t>> groups;
  std::unordered_map<uint32_t, size_t> groupOf;
  for (uint32_t k = 0; k < em.size(); ++k) {
    const auto [it, fresh] = groupOf.emplace(uf.find(k), groups.size());
    if (fresh) groups.emplace_back();
    groups[it->second].push_back(em[k]);
  }

  auto build = [&](const std::vector<uint32_t>& faces) {
    Luminaire L;
    L.faces = faces;
    L.E = s.faceEmission(faces[0]);
    glm::dvec3 nsum(0.0), c(0.0);
    for (uint32_t f : faces) {
      const double a = faceArea(s, f);
      L.area += a;
      L.cdf.push_back(L.area);
      nsum += plane(f);
      c += a * (pos(s.triangles[f][0]) + pos(s.triangles[f][1]) + pos(s.triangles[f][2])) / 3.0;
    }
    L.normal = glm::normalize(nsum);
    L.origin = c / L.area;
    // Directed edges; an edge met in both directions is interior and cancels.
    std::unordered_map<uint64_t, int> count;
    std::vector<uint64_t> order;
    for (uint32_t f : faces)
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = s.triangles[f][e], b = s.triangles[f][(e + 1) % 3];
        auto rev = count.find(edgeKey(b, a));
        if (rev != count.end() && rev->second > 0) { --rev->second; continue; }
        if (count[edgeKey(a, b)]++ == 0) order.push_back(edgeKey(a, b));
      }
    std::vector<std::array<uint32_t, 2>> edges;
    for (uint64_t key : order)
      for (int m = count[key]; m > 0; --m) edges.push_back({uint32_t(key >> 32), uint32_t(key & 0xffffffffu)});
    mergeCollinear(edges, pos, planeTol_);
    for (const auto& e : edges) {
      L.boundary.push_back({pos(e[0]), pos(e[1])});
      L.corners.push_back(pos(e[0]));
    }
    boundingRectangle(L);
    const size_t step = std::max<size_t>(1, (L.corners.size() + Luminaires::kProbes - 1) / Luminaires::kProbes);
    for (size_t k = 0; k < L.corners.size(); k += step) L.probes.push_back(L.corners[k] + 1e-3 * (L.origin - L.corners[k]));
    return L;
  };
  auto planar = [&](const Luminaire& L) {
    for (const glm::dvec3& p : L.corners)
      if (std::fabs(glm::dot(L.normal, p - L.origin)) > planeTol_) return false;
    return true;
  };
  for (const auto& g : groups) {
    Luminaire L = build(g);
    if (g.size() == 1 || planar(L)) { lum_.push_back(std::move(L)); continue; }
    for (uint32_t f : g) lum_.push_back(build({f}));  // curved: one luminaire per triangle
  }
  firstPortal_ = lum_.size();
}

Luminaires::Luminaires(const Scene& s, const SkyOpenings& openings)
    : s_(s), planeTol_(kPlaneTolerance * sceneScale(s).diagonal) {
  addPortals(openings);
}

void Luminaires::addPortals(const SkyOpenings& op) {
  openings_ = &op;
  for (const SkyPortal& P : op.portals) {
    Luminaire L;
    L.portal = true;
    L.E = op.E;
    L.normal = P.normal;
    L.origin = P.centre;
    const size_t m = P.corners.size();
    for (size_t k = 0; k < m; ++k) {
      L.boundary.push_back({P.corners[k], P.corners[(k + 1) % m]});
      L.corners.push_back(P.corners[k]);
    }
    for (size_t k = 1; k + 1 < m; ++k) {  // the convex outline's fan
      L.tris.push_back({P.corners[0], P.corners[k], P.corners[k + 1]});
      L.area += 0.5 * glm::length(glm::cross(P.corners[k] - P.corners[0], P.corners[k + 1] - P.corners[0]));
      L.cdf.push_back(L.area);
    }
    boundingRectangle(L);
    const size_t step = std::max<size_t>(1, (m + kProbes - 1) / kProbes);
    for (size_t k = 0; k < m; k += step) L.probes.push_back(L.corners[k] + 1e-3 * (L.origin - L.corners[k]));
    lum_.push_back(std::move(L));
  }
}

bool Luminaires::counts(size_t L, const glm::vec3& x, const glm::vec3& w) const {
  if (!lum_[L].portal || portals() < 2) return true;
  return openings_->crossed(x, w) == int(L - firstPortal_);
}

double Luminaires::formFactor(size_t i, const glm::dvec3& x, const glm::dvec3& n) const {
  const Luminaire& L = lum_[i];
  // Behind or in its plane: an emitter emits one-sided, a portal lets the
  // sky in from both.
  const double side = glm::dot(L.normal, x - L.origin);
  if (L.portal ? side == 0.0 : side <= 0.0) return 0.0;
  bool anyFront = false, allFront = true;
  for (const glm::dvec3& p : L.corners) {
    const bool front = glm::dot(n, p - x) >= 0.0;
    anyFront = anyFront || front;
    allFront = allFront && front;
  }
  if (!anyFront) return 0.0;
  double F = 0.0;
  if (allFront) {
    for (const auto& e : L.boundary) F += lambertEdgeTerm(e[0] - x, e[1] - x, n);
    return std::fabs(F) / (2.0 * M_PI);
  }
  for (uint32_t f : L.faces) {  // straddling x's tangent plane: each triangle clipped
    const auto& t = s_.triangles[f];
    F += pointToTriangleFormFactor(x, n, glm::dvec3(s_.positions[t.x]), glm::dvec3(s_.positions[t.y]),
                                   glm::dvec3(s_.positions[t.z]));
  }
  for (const auto& t : L.tris) F += pointToTriangleFormFactor(x, n, t[0], t[1], t[2]);
  return F;
}

FormFactorTarget Luminaires::target(size_t i) const {
  const Luminaire& L = lum_[i];
  FormFactorTarget t;
  t.edges = L.boundary;
  t.normal = L.normal;
  t.origin = L.origin;
  t.area = L.area;
  t.twoSided = L.portal;
  auto narrowest = [&](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    const double half = longest > 0 ? 0.5 * glm::length(glm::cross(b - a, c - a)) / longest : 0.0;
    t.narrowest = t.narrowest > 0 ? std::min(t.narrowest, half) : half;
  };
  for (uint32_t f : L.faces) {
    const auto& tri = s_.triangles[f];
    narrowest(glm::dvec3(s_.positions[tri.x]), glm::dvec3(s_.positions[tri.y]), glm::dvec3(s_.positions[tri.z]));
  }
  for (const auto& tri : L.tris) narrowest(tri[0], tri[1], tri[2]);
  for (const glm::dvec3& p : L.corners) t.centre += p / double(L.corners.size());
  for (const glm::dvec3& p : L.corners) t.radius = std::max(t.radius, glm::length(p - t.centre));
  return t;
}

bool Luminaires::point(size_t i, glm::vec2 u, glm::vec3* y) const {
  const Luminaire& L = lum_[i];
  if (L.rect) {
    // Even-odd crossings of a ray from (u.x, u.y) towards +u: inside or not.
    const glm::dvec2 p(u);
    bool inside = false;
    for (const auto& e : L.outline)
      if ((e[0].y > p.y) != (e[1].y > p.y) && p.x < e[0].x + (p.y - e[0].y) * (e[1].x - e[0].x) / (e[1].y - e[0].y))
        inside = !inside;
    *y = glm::vec3(L.rectCorner + double(u.x) * L.u + double(u.y) * L.v);
    return inside;
  }
  float ux;
  const size_t k = invertCdf(L.cdf, double(u.x), &ux);
  const glm::vec2 b = uniformTriangle({ux, u.y});
  if (L.portal) {
    const auto& t = L.tris[k];
    *y = glm::vec3(double(b.x) * t[0] + double(b.y) * t[1] + double(1.f - b.x - b.y) * t[2]);
    return true;
  }
  const auto& t = s_.triangles[L.faces[k]];
  *y = b.x * s_.positions[t.x] + b.y * s_.positions[t.y] + (1.f - b.x - b.y) * s_.positions[t.z];
  return true;
}

namespace {

// The kernel-weighted visibility V_m = sum k vis / sum k of the rays cast so
// far and its standard error from the sums of k, k vis, k^2 and k^2 vis
// (vis^2 = vis: sum k^2 (vis - V)^2 = (1 - 2V) sum k^2 vis + V^2 sum k^2).
struct VisibilitySums {
  double k = 0, kv = 0, k2 = 0, k2v = 0;
  uint32_t rays = 0;
  double V() const { return k > 0 ? kv / k : 1.0; }
  double stdError() const {
    if (!(k > 0)) return 0.0;
    const double V = kv / k;
    return std::sqrt(std::max(0.0, (1.0 - 2.0 * V) * k2v + V * V * k2)) / k;
  }
  bool split() const { return kv > 0 && kv < k; }
};

// Rays from x to `count` points of luminaire L that next(&y) gives (false:
// no point this draw; at most 4 count draws), into v.
template <class Next>
void castRays(const Luminaires& lums, size_t L, const RayCaster& caster, const glm::vec3& x, const glm::vec3& from,
              const glm::vec3& n, const Next& next, int count, float eps, VisibilitySums& v) {
  constexpr int kBlock = 16;
  Ray rays[kBlock];
  float kern[kBlock];
  uint8_t occ[kBlock];
  const Luminaire& lum = lums.list()[L];
  const glm::vec3 nL(lum.normal);
  // A portal: seen from either side, and its rays must leave the scene.
  const float sgn = !lum.portal || glm::dot(glm::dvec3(x) - lum.origin, lum.normal) > 0.0 ? -1.f : 1.f;
  // Points outside the polygon (drawn in its bounding rectangle) are
  // skipped: at most 4 count draws, a quarter of them inside at least.
  for (int done = 0, draws = 0; done < count && draws < 4 * count;) {
    const int m = std::min(kBlock, count - done);
    int used = 0;
    for (int j = 0; j < m && draws < 4 * count; ++draws) {
      glm::vec3 y;
      if (!next(&y)) continue;
      ++j;
      glm::vec3 w = y - x;
      const float r2 = glm::dot(w, w);
      if (!(r2 > 0.f)) continue;
      const float r = std::sqrt(r2);
      w /= r;
      const float kxy = std::max(0.f, glm::dot(n, w)) * std::max(0.f, sgn * glm::dot(nL, w)) / r2;
      if (!(kxy > 0.f)) continue;  // behind x's tangent plane: outside the clipped polygon
      // The kernel is x's; the ray leaves from x lifted, aimed at y.
      const glm::vec3 wo = y - from;
      const float ro = glm::length(wo);
      rays[used].o = from;
      rays[used].d = ro > 0.f ? wo / ro : w;
      rays[used].tfar = lum.portal ? std::numeric_limits<float>::infinity() : ro * (1.f - 1e-4f) - eps;
      kern[used++] = kxy;
    }
    done += m;
    caster.occludedBatch(rays, size_t(used), occ);
    for (int j = 0; j < used; ++j) {
      const double kj = kern[j],
                   vis = (rays[j].tfar <= 0.f || !occ[j]) && lums.counts(L, rays[j].o, rays[j].d) ? 1.0 : 0.0;
      v.k += kj;
      v.kv += kj * vis;
      v.k2 += kj * kj;
      v.k2v += kj * kj * vis;
    }
    v.rays += uint32_t(used);
  }
}

}  // namespace

LuminaireEstimate luminaireIrradiance(const Luminaires& lums, const RayCaster& caster, const glm::vec3& x,
                                      const glm::vec3& from, const glm::vec3& n, int budget, uint32_t key, float eps,
                                      bool unoccluded, uint32_t skip, LuminaireSums* sums) {
  LuminaireEstimate out;
  const int first = Luminaires::kFirstRays, total = std::max(first, budget);
  double var = 0;
  for (size_t L = 0; L < lums.count(); ++L) {
    if (L == skip) continue;
    const Luminaire& lum = lums.list()[L];
    const glm::vec3& at = lightSeenFrom(x, from, glm::vec3(lum.origin), glm::vec3(lum.normal), eps);
    const double F = lums.formFactor(L, glm::dvec3(at), glm::dvec3(n));
    if (!(F > 0.0)) continue;
    const glm::vec3 E = lums.list()[L].E;
    if (unoccluded) {
      out.H += float(F) * E;
      if (sums) sums->F[L] += F, sums->FV[L] += F;
      continue;
    }
    SobolOwenStream seq(hash3(key, uint32_t(L), 0x1ea5u));
    auto stratified = [&](glm::vec3* y) { return lums.point(L, seq.next(), y); };
    VisibilitySums v;
    castRays(lums, L, caster, at, from, n, stratified, first, eps, v);
    bool penumbra = v.split();
    if (!penumbra && v.k > 0) {  // the corners: a verdict they contradict is a penumbra
      const auto& probes = lums.list()[L].probes;
      size_t c = 0;
      auto corner = [&](glm::vec3* y) { return c < probes.size() ? (*y = glm::vec3(probes[c++]), true) : false; };
      VisibilitySums pv;
      castRays(lums, L, caster, at, from, n, corner, int(probes.size()), eps, pv);
      out.rays += pv.rays;
      penumbra = pv.k > 0 && (pv.split() || (pv.kv > 0) != (v.kv > 0));
    }
    if (penumbra) {  // the same stratified sequence, continued
      out.penumbra = true;
      castRays(lums, L, caster, at, from, n, stratified, total - first, eps, v);
    }
    out.rays += v.rays;
    out.H += float(F * v.V()) * E;
    if (sums) sums->F[L] += F, sums->FV[L] += F * v.V();
    const double se = F * double(luminance(E)) * v.stdError();
    var += se * se;
  }
  out.stdError = std::sqrt(var);
  return out;
}

}  // namespace gi
