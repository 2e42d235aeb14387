// The hemicube (Cohen and Greenberg 1985), on the CPU: at the centre of patch
// i, every other patch is projected onto the five faces of a unit hemicube
// and scan-converted with a depth buffer; each cell's delta form factor goes
// to the patch it shows,
//   top face (z = 1):   dF = dA / (pi (x^2 + y^2 + 1)^2)
//   side faces (x = 1): dF = z dA / (pi (y^2 + z^2 + 1)^2),
// which sum to 1 over the hemicube (up to the cells' quadrature, normalised
// away). A cell that shows a patch's back, or nothing, is light lost.
#include <algorithm>
#include <cmath>
#include <cstdio>
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
        const float w0 = s * ((cx - bx) * (py - by) - (cy - by) * (px - bx));
        const float w1 = s * ((ax - cx) * (py - cy) - (ay - cy) * (px - cx));
        const float w2 = s * ((bx - ax) * (py - ay) - (by - ay) * (px - ax));
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
  double accumulate(std::vector<double>& F, double& lost) const {
    double total = 0;
    const float cell = 2.f / float(w_);
    for (int j = 0; j < h_; ++j)
      for (int i = 0; i < w_; ++i) {
        const double x = -1.0 + (i + 0.5) * cell, y = (top_ ? -1.0 : 0.0) + (j + 0.5) * cell;
        const double r = x * x + y * y + 1.0;
        const double dF = (top_ ? 1.0 : y) * cell * cell / (M_PI * r * r);
        const size_t k = size_t(j) * size_t(w_) + size_t(i);
        total += dF;
        if (id_[k] == kNoHit || back_[k]) lost += dF;
        else F[id_[k]] += dF;
      }
    return total;
  }

 private:
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

FormFactorRow FormFactors::hemicubeRow(uint32_t i) const {
  const int res = std::max(4, set_.hemicubeResolution & ~1);
  const auto& ti = s_.triangles[i];
  const glm::vec3 c = (s_.positions[ti.x] + s_.positions[ti.y] + s_.positions[ti.z]) / 3.f + normal_[i] * eps_;
  const Frame fr(normal_[i]);
  // Five views: forward axis, right axis, up axis (local frame of patch i).
  const glm::vec3 views[5][3] = {{fr.n, fr.t, fr.b},  {fr.t, fr.b, fr.n},  {-fr.t, -fr.b, fr.n},
                                 {fr.b, -fr.t, fr.n}, {-fr.b, fr.t, fr.n}};
  const float nearD = eps_;
  double lost = 0, total = 0;
  std::vector<double> F(s_.faceCount(), 0.0);
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
      glm::vec3 poly[4];
      int m = 0;
      for (int k = 0; k < 3; ++k) {
        const glm::vec3& a = p[k];
        const glm::vec3& b = p[(k + 1) % 3];
        if (a.z > nearD) poly[m++] = a;
        if ((a.z > nearD) != (b.z > nearD)) poly[m++] = a + (b - a) * ((nearD - a.z) / (b.z - a.z));
      }
      if (m < 3) continue;
      const bool back = glm::dot(normal_[j], s_.positions[t.x] - c) >= 0.f;  // c is behind patch j
      V2 q[4];
      for (int k = 0; k < m; ++k) q[k] = {poly[k].x / poly[k].z, poly[k].y / poly[k].z, 1.f / poly[k].z};
      for (int k = 1; k + 1 < m; ++k) face.drawTriangle(q[0], q[k], q[k + 1], j, back);
    }
    total += face.accumulate(F, lost);
  }
  FormFactorRow r;
  for (uint32_t j = 0; j < uint32_t(F.size()); ++j)
    if (F[j] > 0) { r.j.push_back(j); r.F.push_back(float(F[j] / total)); }
  r.escaped = float(lost / total);
  return r;
}

}  // namespace gi
