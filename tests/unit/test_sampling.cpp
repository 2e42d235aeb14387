// gi/sampling.h: the warps are checked with chi-square goodness-of-fit tests,
// the Owen-scrambled Sobol points for their (0,m,2)-net stratification,
// determinism and convergence rate, and Frame for orthonormality.
//
// Chi-square tests: the statistic X^2 = sum (O - E)^2 / E is computed here
// over equal-probability bins, and compared with the critical value of the
// chi-square distribution with dof = bins - 1 at significance p = 1e-4, from
// the Wilson-Hilferty approximation
//   chi2_{1-p}(k) ~ k (1 - 2/(9k) + z_{1-p} sqrt(2/(9k)))^3,  z_{1-p} = 3.7190165
// (the standard normal quantile of 1 - 1e-4). For k >= 15 the approximation is
// within 1% of the exact quantile (k = 255: 347.72 vs exact 347.65). All inputs
// come from fixed seeds, so the tests are deterministic; the p-value only says
// how unlikely a correct warp would be to fail with a fresh seed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "gi/sampling.h"

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kZ1e4 = 3.7190164854556804;  // Phi^-1(1 - 1e-4)

double chi2Critical(int dof) {
  const double k = dof, h = 2.0 / (9.0 * k);
  const double c = 1.0 - h + kZ1e4 * std::sqrt(h);
  return k * c * c * c;
}

// X^2 for counts that should be equally likely.
double chi2Uniform(const std::vector<long>& counts) {
  long n = 0;
  for (long c : counts) n += c;
  const double e = double(n) / double(counts.size());
  double x2 = 0.0;
  for (long c : counts) x2 += (double(c) - e) * (double(c) - e) / e;
  return x2;
}

// Sources of points in [0,1)^2: a plain counter-based Rng, or Owen-scrambled
// Sobol points in blocks of 1024 per key (as the algorithms use them: one key
// per element).
enum class Source { Rng, Sobol };
std::vector<glm::vec2> makeInputs(Source src, size_t n, uint32_t seed) {
  std::vector<glm::vec2> u(n);
  if (src == Source::Rng) {
    gi::Rng rng(seed);
    for (auto& x : u) { x.x = rng.next(); x.y = rng.next(); }
  } else {
    for (size_t i = 0; i < n; ++i)
      u[i] = gi::sobolOwen2D(uint32_t(i % 1024), gi::hash3(seed, uint32_t(i / 1024), 7u));
  }
  return u;
}

double phi01(const glm::vec3& d) {  // azimuth mapped to [0,1)
  double p = (std::atan2(double(d.y), double(d.x)) + kPi) / (2.0 * kPi);
  return p >= 1.0 ? 0.0 : p;
}
int binOf(double x, int n) { return std::clamp(int(std::floor(x * n)), 0, n - 1); }

// Joint histogram of (a, b) in [0,1)^2 over na x nb equal cells.
struct Hist2 {
  int na, nb;
  std::vector<long> c;
  Hist2(int a, int b) : na(a), nb(b), c(size_t(a) * size_t(b), 0) {}
  void add(double a, double b) { ++c[size_t(binOf(a, na)) * size_t(nb) + size_t(binOf(b, nb))]; }
  double x2() const { return chi2Uniform(c); }
  // The statistic, also recorded in the XML report (--gtest_output=xml).
  double recorded(const std::string& key) const {
    const double v = x2();
    ::testing::Test::RecordProperty(key, std::to_string(v));
    return v;
  }
  int dof() const { return na * nb - 1; }
};

// 16 x 16 bins, 200,000 samples: 781 expected per bin, dof 255, critical X^2 = 347.7.
constexpr size_t kN = 200000;
constexpr int kBins = 16;

// Histogram of the warped directions over (F(z), phi), F being the CDF of z
// under the claimed distribution, which makes every cell equally likely.
Hist2 dirHist(const std::vector<glm::vec3>& d, const std::function<double(double)>& cdfZ) {
  Hist2 h(kBins, kBins);
  for (const auto& v : d) h.add(cdfZ(v.z), phi01(v));
  return h;
}

template <class Warp>
std::vector<glm::vec3> warpAll(Source src, uint32_t seed, Warp w) {
  auto u = makeInputs(src, kN, seed);
  std::vector<glm::vec3> d(u.size());
  for (size_t i = 0; i < u.size(); ++i) d[i] = w(u[i]);
  return d;
}

