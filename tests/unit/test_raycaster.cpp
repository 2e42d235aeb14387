// gi/raycaster.h: the Embree caster (all BatchModes) against the brute-force
// double-precision oracle on a random triangle soup, occlusion queries against
// intersection (tnear / tfar limits included), thread safety, empty scenes, and
// the exclusion of NaN / degenerate / invalid faces with face indices that
// still refer to Scene::triangles.
//
// Ambiguous rays: float (Embree) and double (brute force) may legitimately
// disagree when a ray grazes a triangle edge or two hits are nearly equally
// far. A ray is "ambiguous" (face identity not compared) when, computed here in
// double precision over the usable faces:
//   - the two nearest hits in (tnear, tfar) are within 1e-4 relative distance;
//   - some face is hit or missed by a barycentric margin below 1e-5;
//   - some candidate hit lies within 1e-4 relative distance of tnear or tfar;
//   - some candidate is seen edge-on (|cos| < 1e-4).
// Everything else must agree: same face, t within 1e-4 relative, (u, v) within
// 1e-3, same geometric-normal orientation. The tests require < 2% ambiguous rays
// so that they cannot pass vacuously.
#include <gtest/gtest.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "gi/raycaster.h"
#include "gi/sampling.h"
#include "gi/scene.h"

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr gi::BatchMode kModes[] = {gi::BatchMode::Single, gi::BatchMode::Packet8, gi::BatchMode::Stream};
const char* modeName(gi::BatchMode m) {
  return m == gi::BatchMode::Single ? "Single" : m == gi::BatchMode::Packet8 ? "Packet8" : "Stream";
}

constexpr double kRelT = 1e-4;     // relative distance tolerance
constexpr double kBaryEps = 1e-5;  // grazing margin in barycentric units

// A soup of 300 random triangles in [-1.25, 1.25]^3, with 50 unusable faces
// interleaved (every 7th slot: collinear, repeated index, NaN / Inf vertex,
// index out of range), so usable faces have indices != primitive order.
gi::Scene randomSoup(uint32_t seed, size_t nTris = 300) {
  gi::Scene s;
  gi::Rng rng(seed);
  auto r = [&] { return rng.next() * 2.f - 1.f; };
  const uint32_t nanV = 0, infV = 1;
  s.positions.push_back({kNaN, 0.f, 0.f});
  s.positions.push_back({0.f, kInf, 0.f});
  size_t good = 0, slot = 0;
  while (good < nTris) {
    const uint32_t b = uint32_t(s.positions.size());
    const glm::vec3 c(r(), r(), r());
    if (slot++ % 7 == 3) {
      switch ((slot / 7) % 5) {
        case 0: {  // exactly collinear (along x: same y and z)
          const glm::vec3 d(0.1f + 0.1f * rng.next(), 0.f, 0.f);
          s.positions.insert(s.positions.end(), {c - d, c, c + 2.f * d});
          s.triangles.push_back({b, b + 1, b + 2});
          break;
        }
        case 1:
          s.positions.insert(s.positions.end(), {c, c + glm::vec3(0.2f, 0, 0)});
          s.triangles.push_back({b, b + 1, b});
          break;
        case 2:
          s.positions.insert(s.positions.end(), {c, c + glm::vec3(0.2f, 0, 0)});
          s.triangles.push_back({b, b + 1, nanV});
          break;
        case 3:
          s.positions.insert(s.positions.end(), {c, c + glm::vec3(0.2f, 0, 0)});
          s.triangles.push_back({infV, b, b + 1});
          break;
        default:
          s.positions.insert(s.positions.end(), {c, c + glm::vec3(0.2f, 0, 0)});
          s.triangles.push_back({b, b + 1, 1u << 30});
      }
      continue;
    }
    for (int k = 0; k < 3; ++k) s.positions.push_back(c + 0.25f * glm::vec3(r(), r(), r()));
    s.triangles.push_back({b, b + 1, b + 2});
    ++good;
  }
  return s;
}

