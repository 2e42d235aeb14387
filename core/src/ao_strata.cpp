#include "ao_strata.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace gi {

StrataGrid StrataGrid::forRays(int n) {
  // At least 2 rows: with one, the zenith row's neighbour across the pole
  // would be the stratum itself for C = 2 (and the split rule must never
  // read a stratum's own sample).
  const int r = std::max(2, int(std::lround(std::sqrt(std::max(1, n) / 2.0))));
  return {r, 2 * r};
}

namespace {

// The rows' bounds: x_i = 1 - (1 - i/R)^kRowPower. Rows of equal width in
// x (power 1) put the horizon's whole band of elevations 0 to
// asin(sqrt(1/R)) in one row, where a smooth surface occludes itself; 1.25
// makes the rows near the horizon thinner (R = 8: the last row 0 to 15.8
// degrees instead of 20.7), and for the same rays the error is 1 to 5%
// lower on the bunny and 5 to 6% on bunny_fine (power 1.4 about the same,
// 1.5, 2 and 0.8 worse; docs/ao_log.md).
constexpr double kRowPower = 1.25;

// Jitter in [0,1)^2 for sample `index` (base strata 0..n-1, quarters
// n + 4c + q), keyed by the vertex.
inline glm::vec2 jitter(uint32_t key, uint32_t index) {
  const uint32_t h = hash32(key + index * 0x9e3779b9u);
  return {toUnitFloat(h), toUnitFloat(hash32(h ^ 0x85ebca6bu))};
}

// Directions of the cells of a grid with C >= 4 columns: the azimuth is a
// column's centre (cos and sin kept per column) plus an offset of at most
// pi/C <= pi/4 (sinCosQuarterPi), added by the angle-sum formulas.
struct Directions {
  std::vector<float> cosCol, sinCol;
  int cols = 0;
  float step = 0.f;  // a column's width in radians
  void setColumns(int c) {
    if (c == cols) return;
    cols = c;
    step = float(6.283185307179586 / c);
    cosCol.resize(size_t(c));
    sinCol.resize(size_t(c));
    for (int j = 0; j < c; ++j) {
      const double a = 6.283185307179586 * (j + 0.5) / c;
      cosCol[size_t(j)] = float(std::cos(a));
      sinCol[size_t(j)] = float(std::sin(a));
    }
  }
  // x in [0,1) (the row's share of sin^2 theta), column j, offset within it f in [0,1).
  glm::vec3 operator()(const Frame& fr, float x, int j, float f) const {
    const float sinT = std::sqrt(std::max(0.f, x)), cosT = std::sqrt(std::max(0.f, 1.f - x));
    float sd, cd;
    sinCosQuarterPi(step * (f - 0.5f), sd, cd);
    const float c = cosCol[size_t(j)] * cd - sinCol[size_t(j)] * sd;
    const float s = sinCol[size_t(j)] * cd + cosCol[size_t(j)] * sd;
    return fr.t * (sinT * c) + fr.b * (sinT * s) + fr.n * cosT;
  }
};

// One vertex's strata, in per-thread buffers grown to the largest grid seen.
struct Strata {
  int R = 0, C = 0, n = 0;
  std::vector<glm::vec3> dirs;       // the base rays' directions
  std::vector<uint8_t> open;         // the base rays: 1 = open
  std::vector<uint8_t> quarter;      // which quarter each base ray fell in (2 bits: row half, column half)
  std::vector<glm::vec3> qdirs;      // their quarters' new rays, 3 a stratum
  std::vector<uint8_t> occ;          // one per ray cast
  std::vector<uint8_t> isSplit;      // 1: the stratum was split
  std::vector<float> mean;           // each stratum's estimate
  Directions direction;
  std::vector<float> rowX;           // the rows' bounds in x, R + 1 of them
  std::vector<double> rowArea;       // a stratum's area in each row
  int rowsOf = 0;

  void reset(StrataGrid g) {
    R = g.rows; C = g.cols; n = R * C;
    if (rowsOf != R) {  // equal steps in t, x = 1 - (1 - t)^kRowPower: thinner rows towards the horizon
      rowsOf = R;
      rowX.resize(size_t(R) + 1);
      rowArea.resize(size_t(R));
      for (int i = 0; i <= R; ++i) rowX[size_t(i)] = float(1.0 - std::pow(1.0 - double(i) / R, kRowPower));
      rowX[size_t(R)] = 1.f;
      for (int i = 0; i < R; ++i) rowArea[size_t(i)] = (double(rowX[size_t(i) + 1]) - rowX[size_t(i)]) / C;
    }
    dirs.resize(size_t(n));
    open.resize(size_t(n));
    quarter.resize(size_t(n));
    occ.resize(std::max(occ.size(), size_t(n)));
    direction.setColumns(C);
  }