void expectUnitAndAbove(const std::vector<glm::vec3>& d, float zMin) {
  int bad = 0;
  for (const auto& v : d)
    if (!(std::fabs(glm::length(v) - 1.f) < 1e-5f) || !(v.z >= zMin - 1e-6f)) ++bad;
  EXPECT_EQ(bad, 0) << "directions not of unit length (tolerance 1e-5) or below z = " << zMin;
}

const auto cdfCosine = [](double z) { return z * z; };            // P(cos <= z) = z^2
const auto cdfUniformHemi = [](double z) { return z; };           // z uniform in [0,1]
const auto cdfSphere = [](double z) { return 0.5 * (z + 1.0); };  // z uniform in [-1,1]

class WarpChi2 : public ::testing::TestWithParam<Source> {};

TEST_P(WarpChi2, CosineHemisphere) {
  // 200,000 samples, 16 x 16 bins over (cos^2 theta, phi); p = 1e-4.
  auto d = warpAll(GetParam(), 11, gi::cosineHemisphere);
  expectUnitAndAbove(d, 0.f);
  auto h = dirHist(d, cdfCosine);
  EXPECT_LT(h.recorded("X2"), chi2Critical(h.dof())) << "dof " << h.dof();
}

TEST_P(WarpChi2, UniformSphere) {
  // 200,000 samples, 16 x 16 bins over ((z+1)/2, phi); p = 1e-4.
  auto d = warpAll(GetParam(), 12, gi::uniformSphere);
  expectUnitAndAbove(d, -1.f);
  auto h = dirHist(d, cdfSphere);
  EXPECT_LT(h.recorded("X2"), chi2Critical(h.dof())) << "dof " << h.dof();
}

TEST_P(WarpChi2, UniformHemisphere) {
  // 200,000 samples, 16 x 16 bins over (z, phi); p = 1e-4.
  auto d = warpAll(GetParam(), 13, gi::uniformHemisphere);
  expectUnitAndAbove(d, 0.f);
  auto h = dirHist(d, cdfUniformHemi);
  EXPECT_LT(h.recorded("X2"), chi2Critical(h.dof())) << "dof " << h.dof();
}

TEST_P(WarpChi2, UniformCone) {
  // For each cosMax: 200,000 samples, 16 x 16 bins over ((1-z)/(1-cosMax), phi); p = 1e-4.
  for (float cosMax : {0.99f, 0.5f, 0.f, -0.6f}) {
    auto d = warpAll(GetParam(), 14, [cosMax](glm::vec2 u) { return gi::uniformCone(u, cosMax); });
    expectUnitAndAbove(d, cosMax);
    auto h = dirHist(d, [cosMax](double z) { return (1.0 - z) / (1.0 - double(cosMax)); });
    EXPECT_LT(h.recorded("X2_cos" + std::to_string(cosMax)), chi2Critical(h.dof())) << "cosMax " << cosMax << ", dof " << h.dof();
  }
}

// Index of the cell of barycentrics (a, b) (a, b >= 0, a + b <= 1) in the
// subdivision of the triangle into n^2 congruent triangles of equal area.
int triangleCell(double a, double b, int n) {
  int i = std::clamp(int(std::floor(a * n)), 0, n - 1), j = std::clamp(int(std::floor(b * n)), 0, n - 1);
  if (i + j > n - 1) {  // rounding at the hypotenuse
    if (i > j) i = n - 1 - j; else j = n - 1 - i;
  }
  const double fa = a * n - i, fb = b * n - j;
  const bool upper = (fa + fb >= 1.0) && (i + j <= n - 2);
  // n^2 cells: index the square cell (i, j) twice.
  return (i * n + j) * 2 + (upper ? 1 : 0);
}

std::vector<long> triangleCounts(const std::vector<glm::vec2>& bary, int n, int* outside) {
  std::vector<long> cells(size_t(2 * n * n), 0);
  for (const auto& b : bary) {
    if (!(b.x >= 0.f && b.y >= 0.f && b.x + b.y <= 1.f + 1e-6f)) ++*outside;
    ++cells[size_t(triangleCell(b.x, b.y, n))];
  }
  // Keep the n^2 cells that exist (upper halves only below the hypotenuse).
  std::vector<long> used;
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      used.push_back(cells[size_t((i * n + j) * 2)]);
      if (i + j <= n - 2) used.push_back(cells[size_t((i * n + j) * 2 + 1)]);
    }
  return used;
}

