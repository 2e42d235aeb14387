// The hemicube (Cohen and Greenberg 1985), on the CPU: at the centre of patch
// i (or at the centroids of parts of it, F_ij then their area-weighted mean),
// every other patch is projected onto the five faces of a unit hemicube
// and scan-converted with a depth buffer; each cell's delta form factor goes
// to the patch it shows,
//   top face (z = 1):   dF = dA / (pi (x^2 + y^2 + 1)^2)
//   side faces (x = 1): dF = z dA / (pi (y^2 + z^2 + 1)^2),
// which sum to 1 over the hemicube (up to the cells' quadrature, normalised
// away). A cell that shows a patch's back, or nothing, is light lost.
#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "gi/form_factors.h"
#include "gi/sampling.h"

namespace gi {
namespace {

struct V2 {
  float x, y, invD;  // projected position and 1 / depth
};

class HemicubeFace {
 public:
  HemicubeFace(int res, bool top) : w_(res), h_(top ? res : res / 2), top_(top) {
    depth_.assign(size_t(w_) * h_, 0.f);
    id_.assign(size_t(w_) * h_, kNoHit);
    back_.assign(size_t(w_) * h_, 0);
  }
  // Projected coordinates: x in [-1, 1] across, y in [-1, 1] (top) or [0, 1] (side).
  void drawTriangle(const V2& a, const V2& b, const V2& c, uint32_t id, bool back) {
    const float cell = 2.f / float(w_);
    const float y0 = top_ ? -1.f : 0.f;
    auto col = [&](float x) { return (x + 1.f) / cell - 0.5f; };
    auto row = [&](float y) { return (y - y0) / cell - 0.5f; };
    const float ax = col(a.x), ay = row(a.y), bx = col(b.x), by = row(b.y), cx = col(c.x), cy = row(c.y);
    const float area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
    if (area == 0.f) return;
    const int i0 = std::max(0, int(std::ceil(std::min({ax, bx, cx})))), i1 = std::min(w_ - 1, int(std::floor(std::max({ax, bx, cx}))));
    const int j0 = std::max(0, int(std::ceil(std::min({ay, by, cy})))), j1 = std::min(h_ - 1, int(std::floor(std::max({ay, by, cy}))));
    const float s = area > 0 ? 1.f : -1.f;
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const float px = float(i), py = float(j);
        // Edge functions, oriented so that inside is >= 0; a top-left style
        // tie rule keeps shared edges from being drawn twice or not at all.
        const float w0 = s * edge(bx, by, cx, cy, px, py);
        const float w1 = s * edge(cx, cy, ax, ay, px, py);
        const float w2 = s * edge(ax, ay, bx, by, px, py);
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        if ((w0 == 0 && !topLeft(cx - bx, cy - by, s)) || (w1 == 0 && !topLeft(ax - cx, ay - cy, s)) ||
            (w2 == 0 && !topLeft(bx - ax, by - ay, s)))
          continue;
        const float sum = w0 + w1 + w2;
        const float invD = (w0 * a.invD + w1 * b.invD + w2 * c.invD) / sum;
        const size_t k = size_t(j) * size_t(w_) + size_t(i);
        if (invD > depth_[k]) { depth_[k] = invD; id_[k] = id; back_[k] = back; }
      }
  }
  // Adds each cell's delta form factor to its patch; returns their sum
  // (1 - O(1/res^2)), by which the caller normalises so closed rooms close.
  // With `keep`, the cells (patch, back side, dF) are copied there for display.
  double accumulate(std::vector<double>& F, double& lost, HemicubeCells::Face* keep) const {
    double total = 0;
    if (keep) *keep = HemicubeCells::Face{w_, h_, id_, back_, std::vector<double>(size_t(w_) * h_)};
    for (int j = 0; j < h_; ++j)
      for (int i = 0; i < w_; ++i) {
        const double dF = hemicubeDeltaFormFactor(w_, top_, i, j);
        const size_t k = size_t(j) * size_t(w_) + size_t(i);
        if (keep) keep->dF[k] = dF;
        total += dF;
        if (id_[k] == kNoHit || back_[k]) lost += dF;
        else F[id_[k]] += dF;
      }
    return total;
  }