// 10,000 rays: half from a sphere of radius 4 aimed at points of the soup's
// box, half starting inside it in uniform directions; every 5th direction is
// scaled by 0.5 .. 2 (t is in units of |d|).
std::vector<gi::Ray> randomRays(uint32_t seed, size_t n = 10000) {
  std::vector<gi::Ray> rays(n);
  gi::Rng rng(seed);
  for (size_t i = 0; i < n; ++i) {
    gi::Ray& ry = rays[i];
    if (i % 2 == 0) {
      ry.o = 4.f * gi::uniformSphere({rng.next(), rng.next()});
      glm::vec3 target(rng.next() * 2.5f - 1.25f, rng.next() * 2.5f - 1.25f, rng.next() * 2.5f - 1.25f);
      ry.d = glm::normalize(target - ry.o);
    } else {
      ry.o = glm::vec3(rng.next() * 2.5f - 1.25f, rng.next() * 2.5f - 1.25f, rng.next() * 2.5f - 1.25f);
      ry.d = gi::uniformSphere({rng.next(), rng.next()});
    }
    if (i % 5 == 0) ry.d *= 0.5f + 1.5f * rng.next();
  }
  return rays;
}

struct Expect {
  bool ambiguous = false;
  uint32_t face = gi::kNoHit;
  double t = 0.0;
};

// Double-precision classification of a ray over the usable faces (see top).
Expect classify(const gi::Scene& s, const std::vector<uint8_t>& ok, const gi::Ray& r) {
  Expect e;
  double best = HUGE_VAL, second = HUGE_VAL;
  const glm::dvec3 o(r.o), d(r.d);
  const double tn = r.tnear, tf = r.tfar;
  auto tau = [](double t) { return kRelT * std::max(std::fabs(t), 1e-3); };
  for (size_t f = 0; f < ok.size(); ++f) {
    if (!ok[f]) continue;
    const auto& tri = s.triangles[f];
    const glm::dvec3 a(s.positions[tri.x]), b(s.positions[tri.y]), c(s.positions[tri.z]);
    const glm::dvec3 e1 = b - a, e2 = c - a, pv = glm::cross(d, e2);
    const double det = glm::dot(e1, pv);
    const glm::dvec3 n = glm::cross(e1, e2);
    const double cosA = std::fabs(glm::dot(n, d)) / (glm::length(n) * glm::length(d));
    if (det == 0.0) continue;
    const glm::dvec3 tv = o - a, qv = glm::cross(tv, e1);
    const double u = glm::dot(tv, pv) / det, v = glm::dot(d, qv) / det, t = glm::dot(e2, qv) / det;
    const double margin = std::min({u, v, 1.0 - u - v});
    if (margin < -kBaryEps) continue;
    if (t < tn - tau(tn) || t > tf + tau(tf)) continue;  // clearly out of range
    if (cosA < 1e-4 || margin < kBaryEps || std::fabs(t - tn) < tau(t) || std::fabs(t - tf) < tau(t)) {
      e.ambiguous = true;
      continue;
    }
    if (t <= tn || t >= tf) continue;
    if (t < best) { second = best; best = t; e.face = uint32_t(f); }
    else if (t < second) second = t;
  }
  if (second < HUGE_VAL && second - best < tau(best)) e.ambiguous = true;
  e.t = best;
  return e;
}

std::string rayStr(const gi::Ray& r) {
  char b[256];
  std::snprintf(b, sizeof b, "o=(%.9g,%.9g,%.9g) d=(%.9g,%.9g,%.9g) tnear=%.9g tfar=%.9g", r.o.x, r.o.y, r.o.z, r.d.x,
                r.d.y, r.d.z, r.tnear, r.tfar);
  return b;
}

