#include "gi/ao_strata.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
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
  std::vector<glm::vec2> at;         // where each base ray lies in its stratum ([0,1)^2: row, column)
  std::vector<uint8_t> quarter;      // which quarter each base ray fell in (2 bits: row half, column half)
  std::vector<uint8_t> have;         // 1: the stratum's base ray came from the coarser grid (refine)
  std::vector<glm::vec3> qdirs;      // their quarters' new rays, 3 a stratum
  std::vector<glm::vec2> qat;        // where each quarter's ray lies in its quarter
  int cast = 0;                      // base rays cast on this grid (the rest came from the coarser one)
  std::vector<uint8_t> occ;          // one per ray cast
  std::vector<uint8_t> isSplit;      // 1: the stratum was split
  std::vector<float> mean;           // each stratum's estimate
  Directions direction;
  std::vector<float> rowX;           // the rows' bounds in x, R + 1 of them
  std::vector<double> rowArea;       // a stratum's area in each row
  int rowsOf = 0;

  // A stratum's area in each row, from the rows' bounds.
  void setRowAreas() {
    rowArea.resize(size_t(R));
    for (int i = 0; i < R; ++i) rowArea[size_t(i)] = (double(rowX[size_t(i) + 1]) - rowX[size_t(i)]) / C;
  }

  void reset(StrataGrid g) {
    R = g.rows; C = g.cols; n = R * C;
    // Equal steps in t, x = 1 - (1 - t)^kRowPower: thinner rows towards the
    // horizon (rowsOf -1 after refine: the rows were halved).
    if (rowsOf != R) {
      rowsOf = R;
      rowX.resize(size_t(R) + 1);
      for (int i = 0; i <= R; ++i) rowX[size_t(i)] = float(1.0 - std::pow(1.0 - double(i) / R, kRowPower));
      rowX[size_t(R)] = 1.f;
      setRowAreas();
    }
    dirs.resize(size_t(n));
    open.resize(size_t(n));
    at.resize(size_t(n));
    quarter.resize(size_t(n));
    have.assign(size_t(n), 0);
    occ.resize(std::max(occ.size(), size_t(n)));
    direction.setColumns(C);
  }

  // The next grid of a target's rounds: every stratum cut into its four
  // quarters (its row halved in x, its column in y), each quarter keeping
  // the ray that lies in it (the stratum's own, or one cast for the quarter
  // when the stratum was split), so only the empty quarters need rays.
  // Each ray is uniform in the quarter it lies in and independent of the
  // others, which is all the split rule and the estimate need.
  std::vector<float> rowX2;
  std::vector<glm::vec3> dirs2;
  std::vector<uint8_t> open2, have2;
  std::vector<glm::vec2> at2;
  void refine() {
    const int R2 = 2 * R, C2 = 2 * C, n2 = 4 * n;
    rowX2.resize(size_t(R2) + 1);
    for (int i = 0; i < R; ++i) {
      rowX2[size_t(2 * i)] = rowX[size_t(i)];
      rowX2[size_t(2 * i) + 1] = 0.5f * (rowX[size_t(i)] + rowX[size_t(i) + 1]);
    }
    rowX2[size_t(R2)] = rowX[size_t(R)];
    dirs2.resize(size_t(n2));
    open2.resize(size_t(n2));
    at2.resize(size_t(n2));
    have2.assign(size_t(n2), 0);
    auto keep = [&](int i, int j, int q, glm::vec2 u, const glm::vec3& d, uint8_t o) {
      const size_t f = size_t(2 * i + (q >> 1)) * size_t(C2) + size_t(2 * j + (q & 1));
      dirs2[f] = d; open2[f] = o; at2[f] = u; have2[f] = 1;
    };
    for (int c = 0, k = 0; c < n; ++c) {
      const int i = c / C, j = c % C, own = quarter[size_t(c)];
      const glm::vec2 u = at[size_t(c)];
      keep(i, j, own, {2.f * u.x - float(own >> 1), 2.f * u.y - float(own & 1)}, dirs[size_t(c)], open[size_t(c)]);
      if (!isSplit[size_t(c)]) continue;
      for (int q = 0, m = 0; q < 4; ++q) {
        if (q == own) continue;
        const size_t r = 3 * size_t(k) + size_t(m++);
        keep(i, j, q, qat[r], qdirs[r], occ[r] ? 0 : 1);
      }
      ++k;
    }
    rowX.swap(rowX2);
    dirs.swap(dirs2);
    open.swap(open2);
    at.swap(at2);
    have.swap(have2);
    R = R2; C = C2; n = n2;
    rowsOf = -1;
    setRowAreas();
    quarter.resize(size_t(n));
    for (int c = 0; c < n; ++c)
      if (have[size_t(c)])
        quarter[size_t(c)] = uint8_t((at[size_t(c)].x >= 0.5f ? 2 : 0) | (at[size_t(c)].y >= 0.5f ? 1 : 0));
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

  // One jittered ray in each stratum that has none yet.
  std::vector<uint32_t> castAt;
  std::vector<glm::vec3> castDirs;
  void castBase(const RayCaster& caster, uint32_t key, const glm::vec3& org, const Frame& frame, float tfar) {
    castAt.clear();
    for (int i = 0, c = 0; i < R; ++i) {
      const float x0 = rowX[size_t(i)], width = rowX[size_t(i) + 1] - x0;
      for (int j = 0; j < C; ++j, ++c) {
        if (have[size_t(c)]) continue;
        const glm::vec2 u = jitter(key, uint32_t(c));
        dirs[size_t(c)] = direction(frame, x0 + u.x * width, j, u.y);
        at[size_t(c)] = u;
        quarter[size_t(c)] = uint8_t((u.x >= 0.5f ? 2 : 0) | (u.y >= 0.5f ? 1 : 0));
        castAt.push_back(uint32_t(c));
      }
    }
    cast = int(castAt.size());
    castDirs.resize(castAt.size());
    for (size_t r = 0; r < castAt.size(); ++r) castDirs[r] = dirs[castAt[r]];
    if (!castAt.empty()) caster.occludedFan(org, castDirs.data(), castDirs.size(), tfar, occ.data());
    for (size_t r = 0; r < castAt.size(); ++r) open[castAt[r]] = occ[r] ? 0 : 1;
  }

  // Splits the strata whose opposite neighbours disagree and casts their
  // quarters' rays (occ then holds them, 3 a split stratum).
  void castSplits(const RayCaster& caster, uint32_t key, const glm::vec3& org, const Frame& frame, float tfar) {
    qdirs.clear();
    qat.clear();
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
          qat.push_back(u);
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
    e.rays = cast + int(qdirs.size());
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

// Whether a target's next round (every stratum quartered, gi/ao_strata.h) fits
// in maxRays with every new stratum split: its new base rays (the quarters
// of n strata, less the n rays kept and the quarterRays cast for splits)
// and up to 3 more for each of its 4n strata.
bool nextRoundFits(int64_t rays, int64_t n, int64_t quarterRays, int maxRays) {
  return rays + (3 * n - quarterRays) + 12 * n <= int64_t(maxRays);
}

Strata& threadStrata() {
  thread_local Strata s;
  return s;
}

}  // namespace

StrataEstimate strataOcclusion(const RayCaster& caster, uint32_t key, const glm::vec3& org, const Frame& frame,
                               float tfar, StrataGrid grid) {
  Strata& s = threadStrata();
  s.reset(grid);
  s.castBase(caster, key, org, frame, tfar);
  s.castSplits(caster, key, org, frame, tfar);
  return s.estimate();
}

namespace {

// Rounds of nested grids from strataOcclusion's (key, a grid of about
// minRays strata): at most maxRounds after the first, stopping early where
// the variance is at most stopVariance (> 0) or the next round would not fit
// in budget rays. rounds: the rounds run after the first.
StrataEstimate nestedRounds(const RayCaster& caster, uint32_t key, const glm::vec3& org, const Frame& frame,
                            float tfar, int minRays, int maxRounds, double stopVariance, int budget, int& rounds) {
  Strata& s = threadStrata();
  // Round 0 is strataOcclusion's own grid and jitter; later rounds jitter their new rays afresh.
  StrataEstimate e = strataOcclusion(caster, key, org, frame, tfar, StrataGrid::forRays(minRays));
  int rays = e.rays;
  rounds = 0;
  for (uint32_t k = 1; int(k) <= maxRounds && !(e.variance <= stopVariance) &&
                       nextRoundFits(rays, s.n, int64_t(s.qdirs.size()), budget);
       ++k) {
    const uint32_t roundKey = hash3(key, k, 0x52u);
    s.refine();
    s.castBase(caster, roundKey, org, frame, tfar);
    s.castSplits(caster, roundKey, org, frame, tfar);
    e = s.estimate();
    rays += e.rays;
    rounds = int(k);
  }
  e.rays = rays;
  return e;
}

// The rounds the result's grid takes: the pilot's, and more where its
// standard error is above the target over sqrt(kPilotMargin), each round
// taken to divide it by 4^0.75 (one jittered ray per stratum of a step
// function: variance as n^-1.5, Mitchell 1996, "Consequences of stratified
// sampling in graphics", SIGGRAPH).
int resultRounds(int pilotRounds, double pilotStdError, double target) {
  const double want = target / std::sqrt(kPilotMargin);
  if (!(pilotStdError > want)) return pilotRounds;
  return pilotRounds + int(std::ceil(std::log(pilotStdError / want) / std::log(std::pow(4.0, 0.75))));
}

}  // namespace

StrataEstimate strataOcclusionToTarget(const RayCaster& caster, uint32_t key, const glm::vec3& org,
                                       const Frame& frame, float tfar, const StrataTarget& t) {
  // The pilot: rounds to kPilotLooseness times the target on a key of its
  // own, within a quarter of max_rays (its first round always); left out.
  int pilotRounds = 0, rounds = 0;
  const double loose = kPilotLooseness * t.target;
  const StrataEstimate pilot = nestedRounds(caster, hash3(key, 0x9170u, 0x50u), org, frame, tfar, t.minRays,
                                            std::numeric_limits<int>::max(), loose * loose, t.maxRays / 4,
                                            pilotRounds);
  // The result: the rounds the pilot predicts, on the vertex's own key, none
  // stopped by its own estimate (only a round that would pass what max_rays
  // leaves is not run).
  const int wanted = resultRounds(pilotRounds, std::sqrt(pilot.variance), t.target);
  StrataEstimate e = nestedRounds(caster, key, org, frame, tfar, t.minRays, wanted, -1.0, t.maxRays - pilot.rays, rounds);
  e.rays += pilot.rays;
  e.capped = rounds < wanted;
  return e;
}

StrataGridView lastStrataGrid() {
  const Strata& s = threadStrata();
  if (s.n == 0) return {};
  return {s.R, s.C, std::vector<float>(s.rowX.begin(), s.rowX.begin() + s.R + 1),
          std::vector<glm::vec3>(s.dirs.begin(), s.dirs.begin() + s.n),
          std::vector<uint8_t>(s.have.begin(), s.have.begin() + s.n)};
}

int strataRaysWhenOpen(StrataGrid grid) { return grid.strata() + 3 * grid.cols; }

int strataRaysWhenOpen(const StrataTarget& t) {
  // Every round: the horizon row split (3 rays a column), the variance at
  // estimate()'s floor, 0.25 / n^2; the pilot's rounds, then the result's.
  const StrataGrid g = StrataGrid::forRays(t.minRays);
  auto rounds = [&](int maxRounds, double stopStdError, int budget, int& run, double& stdError) {
    int64_t n = g.strata(), cols = g.cols, rays = n + 3 * cols;
    run = 0;
    while (run < maxRounds && !(0.5 / double(n) <= stopStdError) && nextRoundFits(rays, n, 3 * cols, budget)) {
      rays += (3 * n - 3 * cols) + 3 * (2 * cols);
      n *= 4;
      cols *= 2;
      ++run;
    }
    stdError = 0.5 / double(n);
    return rays;
  };
  int pilotRounds = 0, run = 0;
  double pilotError = 0, error = 0;
  const int64_t pilot = rounds(std::numeric_limits<int>::max(), kPilotLooseness * t.target, t.maxRays / 4,
                               pilotRounds, pilotError);
  return int(pilot + rounds(resultRounds(pilotRounds, pilotError, t.target), -1.0, t.maxRays - int(pilot), run, error));
}

}  // namespace gi