TEST_P(WarpChi2, UniformTriangle) {
  // 200,000 samples; the triangle is cut into 16^2 = 256 congruent triangles
  // of equal area (781 expected each, dof 255); p = 1e-4.
  auto u = makeInputs(GetParam(), kN, 15);
  std::vector<glm::vec2> b(u.size());
  for (size_t i = 0; i < u.size(); ++i) b[i] = gi::uniformTriangle(u[i]);
  int outside = 0;
  auto cells = triangleCounts(b, kBins, &outside);
  ASSERT_EQ(cells.size(), size_t(kBins * kBins));
  EXPECT_EQ(outside, 0) << "barycentrics outside the triangle (tolerance 1e-6)";
  const double x2 = chi2Uniform(cells);
  RecordProperty("X2", std::to_string(x2));
  EXPECT_LT(x2, chi2Critical(int(cells.size()) - 1));
}

INSTANTIATE_TEST_SUITE_P(Inputs, WarpChi2, ::testing::Values(Source::Rng, Source::Sobol),
                         [](const ::testing::TestParamInfo<Source>& i) {
                           return i.param == Source::Rng ? std::string("Rng") : std::string("SobolOwen");
                         });

// Negative controls: the same statistic and critical value reject wrong warps.
TEST(WarpChi2Negative, RejectsWrongDistributions) {
  // 200,000 samples, 16 x 16 bins, p = 1e-4 as above.
  const double crit = chi2Critical(kBins * kBins - 1);
  // Uniform-hemisphere samples tested as cosine-weighted.
  auto uh = warpAll(Source::Rng, 21, gi::uniformHemisphere);
  EXPECT_GT(dirHist(uh, cdfCosine).recorded("X2_uniform_as_cosine"), crit);
  // Cosine-weighted samples tested as uniform on the hemisphere.
  auto ch = warpAll(Source::Sobol, 22, gi::cosineHemisphere);
  EXPECT_GT(dirHist(ch, cdfUniformHemi).recorded("X2_cosine_as_uniform"), crit);
  // A subtle error: azimuth covering only 97% of the circle.
  auto sub = warpAll(Source::Rng, 23, [](glm::vec2 u) { return gi::cosineHemisphere({u.x, u.y}); });
  for (auto& v : sub) {
    double phi = std::atan2(double(v.y), double(v.x)) * 0.97, r = std::hypot(double(v.x), double(v.y));
    v = glm::vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), v.z);
  }
  EXPECT_GT(dirHist(sub, cdfCosine).recorded("X2_phi097"), crit);
  // A cone tested with the wrong aperture (cosMax 0.5 samples as cosMax 0.45).
  auto cone = warpAll(Source::Rng, 24, [](glm::vec2 u) { return gi::uniformCone(u, 0.5f); });
  EXPECT_GT(dirHist(cone, [](double z) { return (1.0 - z) / 0.55; }).recorded("X2_cone_wrong"), crit);
  // The naive triangle warp (b0 = u, b1 = v (1 - u)) crowds the b0 = 1 corner.
  auto u = makeInputs(Source::Rng, kN, 25);
  std::vector<glm::vec2> b(u.size());
  for (size_t i = 0; i < u.size(); ++i) b[i] = {u[i].x, u[i].y * (1.f - u[i].x)};
  int outside = 0;
  const double x2 = chi2Uniform(triangleCounts(b, kBins, &outside));
  RecordProperty("X2_naive_triangle", std::to_string(x2));
  EXPECT_GT(x2, crit);
}

TEST(WarpChi2Negative, CriticalValueMatchesTable) {
  // Wilson-Hilferty against exact quantiles of chi^2 at 1 - 1e-4 (regularised
  // upper incomplete gamma solved with mpmath): k = 15: 44.263, k = 99: 160.056,
  // k = 255: 347.654. Tolerance 1%.
  EXPECT_NEAR(chi2Critical(15), 44.263, 0.44);
  EXPECT_NEAR(chi2Critical(99), 160.056, 1.6);
  EXPECT_NEAR(chi2Critical(255), 347.654, 3.5);
}