// Base rays plus, for each base hit at t: tfar = 0.5 t (no occluder before),
// tfar = 1.01 t (occluded), tnear = 1.001 t (the next hit), and the origin moved
// to 0.4 t with tnear = 0.05 t.
std::vector<gi::Ray> withLimitVariants(const std::vector<gi::Ray>& base, const gi::RayCaster& ref) {
  std::vector<gi::Ray> all = base;
  for (const auto& r : base) {
    const gi::Hit h = ref.intersect(r);
    if (!h.valid()) continue;
    gi::Ray a = r; a.tfar = 0.5f * h.t; all.push_back(a);
    gi::Ray b = r; b.tfar = 1.01f * h.t; all.push_back(b);
    gi::Ray c = r; c.tnear = 1.001f * h.t; all.push_back(c);
    gi::Ray m = r; m.o = r.o + 0.4f * h.t * r.d; m.tnear = 0.05f * h.t; all.push_back(m);
  }
  return all;
}

struct SoupFixture : ::testing::Test {
  static void SetUpTestSuite() {
    scene = new gi::Scene(randomSoup(2024));
    brute = gi::makeBruteForceCaster(*scene).release();
    rays = new std::vector<gi::Ray>(withLimitVariants(randomRays(77), *brute));
    const auto ok = gi::usableFaceMask(*scene);
    expect = new std::vector<Expect>(rays->size());
    refHits = new std::vector<gi::Hit>(rays->size());
    for (size_t i = 0; i < rays->size(); ++i) {
      (*expect)[i] = classify(*scene, ok, (*rays)[i]);
      (*refHits)[i] = brute->intersect((*rays)[i]);
    }
  }
  static void TearDownTestSuite() {
    delete refHits; delete expect; delete rays; delete brute; delete scene;
  }
  static gi::Scene* scene;
  static gi::RayCaster* brute;
  static std::vector<gi::Ray>* rays;
  static std::vector<Expect>* expect;
  static std::vector<gi::Hit>* refHits;
};
gi::Scene* SoupFixture::scene = nullptr;
gi::RayCaster* SoupFixture::brute = nullptr;
std::vector<gi::Ray>* SoupFixture::rays = nullptr;
std::vector<Expect>* SoupFixture::expect = nullptr;
std::vector<gi::Hit>* SoupFixture::refHits = nullptr;

TEST_F(SoupFixture, FixtureIsMeaningful) {
  const auto rep = gi::analyzeScene(*scene);
  EXPECT_EQ(rep.usableFaces(), 300u);
  EXPECT_EQ(rep.faces, 350u);  // 50 unusable faces, 10 of each kind
  EXPECT_EQ(rep.degenerateFaces, 10u);
  EXPECT_EQ(rep.invalidFaces, 20u);
  EXPECT_EQ(rep.facesOnNonFinite, 20u);
  size_t amb = 0, hits = 0;
  for (size_t i = 0; i < rays->size(); ++i) {
    amb += (*expect)[i].ambiguous;
    hits += (*expect)[i].face != gi::kNoHit;
  }
  RecordProperty("rays", std::to_string(rays->size()));
  RecordProperty("ambiguous", std::to_string(amb));
  RecordProperty("hits", std::to_string(hits));
  // At least 10,000 base rays plus variants; < 2% ambiguous; > 30% hit.
  EXPECT_GE(rays->size(), 10000u * 2);
  EXPECT_LT(double(amb), 0.02 * double(rays->size())) << amb << " ambiguous of " << rays->size();
  EXPECT_GT(double(hits), 0.3 * double(rays->size()));
}

TEST_F(SoupFixture, BruteForceMatchesIndependentOracle) {
  // The oracle (classify) and the brute-force caster are separate codes: same
  // face and t (1e-6 relative: both double, t stored as float) on unambiguous rays.
  int bad = 0;
  for (size_t i = 0; i < rays->size(); ++i) {
    const Expect& e = (*expect)[i];
    if (e.ambiguous) continue;
    const gi::Hit& h = (*refHits)[i];
    if (h.face != e.face || (h.valid() && std::fabs(h.t - e.t) > 1e-6 * std::max(1e-3, e.t))) {
      if (++bad < 5) ADD_FAILURE() << "ray " << i << " " << rayStr((*rays)[i]) << ": brute " << h.face << " oracle " << e.face;
    }
    if (!h.valid()) {
      EXPECT_EQ(h.t, kInf);
    }
  }
  EXPECT_EQ(bad, 0);
}

