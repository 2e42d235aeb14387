// The padded Owen-scrambled Sobol sampler (gi/sampling.h; Burley 2020,
// "Practical Hash-based Owen Scrambling"): the index shuffle keeps
// power-of-two prefixes on one aligned block of Sobol indices, every 2D
// dimension stays a (0,m,2)-net, and different dimensions of one index are
// independent, where two streams stepped together are not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "gi/sampling.h"

using namespace gi;

namespace {

// Sobol dimension 2 from its definition (the loop the table replaces).
uint32_t sobol2Reference(uint32_t index) {
  uint32_t x = 0, v = 0x80000000u;
  for (; index; index >>= 1, v ^= v >> 1)
    if (index & 1u) x ^= v;
  return x;
}

// Whether pts[0 .. 2^m) put exactly one point in every elementary interval
// of area 2^-m (all 2^a x 2^(m-a) grids).
bool isNet(const std::vector<glm::vec2>& pts, int m) {
  const size_t n = size_t(1) << m;
  for (int a = 0; a <= m; ++a) {
    std::vector<int> cells(n, 0);
    for (size_t k = 0; k < n; ++k) {
      const uint32_t cx = uint32_t(double(pts[k].x) * double(1u << a));
      const uint32_t cy = uint32_t(double(pts[k].y) * double(1u << (m - a)));
      ++cells[(size_t(cx) << (m - a)) | cy];
    }
    if (!std::all_of(cells.begin(), cells.end(), [](int c) { return c == 1; })) return false;
  }
  return true;
}

// Pearson's X^2 of the joint first two binary digits of u and v (16 cells);
// the 1e-4 critical value for 15 degrees of freedom is 44.26.
double jointDigitsX2(const std::vector<float>& u, const std::vector<float>& v) {
  std::vector<double> c(16, 0.0);
  for (size_t k = 0; k < u.size(); ++k) c[size_t(int(u[k] * 4) * 4 + int(v[k] * 4))] += 1;
  const double e = double(u.size()) / 16;
  double x2 = 0;
  for (double o : c) x2 += (o - e) * (o - e) / e;
  return x2;
}

}  // namespace

TEST(PaddedSobol, Sobol2TableMatchesDefinition) {
  for (uint32_t i : {0u, 1u, 2u, 3u, 255u, 256u, 65535u, 65536u, 0x12345678u, 0xffffffffu})
    EXPECT_EQ(sobol2(i), sobol2Reference(i)) << i;
  Rng rng(3);
  for (int k = 0; k < 1000; ++k) {
    const uint32_t i = rng.nextU32();
    ASSERT_EQ(sobol2(i), sobol2Reference(i));
  }
}

// An Owen scramble of the index maps 0 .. 2^m - 1 onto one aligned block of
// 2^m indices (its bit j depends only on bits j and above).
TEST(PaddedSobol, IndexShuffleKeepsAlignedBlocks) {
  for (uint32_t seed : {1u, 77u, 0xdeadbeefu})
    for (int m : {1, 4, 8, 12}) {
      const uint32_t n = 1u << m;
      std::vector<uint32_t> idx(n);
      for (uint32_t i = 0; i < n; ++i) idx[i] = nestedUniformScramble(i, seed);
      std::sort(idx.begin(), idx.end());
      EXPECT_EQ(idx.front() % n, 0u) << m;
      EXPECT_EQ(idx.back() - idx.front(), n - 1) << m;
      EXPECT_TRUE(std::adjacent_find(idx.begin(), idx.end()) == idx.end()) << m;
    }
}

// Every dimension of the padded sampler, and the plain sobolOwen2D, are
// (0,m,2)-nets on their first 2^m points, for several keys.
TEST(PaddedSobol, EveryDimensionIsANet) {
  for (uint32_t key : {0u, 12345u, 0x9e3779b9u}) {
    const PaddedSobol smp(key);
    for (uint32_t dim : {0u, 1u, 2u, 5u})
      for (int m : {4, 7, 10}) {
        std::vector<glm::vec2> p(size_t(1) << m);
        for (uint32_t i = 0; i < p.size(); ++i) p[i] = smp(i, dim);
        EXPECT_TRUE(isNet(p, m)) << "key " << key << " dim " << dim << " m " << m;
      }
  }
}

// The defect the padding removes: two Owen-scrambled streams stepped with
// the same index share their leading digits (the first binary digit of one
// decides the other's, up to a flip fixed by the seeds), so the joint
// histogram of their first two digits leaves cells empty. Dimensions 0 and 1
// of the padded sampler fill all 16 cells evenly: X^2 below the 1e-4
// critical value (44.26) for every key tried, where the unshuffled pair is
// far above it.
TEST(PaddedSobol, DimensionsAreIndependent) {
  const int n = 4096;
  int paddedOk = 0, lockstepBad = 0;
  for (uint32_t key = 1; key <= 20; ++key) {
    const PaddedSobol smp(hash32(key));
    SobolOwenStream a(hash3(key, 1, 2)), b(hash3(key, 3, 4));
    std::vector<float> u(n), v(n), su(n), sv(n);
    for (int k = 0; k < n; ++k) {
      u[size_t(k)] = smp(uint32_t(k), 0).x;
      v[size_t(k)] = smp(uint32_t(k), 1).x;
      su[size_t(k)] = a.next().x;
      sv[size_t(k)] = b.next().x;
    }
    paddedOk += jointDigitsX2(u, v) < 44.26;
    lockstepBad += jointDigitsX2(su, sv) > 44.26;
  }
  EXPECT_EQ(paddedOk, 20);
  EXPECT_EQ(lockstepBad, 20);
}

TEST(PaddedSobol, Deterministic) {
  const PaddedSobol a(42), b(42), c(43);
  for (uint32_t i = 0; i < 100; ++i)
    for (uint32_t d = 0; d < 6; ++d) {
      EXPECT_EQ(a(i, d), b(i, d));
      EXPECT_NE(a(i, d), c(i, d));
    }
}