 private:
  // The edge function of (a -> b) at p, evaluated from the lexicographically
  // smaller end, so that the triangle on the other side of a shared edge
  // (which walks it b -> a) gets exactly the negated value: a cell centre on
  // or next to the edge then falls in exactly one of the two, never in a
  // crack between them (each order of the float operations alone rounds its
  // own way, and left one cell in 6,000 of a closed box's hemicube unseen).
  static float edge(float ax, float ay, float bx, float by, float px, float py) {
    if (ax < bx || (ax == bx && ay < by)) return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
    return -((ax - bx) * (py - by) - (ay - by) * (px - bx));
  }
  static bool topLeft(float ex, float ey, float s) {
    ex *= s;
    ey *= s;
    return ey < 0 || (ey == 0 && ex > 0);
  }
  int w_, h_;
  bool top_;
  std::vector<float> depth_;
  std::vector<uint32_t> id_;
  std::vector<uint8_t> back_;
};

}  // namespace

double hemicubeDeltaFormFactor(int resolution, bool top, int i, int j) {
  const float cell = 2.f / float(resolution);
  const double x = -1.0 + (i + 0.5) * cell, y = (top ? -1.0 : 0.0) + (j + 0.5) * cell;
  const double r = x * x + y * y + 1.0;
  return (top ? 1.0 : y) * cell * cell / (M_PI * r * r);
}

double hemicubeBufferBytes(int resolution) {
  const double res = std::max(4, resolution & ~1);
  return res * res * double(sizeof(float) + sizeof(uint32_t) + sizeof(uint8_t));
}

std::optional<std::string> hemicubeCostWarning(size_t patches, int resolution) {
  const double res = std::max(4, resolution & ~1), cells = 3.0 * res * res;
  const double work = double(patches) * 2.0 * cells;  // drawn, then summed
  if (work < 1e11) return std::nullopt;
  char b[300];
  std::snprintf(b, sizeof b,
                "hemicube resolution %d on %zu patches: about %.2g cell updates (3 x %d^2 cells drawn and summed per "
                "patch), minutes or more of computing; a lower resolution costs res^2 times less",
                int(res), patches, work, int(res));
  return std::string(b);
}