// (0,m,2)-net: every prefix of 2^k points of one key has exactly one point in
// each elementary interval of area 2^-k, i.e. in every cell of the
// 2^a x 2^(k-a) grids, a = 0..k. Checked at k = 8 (required) and k = 0..10,
// for 32 keys; exact (integer) check.
TEST(SobolOwen, PrefixesAreZeroM2Nets) {
  for (uint32_t key = 0; key < 32; ++key) {
    const uint32_t hk = gi::hash32(key * 7919u + 1u);
    for (int k = 0; k <= 10; ++k) {
      const uint32_t n = 1u << k;
      std::vector<glm::vec2> p(n);
      for (uint32_t i = 0; i < n; ++i) p[i] = gi::sobolOwen2D(i, hk);
      for (int a = 0; a <= k; ++a) {
        std::vector<int> cnt(n, 0);
        for (const auto& q : p) {
          const uint32_t cx = uint32_t(q.x * float(1u << a)), cy = uint32_t(q.y * float(1u << (k - a)));
          ++cnt[(cx << (k - a)) | cy];
        }
        const bool allOne = std::all_of(cnt.begin(), cnt.end(), [](int c) { return c == 1; });
        ASSERT_TRUE(allOne) << "key " << hk << ", 2^" << k << " points, grid 2^" << a << " x 2^" << (k - a);
      }
    }
  }
}

TEST(SobolOwen, RangeDeterminismAndKeys) {
  // Values in [0,1) for 64 keys x 4096 indices (and a few huge indices).
  for (uint32_t key = 0; key < 64; ++key)
    for (uint32_t i = 0; i < 4096; ++i) {
      glm::vec2 p = gi::sobolOwen2D(i, gi::hash32(key));
      ASSERT_TRUE(p.x >= 0.f && p.x < 1.f && p.y >= 0.f && p.y < 1.f) << key << " " << i;
    }
  for (uint32_t i : {0xffffffffu, 0x80000000u, 0x7fffffffu}) {
    glm::vec2 p = gi::sobolOwen2D(i, 123u);
    EXPECT_TRUE(p.x >= 0.f && p.x < 1.f && p.y >= 0.f && p.y < 1.f);
  }
  // Determinism: the same (i, key) gives bit-identical points.
  for (uint32_t i = 0; i < 256; ++i) {
    glm::vec2 a = gi::sobolOwen2D(i, 99u), b = gi::sobolOwen2D(i, 99u);
    EXPECT_EQ(a.x, b.x);
    EXPECT_EQ(a.y, b.y);
  }
  // Different keys: 1000 keys give 1000 different 16-point sequences, and no
  // first point is shared by more than a handful (24-bit values: expected
  // collisions among 1000 ~ 0.03).
  std::set<std::vector<float>> seqs;
  std::set<std::pair<float, float>> firsts;
  for (uint32_t key = 0; key < 1000; ++key) {
    std::vector<float> s;
    for (uint32_t i = 0; i < 16; ++i) {
      glm::vec2 p = gi::sobolOwen2D(i, key);
      s.push_back(p.x);
      s.push_back(p.y);
    }
    seqs.insert(s);
    firsts.insert({s[0], s[1]});
  }
  EXPECT_EQ(seqs.size(), 1000u);
  EXPECT_GE(firsts.size(), 998u);
  // The two dimensions are scrambled independently (not x == y).
  int same = 0;
  for (uint32_t i = 0; i < 1024; ++i) {
    glm::vec2 p = gi::sobolOwen2D(i, 5u);
    same += p.x == p.y;
  }
  EXPECT_LT(same, 4);
}

TEST(Rng, RangeAndDeterminism) {
  // 100,000 draws in [0,1); same key, same stream; mean within 0.01 of 1/2.
  gi::Rng a(42), b(42), c(43);
  double sum = 0.0;
  int equal = 0;
  for (int i = 0; i < 100000; ++i) {
    float x = a.next(), y = b.next(), z = c.next();
    ASSERT_TRUE(x >= 0.f && x < 1.f);
    ASSERT_EQ(x, y);
    equal += x == z;
    sum += x;
  }
  EXPECT_NEAR(sum / 100000.0, 0.5, 0.01);
  EXPECT_LT(equal, 10);
}

