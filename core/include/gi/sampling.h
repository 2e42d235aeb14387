// Deterministic sampling keyed by (element, sample index, seed): results never
// depend on thread identity or scheduling.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

namespace gi {

// Counts to a target error from a pilot left out of the estimate (Stein's
// two-stage procedure with the first stage dropped: Stein 1945, Ann. Math.
// Statist. 16(3)): a count decided from the samples it keeps biases their
// mean (a vertex whose samples came out high meets a relative target early;
// one whose samples all missed a small opening reads no variance and stops
// dark), while one fixed before they are drawn leaves them unbiased. The
// pilot runs to kPilotLooseness times the target (about a quarter of the
// samples); the count is its prediction times kPilotMargin, for the pilot's
// own error. The reference, ambient occlusion and the sky use it.
inline constexpr double kPilotLooseness = 2.0;
inline constexpr double kPilotMargin = 1.25;

// The variance of a 0/1 variable at Laplace's rule of succession, p (1 - p)
// with p = (k + 1) / (n + 2) after k successes in n trials (k may be a sum
// of weights in [0, 1]): never 0, so that trials which all agreed (every ray
// escaped past a thin occluder, every sun ray blocked in a penumbra) still
// report an error and do not stop a vertex early.
inline double laplaceVariance(double k, double n) {
  const double p = (k + 1.0) / (n + 2.0);
  return p * (1.0 - p);
}

constexpr uint32_t reverseBits(uint32_t x) {
  x = __builtin_bswap32(x);  // bytes reversed; then the bits within each byte
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  return ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
}

// A 32-bit integer hash with good avalanche (lowbias32, C. Wellons).
inline uint32_t hash32(uint32_t x) {
  x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
  return x;
}
inline uint32_t hashCombine(uint32_t a, uint32_t b) { return hash32(a ^ (hash32(b) + 0x9e3779b9u + (a << 6) + (a >> 2))); }
inline uint32_t hash3(uint32_t a, uint32_t b, uint32_t c) { return hashCombine(hashCombine(hash32(a), b), c); }

inline float toUnitFloat(uint32_t x) { return float(x >> 8) * 0x1p-24f; }  // [0,1)

// sin and cos on [-pi/4, pi/4] by short Taylor series (error below 2e-9
// there), instead of the libm calls, in the direction generators.
inline void sinCosQuarterPi(float x, float& s, float& c) {
  const float x2 = x * x;
  s = x * (1.f + x2 * (-1.f / 6 + x2 * (1.f / 120 + x2 * (-1.f / 5040 + x2 * (1.f / 362880)))));
  c = 1.f + x2 * (-0.5f + x2 * (1.f / 24 + x2 * (-1.f / 720 + x2 * (1.f / 40320 + x2 * (-1.f / 3628800)))));
}

// Nested uniform (Owen) scrambling by hashing, Burley 2020, "Practical
// Hash-based Owen Scrambling", JCGT 9(4): Laine-Karras permutation on the
// bit-reversed value.
inline uint32_t laineKarrasPermutation(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu; x ^= x * 0xb82f1e52u; x ^= x * 0xc7afe638u; x ^= x * 0x8d22f6e6u;
  return x;
}
inline uint32_t nestedUniformScramble(uint32_t x, uint32_t seed) {
  return reverseBits(laineKarrasPermutation(reverseBits(x), seed));
}

// The first two Sobol dimensions (van der Corput and the Pascal-matrix one).
// Dimension 2's direction numbers (primitive polynomial x + 1): v_0 = 2^31,
// v_k = v_{k-1} ^ (v_{k-1} >> 1); tabulated per byte of the index, bit-reversed
// (the Owen scramble works on reversed values).
struct Sobol2Table {
  uint32_t t[4][256];
  constexpr Sobol2Table() : t() {
    uint32_t v[32] = {};
    v[0] = 0x80000000u;
    for (int k = 1; k < 32; ++k) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
    for (int byte = 0; byte < 4; ++byte)
      for (int b = 0; b < 256; ++b) {
        uint32_t x = 0;
        for (int bit = 0; bit < 8; ++bit)
          if (b & (1 << bit)) x ^= v[8 * byte + bit];
        t[byte][b] = reverseBits(x);
      }
  }
};
inline constexpr Sobol2Table kSobol2Reversed{};
inline uint32_t sobol2Reversed(uint32_t i) {
  return kSobol2Reversed.t[0][i & 0xffu] ^ kSobol2Reversed.t[1][(i >> 8) & 0xffu] ^
         kSobol2Reversed.t[2][(i >> 16) & 0xffu] ^ kSobol2Reversed.t[3][i >> 24];
}
inline uint32_t sobol2(uint32_t index) { return reverseBits(sobol2Reversed(index)); }
inline uint32_t sobol1(uint32_t index) { return reverseBits(index); }

// The seeds of one randomised 2D sequence: its index shuffle and its two
// dimensions' scrambles, derived from `key`.
struct SobolOwenSeeds {
  uint32_t shuffle, x, y;
  explicit SobolOwenSeeds(uint32_t key)
      : shuffle(hash32(key)), x(hashCombine(key, 0x68bc21ebu)), y(hashCombine(key, 0x02e5be93u)) {}
};
// Sobol point `idx` (no index shuffle), each dimension Owen-scrambled:
// nestedUniformScramble(v, s) = reverse(LK(reverse(v), s)), and sobol1(idx)
// reversed is idx itself.
inline glm::vec2 sobolOwenAt(uint32_t idx, const SobolOwenSeeds& s) {
  return {toUnitFloat(reverseBits(laineKarrasPermutation(idx, s.x))),
          toUnitFloat(reverseBits(laineKarrasPermutation(sobol2Reversed(idx), s.y)))};
}
// The same at the shuffled index (Burley 2020, section 4).
inline glm::vec2 sobolOwen2D(uint32_t i, const SobolOwenSeeds& s) {
  return sobolOwenAt(nestedUniformScramble(i, s.shuffle), s);
}

// Owen-scrambled 2D Sobol point `i` of the sequence keyed by `key`
// (e.g. hash of element and seed). Each key gives an independent randomised
// sequence whose prefixes of 2^k points are stratified. The index itself is
// Owen-scrambled first (its first 2^k values map onto one aligned block of
// 2^k Sobol indices, which is again a (0,k,2)-net), so two keys give
// independent sequences even when stepped with the same i.
inline glm::vec2 sobolOwen2D(uint32_t i, uint32_t key) { return sobolOwen2D(i, SobolOwenSeeds(key)); }

// Independent 2D dimensions of one sample index ("padding", Burley 2020,
// section 4): dimension pair `dim` of sample i is sobolOwen2D(i, key of dim),
// so each pair has its own index shuffle (but the first, which needs none)
// and its own scrambles. Every pair alone is
// a stratified (0,k,2)-net on power-of-two prefixes, and the pairs are
// independent of each other. Use it wherever one estimate consumes two or
// more 2D draws (origin and direction, light point and direction):
// two Owen-scrambled streams stepped with the same index and no index
// shuffle share their leading digits, which ties e.g. a ray's origin on a
// patch to its direction and biases the estimate.
class PaddedSobol {
 public:
  explicit PaddedSobol(uint32_t key)
      : key_(key), seeds_{SobolOwenSeeds(dimKey(0)), SobolOwenSeeds(dimKey(1)), SobolOwenSeeds(dimKey(2))} {}
  // Dimension 0 keeps the natural order: only the dimensions' orders
  // relative to each other matter, and it saves one index scramble.
  glm::vec2 operator()(uint32_t i, uint32_t dim) const {
    if (dim == 0) return sobolOwenAt(i, seeds_[0]);
    return sobolOwen2D(i, dim < kCached ? seeds_[dim] : SobolOwenSeeds(dimKey(dim)));
  }