TEST_F(SoupFixture, EmbreeAgreesWithBruteForce) {
  for (gi::BatchMode mode : kModes) {
    SCOPED_TRACE(modeName(mode));
    auto emb = gi::makeEmbreeCaster(*scene, mode);
    const size_t n = rays->size();
    std::vector<gi::Hit> batchHits(n);
    emb->intersectBatch(rays->data(), n, batchHits.data());
    int bad = 0;
    for (size_t i = 0; i < n; ++i) {
      if ((*expect)[i].ambiguous) continue;
      const gi::Ray& r = (*rays)[i];
      const gi::Hit e = emb->intersect(r), &b = (*refHits)[i];
      bool ok = e.face == b.face;
      if (ok && b.valid()) {
        ok = std::fabs(double(e.t) - double(b.t)) <= kRelT * std::max(1e-3, double(b.t)) &&
             std::fabs(e.u - b.u) < 1e-3f && std::fabs(e.v - b.v) < 1e-3f &&
             glm::dot(glm::normalize(e.ng), glm::normalize(b.ng)) > 0.9999f;
      }
      if (!ok && ++bad <= 5)
        ADD_FAILURE() << "ray " << i << " " << rayStr(r) << ": embree face " << e.face << " t " << e.t << " uv " << e.u
                      << "," << e.v << "; brute face " << b.face << " t " << b.t << " uv " << b.u << "," << b.v;
      const gi::Hit& bh = batchHits[i];
      if (bh.face != e.face || bh.t != e.t) ++bad;
    }
    EXPECT_EQ(bad, 0);
  }
}

TEST_F(SoupFixture, OcclusionAgreesWithIntersection) {
  // occluded(), occludedBatch() (n = all rays, not a multiple of 8 or 64) and
  // the brute-force occlusion agree with intersect() on unambiguous rays.
  const size_t n = rays->size();
  ASSERT_NE(n % 8, 0u) << "make the ray count leave a partial packet";
  for (gi::BatchMode mode : kModes) {
    SCOPED_TRACE(modeName(mode));
    auto emb = gi::makeEmbreeCaster(*scene, mode);
    std::vector<uint8_t> occ(n, 7);
    emb->occludedBatch(rays->data(), n, occ.data());
    int bad = 0, occludedCount = 0;
    for (size_t i = 0; i < n; ++i) {
      ASSERT_TRUE(occ[i] == 0 || occ[i] == 1) << i;
      if ((*expect)[i].ambiguous) continue;
      const gi::Ray& r = (*rays)[i];
      const bool want = (*refHits)[i].valid();
      occludedCount += want;
      const bool single = emb->occluded(r), viaHit = emb->intersect(r).valid(), bf = brute->occluded(r);
      if (single != want || viaHit != want || bf != want || bool(occ[i]) != want) {
        if (++bad <= 5)
          ADD_FAILURE() << "ray " << i << " " << rayStr(r) << ": expected " << want << ", occluded " << single
                        << ", intersect " << viaHit << ", batch " << int(occ[i]) << ", brute " << bf;
      }
    }
    EXPECT_EQ(bad, 0);
    EXPECT_GT(occludedCount, 1000);
    // Small batches: 0, 1, 7, 9, 63, 65 rays starting at an odd offset.
    for (size_t m : {0u, 1u, 7u, 9u, 63u, 65u}) {
      std::vector<uint8_t> o(m + 1, 9);
      emb->occludedBatch(rays->data() + 3, m, o.data());
      for (size_t i = 0; i < m; ++i) {
        if (!(*expect)[i + 3].ambiguous) {
          EXPECT_EQ(bool(o[i]), (*refHits)[i + 3].valid()) << "m " << m << " i " << i;
        }
      }
      EXPECT_EQ(o[m], 9) << "occludedBatch wrote past n = " << m;
    }
  }
}