// One hemicube at point c (lifted off patch i) with its side axes turned by
// phi about the normal: the delta form factors of the cells, normalised,
// per patch shown (dense, indexed by face) and the fraction lost.
double FormFactors::hemicubeAt(uint32_t i, const glm::vec3& c, float phi, std::vector<double>& F,
                               HemicubeCells* keep) const {
  const int res = std::max(4, set_.hemicubeResolution & ~1);
  const Frame f0(normal_[i]);
  const float cp = std::cos(phi), sp = std::sin(phi);
  const glm::vec3 tt = f0.t * cp + f0.b * sp, bb = f0.b * cp - f0.t * sp, nn = f0.n;
  // Five views: forward axis, right axis, up axis (kHemicubeViews, in the local frame of patch i).
  glm::vec3 views[5][3];
  for (int v = 0; v < 5; ++v)
    for (int a = 0; a < 3; ++a) {
      const glm::vec3& l = kHemicubeViews[v][a];
      views[v][a] = tt * l.x + bb * l.y + nn * l.z;
    }
  if (keep) {
    keep->resolution = res;
    keep->eye = c;
    keep->t = tt;
    keep->b = bb;
    keep->n = nn;
  }
  const float nearD = eps_;
  double lost = 0, total = 0;
  F.assign(s_.faceCount(), 0.0);
  for (int v = 0; v < 5; ++v) {
    HemicubeFace face(res, v == 0);
    const glm::vec3 fwd = views[v][0], right = views[v][1], up = views[v][2];
    for (uint32_t j = 0; j < uint32_t(s_.faceCount()); ++j) {
      if (j == i || !ok_[j]) continue;
      const auto& t = s_.triangles[j];
      glm::vec3 p[3];
      for (int k = 0; k < 3; ++k) {
        const glm::vec3 d = s_.positions[t[k]] - c;
        p[k] = {glm::dot(d, right), glm::dot(d, up), glm::dot(d, fwd)};
      }
      // Clip to depth > near (one plane), then project and fan-triangulate.
      // The crossing point is computed from the edge's inside end towards
      // its outside end, whichever triangle the edge belongs to: the two
      // triangles sharing it then get the same float point, and no cells
      // fall through a crack between them.
      glm::vec3 poly[4];
      int m = 0;
      for (int k = 0; k < 3; ++k) {
        const glm::vec3& a = p[k];
        const glm::vec3& b = p[(k + 1) % 3];
        if (a.z > nearD) poly[m++] = a;
        if ((a.z > nearD) != (b.z > nearD)) {
          const glm::vec3& in = a.z > nearD ? a : b;
          const glm::vec3& out = a.z > nearD ? b : a;
          poly[m++] = in + (out - in) * ((nearD - in.z) / (out.z - in.z));
        }
      }
      if (m < 3) continue;
      const bool back = glm::dot(normal_[j], s_.positions[t.x] - c) >= 0.f;  // c is behind patch j
      // A two-sided surface's face and its reversed copy lie in one plane:
      // only the one facing c is drawn (the other, at the same depth, would
      // win some cells as a back: light lost).
      if (back && caster_.reversedCopy(j) != kNoHit) continue;
      V2 q[4];
      for (int k = 0; k < m; ++k) q[k] = {poly[k].x / poly[k].z, poly[k].y / poly[k].z, 1.f / poly[k].z};
      for (int k = 1; k + 1 < m; ++k) face.drawTriangle(q[0], q[k], q[k + 1], j, back);
    }
    total += face.accumulate(F, lost, keep ? &keep->faces[size_t(v)] : nullptr);
  }
  for (double& x : F) x /= total;
  // At most 1: lost and total sum the same cells in another order (a face
  // that sees nothing read 1.0000000000000155).
  const double lostFraction = std::min(1.0, lost / total);
  if (keep) {
    keep->total = total;
    keep->F = F;
    keep->lost = lostFraction;
  }
  return lostFraction;
}

HemicubeCells FormFactors::hemicubeCells(uint32_t i) const {
  if (i >= s_.faceCount() || !ok_[i]) throw std::invalid_argument("face " + std::to_string(i) + " is degenerate");
  // The single central view of hemicubeRow (hemicube_points = 1): same
  // point, same axes (no turn), so the per-patch sums are that row.
  const auto& t = s_.triangles[i];
  const glm::vec3 c = (s_.positions[t.x] + s_.positions[t.y] + s_.positions[t.z]) / 3.f + normal_[i] * eps_;
  HemicubeCells cells;
  std::vector<double> F;
  hemicubeAt(i, c, 0.f, F, &cells);
  return cells;
}