// Frame: orthonormal, right-handed (t x b = n) and invertible, for 10,000
// random unit normals and the hard cases around -z. Tolerance 1e-5 (float).
void expectOrthonormal(const glm::vec3& n) {
  gi::Frame f(n);
  const float tol = 1e-5f;
  EXPECT_NEAR(glm::length(f.t), 1.f, tol) << n.x << "," << n.y << "," << n.z;
  EXPECT_NEAR(glm::length(f.b), 1.f, tol) << n.x << "," << n.y << "," << n.z;
  EXPECT_NEAR(glm::dot(f.t, f.b), 0.f, tol) << n.x << "," << n.y << "," << n.z;
  EXPECT_NEAR(glm::dot(f.t, n), 0.f, tol) << n.x << "," << n.y << "," << n.z;
  EXPECT_NEAR(glm::dot(f.b, n), 0.f, tol) << n.x << "," << n.y << "," << n.z;
  EXPECT_LT(glm::length(glm::cross(f.t, f.b) - n), 2 * tol) << n.x << "," << n.y << "," << n.z;
  const glm::vec3 v(0.3f, -0.5f, 0.8f);
  EXPECT_LT(glm::length(f.toLocal(f.toWorld(v)) - v), 2 * tol);
  EXPECT_LT(glm::length(f.toWorld(glm::vec3(0, 0, 1)) - n), tol);
  for (float c : {f.t.x, f.t.y, f.t.z, f.b.x, f.b.y, f.b.z}) EXPECT_TRUE(std::isfinite(c));
}

TEST(Frame, OrthonormalForAllNormals) {
  gi::Rng rng(7);
  for (int i = 0; i < 10000; ++i) expectOrthonormal(gi::uniformSphere({rng.next(), rng.next()}));
  for (glm::vec3 n : {glm::vec3(0, 0, -1), glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::vec3(0, -1, 0),
                      glm::normalize(glm::vec3(1e-4f, 1e-4f, -1.f)), glm::normalize(glm::vec3(-1e-7f, 0.f, -1.f)),
                      glm::normalize(glm::vec3(3e-4f, -2e-4f, -1.f)), glm::normalize(glm::vec3(1.f, 1.f, -1e-7f)),
                      glm::normalize(glm::vec3(1.f, 0.f, 1e-7f))})
    expectOrthonormal(n);
  // A sweep down to the south pole: z = -cos(theta), theta = 1e-1 .. 1e-7.
  for (double th = 1e-1; th > 1e-7; th *= 0.5)
    expectOrthonormal(glm::vec3(float(std::sin(th)), 0.f, float(-std::cos(th))));
}

// Convergence: the mean of x*y over [0,1]^2 (exactly 1/4) estimated with the
// first N points of 64 independent keys; RMS error over the keys at
// N = 64, 128, ..., 1024; least-squares slope of log RMS vs log N. Owen-
// scrambled Sobol gives about N^-1.5 for smooth integrands; required < -0.7.
// A plain Rng control must give about -0.5 (in [-0.7, -0.3]).
double convergenceSlope(bool sobol) {
  std::vector<double> lx, ly;
  for (int N = 64; N <= 1024; N *= 2) {
    double se = 0.0;
    for (uint32_t key = 0; key < 64; ++key) {
      gi::Rng rng(gi::hash3(key, uint32_t(N), 3u));
      double s = 0.0;
      for (int i = 0; i < N; ++i) {
        glm::vec2 p = sobol ? gi::sobolOwen2D(uint32_t(i), gi::hash3(key, 1u, 2u)) : glm::vec2(rng.next(), rng.next());
        s += double(p.x) * double(p.y);
      }
      const double e = s / N - 0.25;
      se += e * e;
    }
    lx.push_back(std::log(double(N)));
    ly.push_back(0.5 * std::log(se / 64.0));
  }
  const double n = double(lx.size());
  double mx = 0, my = 0;
  for (size_t i = 0; i < lx.size(); ++i) { mx += lx[i] / n; my += ly[i] / n; }
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < lx.size(); ++i) { sxy += (lx[i] - mx) * (ly[i] - my); sxx += (lx[i] - mx) * (lx[i] - mx); }
  return sxy / sxx;
}

TEST(SobolOwen, ConvergesFasterThanMonteCarlo) {
  const double sSobol = convergenceSlope(true), sRandom = convergenceSlope(false);
  RecordProperty("slope_sobol", std::to_string(sSobol));
  RecordProperty("slope_random", std::to_string(sRandom));
  EXPECT_LT(sSobol, -0.7) << "Owen-scrambled Sobol RMS error slope";
  EXPECT_GT(sRandom, -0.7) << "control: plain random slope";
  EXPECT_LT(sRandom, -0.3) << "control: plain random slope";
}

}  // namespace