 private:
  static constexpr uint32_t kCached = 3;  // the seeds of the first dimensions, computed once
  uint32_t dimKey(uint32_t dim) const { return hashCombine(key_, 0x2545f491u * (dim + 1u)); }
  uint32_t key_;
  SobolOwenSeeds seeds_[kCached];
};

// The same kind of sequence, generated in order at O(1) per point: Sobol
// points in Gray-code order (every power-of-two prefix is the same point set
// as in natural order), each dimension Owen-scrambled with its own seed.
// No index shuffle: only for an estimate that draws ONE 2D point per sample
// (AO's directions); two such streams stepped together are correlated (use
// PaddedSobol).
struct SobolRevDir1 {
  uint32_t v[32];
  constexpr SobolRevDir1() : v() {
    uint32_t d = 0x80000000u;
    for (int k = 0; k < 32; ++k, d ^= d >> 1) v[k] = reverseBits(d);
  }
};
inline constexpr SobolRevDir1 kSobolRevDir1{};

// u[j] = toUnitFloat(reverseBits(laineKarrasPermutation(r[j], seed))) for
// j < n: the scrambling of a block of points (sampling.cpp: built for AVX2
// too, picked at run time; integer operations, so the same bits either way).
void scrambleBlock(int n, const uint32_t* r, uint32_t seed, float* u);

class SobolOwenStream {
 public:
  explicit SobolOwenStream(uint32_t key) : s0_(hashCombine(key, 0x68bc21ebu)), s1_(hashCombine(key, 0x02e5be93u)) {}
  // The next n points as two arrays (scrambling vectorises over the block).
  void nextBlock(int n, float* u0, float* u1) {  // n <= 64
    uint32_t a[64], b[64];
    for (int j = 0; j < n; ++j) {
      a[j] = r0_; b[j] = r1_;
      const int c = __builtin_ctz(++i_);
      r0_ ^= 1u << c;
      r1_ ^= kSobolRevDir1.v[c];
    }
    scrambleBlock(n, a, s0_, u0);
    scrambleBlock(n, b, s1_, u1);
  }
  // Jumps to point i: the Gray code of i in dimension 1 (bit-reversed
  // domain), the XOR of the direction numbers of its set bits in dimension 2.
  void seek(uint32_t i) {
    i_ = i;
    r0_ = i ^ (i >> 1);
    r1_ = 0;
    for (uint32_t g = r0_; g; g &= g - 1) r1_ ^= kSobolRevDir1.v[__builtin_ctz(g)];
  }
  glm::vec2 next() {
    const glm::vec2 p{toUnitFloat(reverseBits(laineKarrasPermutation(r0_, s0_))),
                      toUnitFloat(reverseBits(laineKarrasPermutation(r1_, s1_)))};
    // Gray-code step: flip direction number ctz(i + 1). In the bit-reversed
    // domain, dimension 1's value is the Gray code itself.
    const int c = __builtin_ctz(++i_);
    r0_ ^= 1u << c;
    r1_ ^= kSobolRevDir1.v[c];
    return p;
  }