FormFactorRow FormFactors::hemicubeRow(uint32_t i) const {
  const auto& ti = s_.triangles[i];
  const glm::vec3 lift = normal_[i] * eps_;
  const int budget = std::max(1, set_.hemicubePoints);
  // A part of patch i with the hemicube seen from its centroid (sparse row,
  // the lost fraction as the last entry, j = kNoHit).
  struct Part {
    glm::vec3 a, b, c;
    double w;  // share of patch i's area
    std::vector<uint32_t> j;
    std::vector<double> F;
    double need;  // expected error of its one-view estimate, area-weighted (L1 over the row)
  };
  std::vector<double> F;
  uint32_t views = 0;
  auto render = [&](const glm::vec3& pa, const glm::vec3& pb, const glm::vec3& pc, double w) {
    Part p{pa, pb, pc, w, {}, {}, 0.0};
    // With several views each one's side axes are turned by a hashed angle,
    // so that the cells' aliasing of a small or distant patch differs from
    // view to view and averages out; a single view is the classic one.
    const float phi = budget > 1 ? 6.2831853f * toUnitFloat(hash3(i, views, set_.seed ^ 0x4c1bu)) : 0.f;
    ++views;
    const double lost = hemicubeAt(i, (pa + pb + pc) / 3.f + lift, phi, F);
    for (uint32_t j = 0; j < uint32_t(F.size()); ++j)
      if (F[j] > 0) { p.j.push_back(j); p.F.push_back(F[j]); }
    p.j.push_back(kNoHit);
    p.F.push_back(lost);
    return p;
  };
  std::vector<Part> parts{render(s_.positions[ti.x], s_.positions[ti.y], s_.positions[ti.z], 1.0)};
  parts[0].need = std::numeric_limits<double>::infinity();
  // More views: bisect the part with the largest expected error across its
  // longest edge (the halves stay well shaped, even for a sliver) and view
  // from both halves' centroids, while the budget allows (2 views a split).
  // The halves' centroids average to the parent's, so the linear part of
  // the row's variation cancels in e = w |F_parent - (F_1 + F_2) / 2|: e is
  // the one-view (midpoint) rule's error there, and each half is expected
  // to carry a quarter of it (half the area, half the squared size). Parts
  // next to a common edge or close to another patch, where the view
  // changes fastest, are split most.
  auto dist = [](const Part& x, const Part& y) {
    double d = 0;
    size_t p = 0, q = 0;
    while (p < x.j.size() || q < y.j.size()) {
      if (q == y.j.size() || (p < x.j.size() && x.j[p] < y.j[q])) d += x.F[p++];
      else if (p == x.j.size() || y.j[q] < x.j[p]) d += y.F[q++];
      else { d += std::fabs(x.F[p] - y.F[q]); ++p; ++q; }
    }
    return d;
  };
  while (int(views) + 2 <= budget) {
    size_t worst = 0;
    for (size_t k = 1; k < parts.size(); ++k)
      if (parts[k].need > parts[worst].need) worst = k;
    Part parent = std::move(parts[worst]);
    parts.erase(parts.begin() + std::ptrdiff_t(worst));
    // Rotate the corners so that (a, b) is the longest edge, then split it at its midpoint.
    const float lab = glm::length(parent.b - parent.a), lbc = glm::length(parent.c - parent.b),
                lca = glm::length(parent.a - parent.c);
    if (lbc >= lab && lbc >= lca) parent = Part{parent.b, parent.c, parent.a, parent.w, std::move(parent.j), std::move(parent.F), 0};
    else if (lca >= lab && lca >= lbc) parent = Part{parent.c, parent.a, parent.b, parent.w, std::move(parent.j), std::move(parent.F), 0};
    const glm::vec3 m = 0.5f * (parent.a + parent.b);
    Part h1 = render(parent.c, parent.a, m, 0.5 * parent.w), h2 = render(parent.c, m, parent.b, 0.5 * parent.w);
    // Mean of the halves' rows against the parent's: 0.5 (F1 + F2) - F_parent.
    Part mean{{}, {}, {}, 0, {}, {}, 0};
    {
      size_t p = 0, q = 0;
      while (p < h1.j.size() || q < h2.j.size()) {
        if (q == h2.j.size() || (p < h1.j.size() && h1.j[p] < h2.j[q])) { mean.j.push_back(h1.j[p]); mean.F.push_back(0.5 * h1.F[p++]); }
        else if (p == h1.j.size() || h2.j[q] < h1.j[p]) { mean.j.push_back(h2.j[q]); mean.F.push_back(0.5 * h2.F[q++]); }
        else { mean.j.push_back(h1.j[p]); mean.F.push_back(0.5 * (h1.F[p] + h2.F[q])); ++p; ++q; }
      }
    }
    const double e = parent.w * dist(mean, parent);
    h1.need = h2.need = 0.25 * e;
    parts.push_back(std::move(h1));
    parts.push_back(std::move(h2));
  }
  std::vector<double> sum(s_.faceCount() + 1, 0.0);
  for (const Part& p : parts)
    for (size_t k = 0; k < p.j.size(); ++k) sum[p.j[k] == kNoHit ? s_.faceCount() : p.j[k]] += p.w * p.F[k];
  FormFactorRow r;
  for (uint32_t j = 0; j < uint32_t(s_.faceCount()); ++j)
    if (sum[j] > 0) { r.j.push_back(j); r.F.push_back(float(sum[j])); }
  r.escaped = float(sum[s_.faceCount()]);
  return r;
}

}  // namespace gi