TEST_F(SoupFixture, TnearAndTfarLimits) {
  // Targeted checks of the limit variants: a base hit at t is not occluded
  // with tfar = 0.5 t, occluded with tfar = 1.01 t, and with tnear = 1.001 t the
  // nearest hit is beyond tnear (unambiguous rays only).
  auto emb = gi::makeEmbreeCaster(*scene, gi::BatchMode::Packet8);
  int checked = 0;
  for (size_t i = 0; i < rays->size(); ++i) {
    const gi::Ray& r = (*rays)[i];
    if ((*expect)[i].ambiguous) continue;
    const gi::Hit h = emb->intersect(r);
    if (h.valid()) {
      EXPECT_GT(h.t, r.tnear) << i;
      EXPECT_LT(h.t, r.tfar) << i;
      ++checked;
    }
  }
  EXPECT_GT(checked, 5000);
  // A single quad in z = 0 hit from z = 1 at t = 1.
  gi::Scene q;
  q.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  q.triangles = {{0, 1, 2}, {0, 2, 3}};
  for (gi::BatchMode mode : kModes) {
    auto c = gi::makeEmbreeCaster(q, mode);
    auto bf = gi::makeBruteForceCaster(q);
    for (const gi::RayCaster* rc : {c.get(), bf.get()}) {
      gi::Ray r;
      r.o = {0.1f, 0.3f, 1.f};
      r.d = {0, 0, -1};
      EXPECT_NEAR(rc->intersect(r).t, 1.f, 1e-6f);
      r.tfar = 0.999f; EXPECT_FALSE(rc->occluded(r)); EXPECT_FALSE(rc->intersect(r).valid());
      r.tfar = 1.001f; EXPECT_TRUE(rc->occluded(r)); EXPECT_TRUE(rc->intersect(r).valid());
      r.tnear = 1.001f; r.tfar = kInf; EXPECT_FALSE(rc->occluded(r)); EXPECT_FALSE(rc->intersect(r).valid());
      r.tnear = 0.5f; EXPECT_TRUE(rc->occluded(r));
      r.d = {0, 0, 1}; r.tnear = 0.f; EXPECT_FALSE(rc->occluded(r));  // pointing away
      // Back face: hits are two-sided.
      r.o = {0.1f, 0.3f, -2.f}; EXPECT_NEAR(rc->intersect(r).t, 2.f, 1e-6f);
      uint8_t o[3];
      gi::Ray rs[3] = {r, r, r};
      rs[1].tfar = 1.f; rs[2].tnear = 3.f;
      rc->occludedBatch(rs, 3, o);
      EXPECT_EQ(o[0], 1); EXPECT_EQ(o[1], 0); EXPECT_EQ(o[2], 0);
    }
  }
}