 private:
  uint32_t s0_, s1_, i_ = 0, r0_ = 0, r1_ = 0;
};

// Counter-based independent uniform numbers (for Russian roulette etc.).
struct Rng {
  uint32_t state;
  explicit Rng(uint32_t key) : state(hash32(key ^ 0xa511e9b3u)) {}
  uint32_t nextU32() { state = state * 747796405u + 2891336453u; uint32_t w = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u; return (w >> 22u) ^ w; }  // PCG-RXS-M-XS
  float next() { return toUnitFloat(nextU32()); }
};

// Warps of [0,1)^2. Hemisphere warps return z-up local directions.
glm::vec3 cosineHemisphere(glm::vec2 u);   // pdf = cos(theta) / pi
// The same warp for n points at once (branch-free, vectorisable), z-up local.
void cosineHemisphereBlock(int n, const float* u0, const float* u1, float* x, float* y, float* z);
inline float cosineHemispherePdf(float cosTheta) { return cosTheta * 0.318309886f; }
glm::vec3 uniformSphere(glm::vec2 u);      // pdf = 1 / (4 pi)
glm::vec3 uniformHemisphere(glm::vec2 u);  // pdf = 1 / (2 pi)
// Uniform in a cone of half-angle with cos = cosMax around +z; pdf = 1 / (2 pi (1 - cosMax)).
glm::vec3 uniformCone(glm::vec2 u, float cosMax);
// The same cone given by its versine 1 - cos(half-angle): exact for cones
// too narrow for cosMax in single precision (1 - cosMax is 0 below 0.014
// degrees, 0.5% off at the sun's 0.27).
glm::vec3 uniformConeVersine(glm::vec2 u, float versine);

// A cone of half-angle a around an axis (the sun's disk, a spot light),
// kept in double: a float cosine admits a cone wider than the one whose
// solid angle a radiance divides by (the sun 1.55 times too bright at 0.01
// degrees) and holds no direction but the axis below 0.014 degrees.
class Cone {
 public:
  Cone() = default;
  Cone(const glm::vec3& axis, double halfAngleDeg);  // axis of any length
  double versine() const { return versine_; }  // 1 - cos a = 2 sin^2(a / 2), exact when narrow
  double solidAngle() const { return 2.0 * 3.14159265358979323846 * versine_; }
  // Whether d (any length) lies inside: |d x axis|^2 <= sin^2 a |d|^2
  // |axis|^2 on the axis's side up to 90 degrees, the cosine beyond.
  bool contains(const glm::vec3& d) const;

 private:
  glm::dvec3 axis_{0.0, 0.0, 1.0};
  double versine_ = 0.0, sin2_ = 0.0, cos_ = 1.0;
  bool narrow_ = true, all_ = false;  // a <= 90 degrees; a >= 180 degrees
};
// Uniform point on a triangle: barycentrics (b1, b2) (Heitz 2019 low-distortion warp).
glm::vec2 uniformTriangle(glm::vec2 u);

// Barycentrics (b1, b2) pulled towards the centroid by 1e-5 of the
// triangle: a ray origin strictly inside (one on an edge can slip through the
// neighbour's edge), in a band too thin to bias an estimate. (A pull of 2e-3
// cost 1.1% of F from a thin patch to one at its common edge, where the
// integrand is 20 times its mean.)
inline glm::vec2 strictlyInside(glm::vec2 b) { return b * (1.f - 3e-5f) + 1e-5f; }

// Orthonormal basis with n as z (Duff et al. 2017).
struct Frame {
  glm::vec3 t, b, n;
  explicit Frame(const glm::vec3& nn);
  glm::vec3 toWorld(const glm::vec3& v) const { return t * v.x + b * v.y + n * v.z; }
  glm::vec3 toLocal(const glm::vec3& v) const { return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)}; }
};

}  // namespace gi