  // The base rays padded for the split rule (C + 2 columns, wrapping; R + 2
  // rows): above the zenith row that row half a turn away (the cells meet at
  // the pole), below the horizon row the tangent plane (occluded).
  std::vector<uint8_t> padded;
  void pad() {
    const int W = C + 2;
    padded.resize(size_t(R + 2) * size_t(W));
    auto row = [&](int r, auto value) {
      uint8_t* p = &padded[size_t(r) * size_t(W)];
      for (int j = 0; j < C; ++j) p[j + 1] = value(j);
      p[0] = p[C];
      p[C + 1] = p[1];
    };
    row(0, [&](int j) { return open[size_t((j + C / 2) % C)]; });
    for (int i = 0; i < R; ++i) row(i + 1, [&](int j) { return open[size_t(i * C + j)]; });
    row(R + 1, [](int) { return uint8_t(0); });
  }

  void castBase(const RayCaster& caster, uint32_t key, const glm::vec3& org, const Frame& frame, float tfar) {
    for (int i = 0, c = 0; i < R; ++i) {
      const float x0 = rowX[size_t(i)], width = rowX[size_t(i) + 1] - x0;
      for (int j = 0; j < C; ++j, ++c) {
        const glm::vec2 u = jitter(key, uint32_t(c));
        dirs[size_t(c)] = direction(frame, x0 + u.x * width, j, u.y);
        quarter[size_t(c)] = uint8_t((u.x >= 0.5f ? 2 : 0) | (u.y >= 0.5f ? 1 : 0));
      }
    }
    caster.occludedFan(org, dirs.data(), size_t(n), tfar, occ.data());
    for (int c = 0; c < n; ++c) open[size_t(c)] = occ[size_t(c)] ? 0 : 1;
  }

  // Splits the strata whose opposite neighbours disagree and casts their
  // quarters' rays (occ then holds them, 3 a split stratum).
  void castSplits(const RayCaster& caster, uint32_t key, const glm::vec3& org, const Frame& frame, float tfar) {
    qdirs.clear();
    isSplit.assign(size_t(n), 0);
    pad();
    const size_t W = size_t(C) + 2;
    for (int i = 0; i < R; ++i) {
      const float x0 = rowX[size_t(i)], width = rowX[size_t(i) + 1] - x0;
      const uint8_t* up = &padded[size_t(i) * W + 1];  // row i - 1, column j at up[j]
      const uint8_t* mid = up + W;
      const uint8_t* down = mid + W;
      for (int j = 0; j < C; ++j) {
        // Never (i, j) itself (mid[j]): the decision must not read the stratum's own ray.
        const bool split = up[j] != down[j] || mid[j - 1] != mid[j + 1] || up[j - 1] != down[j + 1] ||
                           up[j + 1] != down[j - 1];
        if (!split) continue;
        const uint32_t c = uint32_t(i * C + j);
        isSplit[c] = 1;
        for (int q = 0; q < 4; ++q) {
          if (q == quarter[c]) continue;
          const glm::vec2 u = jitter(key, uint32_t(n) + c * 4u + uint32_t(q));
          qdirs.push_back(direction(frame, x0 + 0.5f * (float(q >> 1) + u.x) * width, j, 0.5f * (float(q & 1) + u.y)));
        }
      }
    }
    occ.resize(std::max(occ.size(), qdirs.size()));
    if (!qdirs.empty()) caster.occludedFan(org, qdirs.data(), qdirs.size(), tfar, occ.data());
  }