TEST_F(SoupFixture, ConcurrentQueriesMatchSerial) {
  // tbb::parallel_for with grain 64 over all rays: intersect, occluded and
  // occludedBatch (chunks of 256 rays, the same chunks as the serial run, so
  // packets are identical) are bit-identical to the serial results.
  const size_t n = rays->size(), chunk = 256;
  for (gi::BatchMode mode : kModes) {
    SCOPED_TRACE(modeName(mode));
    auto emb = gi::makeEmbreeCaster(*scene, mode);
    std::vector<gi::Hit> sh(n), ph(n);
    std::vector<uint8_t> so(n), po(n), sb(n), pb(n);
    for (size_t i = 0; i < n; ++i) { sh[i] = emb->intersect((*rays)[i]); so[i] = emb->occluded((*rays)[i]); }
    for (size_t b = 0; b < n; b += chunk) emb->occludedBatch(rays->data() + b, std::min(chunk, n - b), sb.data() + b);
    for (int rep = 0; rep < 2; ++rep) {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 64), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) { ph[i] = emb->intersect((*rays)[i]); po[i] = emb->occluded((*rays)[i]); }
      });
      tbb::parallel_for(size_t(0), (n + chunk - 1) / chunk, [&](size_t c) {
        const size_t b = c * chunk;
        emb->occludedBatch(rays->data() + b, std::min(chunk, n - b), pb.data() + b);
      });
      int bad = 0;
      for (size_t i = 0; i < n; ++i)
        bad += ph[i].face != sh[i].face || ph[i].t != sh[i].t || ph[i].u != sh[i].u || ph[i].v != sh[i].v ||
               po[i] != so[i] || pb[i] != sb[i];
      EXPECT_EQ(bad, 0) << "repetition " << rep;
    }
  }
}

void expectNoHits(const gi::Scene& s, const char* what) {
  SCOPED_TRACE(what);
  const auto rays = randomRays(5, 1000);  // 1000 rays
  std::vector<std::unique_ptr<gi::RayCaster>> casters;
  casters.push_back(gi::makeBruteForceCaster(s));
  for (gi::BatchMode m : kModes) casters.push_back(gi::makeEmbreeCaster(s, m));
  for (const auto& c : casters) {
    std::vector<uint8_t> occ(rays.size(), 1);
    c->occludedBatch(rays.data(), rays.size(), occ.data());
    for (size_t i = 0; i < rays.size(); ++i) {
      const gi::Hit h = c->intersect(rays[i]);
      ASSERT_FALSE(h.valid()) << i;
      ASSERT_EQ(h.t, kInf);
      ASSERT_FALSE(c->occluded(rays[i]));
      ASSERT_EQ(occ[i], 0);
    }
  }
}

TEST(RayCaster, ScenesWithoutUsableFacesGiveNoHits) {
  expectNoHits(gi::Scene{}, "empty scene");
  gi::Scene pts;
  pts.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  expectNoHits(pts, "vertices only");
  gi::Scene bad;
  bad.positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}, {kNaN, 0, 0}, {3, -1, 0}, {0, 0, kInf}};
  // NaN vertex, repeated index, collinear, index out of range, Inf vertex.
  bad.triangles = {{0, 1, 3}, {0, 0, 1}, {0, 1, 4}, {0, 1, 99}, {5, 1, 2}};
  ASSERT_EQ(gi::analyzeScene(bad).usableFaces(), 0u);
  expectNoHits(bad, "only unusable faces");
}

TEST(RayCaster, UnusableFacesAreExcludedAndIndicesKept) {
  // Faces 0..5 are unusable and lie across the paths of the rays; faces 6 and 7
  // are the two usable ones (a square at z = 0 around (5, 0)), and face 8 a
  // triangle at z = 0 around the origin. Every ray from z = 10 straight down
  // must hit the z = 0 faces (t = 10 within 1e-5) and report their original
  // indices.
  const float tiny = 1e-13f;  // sliver height: area < 1e-12 * longest edge^2
  gi::Scene s;
  s.positions = {
      {4, -1, 5}, {6, -1, 5}, {6, 1, 5},        // 0-2: vertices of bad faces at z = 5
      {4, 0, 4},  {5, 0, 4},  {6, 0, 4},        // 3-5: collinear at z = 4
      {4, 0, 3},  {6, 0, 3},  {4.5f, tiny, 3},  // 6-8: sliver at z = 3
      {kNaN, 0, 2},                             // 9: NaN vertex
      {4, -1, 0}, {6, -1, 0}, {6, 1, 0}, {4, 1, 0},  // 10-13: square at z = 0
      {-1, -1, 0}, {1, -1, 0}, {0, 1, 0},       // 14-16: triangle at z = 0
      {5.8f, 0.6f, 5},                          // 17
  };
  s.triangles = {
      {0, 17, 0},   // 0: repeated index (segment from (4,-1,5) to (5.8,0.6,5))
      {3, 4, 5},    // 1: collinear, zero area
      {6, 7, 8},    // 2: sliver
      {0, 1, 9},    // 3: NaN vertex
      {0, 1, 77},   // 4: index out of range
      {2, 2, 2},    // 5: all the same
      {10, 11, 12}, // 6
      {10, 12, 13}, // 7
      {14, 15, 16}, // 8
  };
  const auto rep = gi::analyzeScene(s);
  EXPECT_EQ(rep.usableFaces(), 3u);
  std::vector<std::unique_ptr<gi::RayCaster>> casters;
  casters.push_back(gi::makeBruteForceCaster(s));
  for (gi::BatchMode m : kModes) casters.push_back(gi::makeEmbreeCaster(s, m));
  // Rays aimed exactly at the degenerate faces' locations: a point of the
  // collinear segment (5.2, 0, 4), the sliver's interior (4.6, tiny/2, 3), the
  // repeated-index face's segment (4.9, -0.2, 5), a point (4.5, -0.8) inside the
  // NaN face if its NaN vertex were read as (0, 0, 0), plus a 9 x 9 grid over
  // the square (off its diagonal, so that the face is 6 or 7 unambiguously).
  std::vector<glm::vec2> xy = {{5.2f, 0.f}, {4.6f, tiny * 0.5f}, {4.9f, -0.2f}, {4.5f, -0.8f}};
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) xy.push_back({4.1f + 0.225f * i, -0.85f + 0.225f * j});
  for (const auto& c : casters) {
    for (const auto& p : xy) {
      gi::Ray r;
      r.o = {p.x, p.y, 10.f};
      r.d = {0, 0, -1};
      const gi::Hit h = c->intersect(r);
      ASSERT_TRUE(h.valid()) << p.x << "," << p.y;
      EXPECT_TRUE(h.face == 6 || h.face == 7) << "face " << h.face << " at " << p.x << "," << p.y;
      EXPECT_NEAR(h.t, 10.f, 1e-5f);
      // The degenerate faces do not occlude a ray that stops above z = 0.
      r.tfar = 9.5f;
      EXPECT_FALSE(c->occluded(r)) << p.x << "," << p.y;
      uint8_t o = 1;
      c->occludedBatch(&r, 1, &o);
      EXPECT_EQ(o, 0);
    }
    gi::Ray r;
    r.o = {0.f, 0.f, 1.f};
    r.d = {0, 0, -1};
    const gi::Hit h = c->intersect(r);
    EXPECT_EQ(h.face, 8u);
    EXPECT_NEAR(h.t, 1.f, 1e-6f);
  }
}

}  // namespace

// A scene filled directly with world coordinates (not through
// Scene::fromAbsolute) so large that squared lengths overflow a float: the
// caster refuses it with a message, so no algorithm meets inf radii or
// light samples (found by the filters' fuzz target). A scene at the edge
// of the accepted range still builds.
TEST(RayCaster, RefusesCoordinatesBeyondLocalUnits) {
  gi::Scene s;
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1e30f, 0, 0}, {1e30f, 1, 0}, {1e30f, 0, 1}};
  s.triangles = {{0, 1, 2}, {3, 4, 5}};
  try {
    gi::makeEmbreeCaster(s);
    ADD_FAILURE() << "a scene at 1e30 local units was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("local units"), std::string::npos) << e.what();
  }
  for (auto& p : s.positions)
    if (p.x > 1.f) p.x = 1e12f;  // below 2^40
  const auto c = gi::makeEmbreeCaster(s);
  gi::Ray r;
  r.o = {0.25f, 0.25f, 1.f};
  r.d = {0, 0, -1};
  EXPECT_EQ(c->intersect(r).face, 0u);
}