  // The estimate, its collapsed-pair variance and the bent normal's sum.
  StrataEstimate estimate() {
    StrataEstimate e;
    e.rays = n + int(qdirs.size());
    double openArea = 0.0, closedArea = 0.0, var = 0.0;
    mean.resize(size_t(n));
    for (int c = 0, k = 0; c < n; ++c) {
      const double A = rowArea[size_t(c / C)];
      const float a = float(A), a4 = 0.25f * a;
      const float own = float(open[size_t(c)]);
      if (!isSplit[size_t(c)]) {
        mean[size_t(c)] = own;
        if (own > 0.f) e.bent += dirs[size_t(c)] * a;
      } else {
        float v[4];
        for (int q = 0, m = 0; q < 4; ++q) {
          if (q == quarter[size_t(c)]) {
            v[q] = own;
            if (own > 0.f) e.bent += dirs[size_t(c)] * a4;
          } else {
            const size_t r = 3 * size_t(k) + size_t(m++);
            v[q] = occ[r] ? 0.f : 1.f;
            if (v[q] > 0.f) e.bent += qdirs[r] * a4;
          }
        }
        mean[size_t(c)] = 0.25f * (v[0] + v[1] + v[2] + v[3]);
        // quarters paired along their row
        var += double(a4) * a4 * (double(v[0] - v[1]) * (v[0] - v[1]) + double(v[2] - v[3]) * (v[2] - v[3]));
        ++k;
      }
      openArea += A * mean[size_t(c)];
      closedArea += A * (1.0 - mean[size_t(c)]);
    }
    // Unsplit strata paired in columns 2m and 2m + 1 of a row (C is even;
    // both of one area); one whose partner was split is paired with the
    // partner's mean.
    for (int c = 0; c < n; ++c) {
      const int partner = c ^ 1;
      if (isSplit[size_t(c)] || (!isSplit[size_t(partner)] && (c & 1))) continue;  // a pair counts once
      const double A = rowArea[size_t(c / C)];
      const double d = double(mean[size_t(c)]) - double(mean[size_t(partner)]);
      var += A * A * d * d;
    }
    // The open area, or 1 minus the closed one: exactly 1 when every ray
    // is open and exactly 0 when every ray is blocked (the areas' float
    // bounds need not add up to 1 exactly).
    e.value = openArea <= 0.5 ? openArea : 1.0 - closedArea;
    // At least one stratum's worth (A^2 / 4 with A = 1/n, a stratum of mean
    // area half occluded): where every pair agreed, an occluder no ray met
    // may still be there (on bunny_fine the nearly open vertices, AO 0.995
    // to 0.9999, had mean squared errors 4.2 times the pairs' bound without
    // it, 0.15 with it).
    const double A = 1.0 / double(n);
    e.variance = std::max(var, 0.25 * A * A);
    return e;
  }
};

}  // namespace

namespace {

// The rounds to a target (ao_strata.h): estimateRound(grid, k) gives round
// k's estimate; the weighted mix of the rounds so far.
template <class EstimateRound>
StrataEstimate rounds(const StrataTarget& t, EstimateRound&& estimateRound) {
  StrataGrid g = StrataGrid::forRays(t.minRays);
  double W = 0.0, openSum = 0.0, closedSum = 0.0, varSum = 0.0;
  StrataEstimate mix;
  for (uint32_t k = 0;; ++k) {
    const StrataEstimate e = estimateRound(g, k);
    const double w = double(g.strata()) * double(g.strata());
    W += w;
    openSum += w * e.value;
    closedSum += w * (1.0 - e.value);
    varSum += w * w * e.variance;
    mix.bent += float(w) * e.bent;
    mix.rays += e.rays;
    if (varSum <= t.target * t.target * W * W) break;
    const StrataGrid next = StrataGrid::forRays(2 * g.strata());
    if (int64_t(mix.rays) + 4 * int64_t(next.strata()) > int64_t(t.maxRays)) break;
    g = next;
  }
  // As in one round: exactly 1 or 0 when every round gave it.
  const double open = openSum / W;
  mix.value = open <= 0.5 ? open : 1.0 - closedSum / W;
  mix.variance = varSum / (W * W);
  return mix;
}

}  // namespace

StrataEstimate strataOcclusion(const RayCaster& caster, uint32_t key, const glm::vec3& org, const Frame& frame,
                               float tfar, StrataGrid grid) {
  thread_local Strata s;
  s.reset(grid);
  s.castBase(caster, key, org, frame, tfar);
  s.castSplits(caster, key, org, frame, tfar);
  return s.estimate();
}

StrataEstimate strataOcclusionToTarget(const RayCaster& caster, uint32_t key, const glm::vec3& org,
                                       const Frame& frame, float tfar, const StrataTarget& t) {
  return rounds(t, [&](StrataGrid g, uint32_t k) {
    // Round 0 is strataOcclusion's own jitter; later rounds jitter afresh.
    return strataOcclusion(caster, k == 0 ? key : hash3(key, k, 0x52u), org, frame, tfar, g);
  });
}

int strataRaysWhenOpen(StrataGrid grid) { return grid.strata() + 3 * grid.cols; }

int strataRaysWhenOpen(const StrataTarget& t) {
  return rounds(t, [](StrataGrid g, uint32_t) {
           StrataEstimate e;
           e.value = 1.0;
           e.variance = 0.25 / (double(g.strata()) * g.strata());  // the floor of estimate()
           e.rays = strataRaysWhenOpen(g);
           return e;
         }).rays;
}

}  // namespace gi
