// The adaptive strata estimator of AO (core/include/gi/ao_strata.h): unbiased
// (the mean over many seeds against the per-vertex reference, on a grid
// small enough that most strata split), its reported standard errors
// covering its errors in the places where a split rule can miss an edge
// (the crease, the contact, the thin disc), the exact cases, determinism,
// the rounds to a target standard error (the target held everywhere, rays
// where the error is, max_rays, unbiased over seeds), and what it refuses.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "gi/ambient.h"
#include "gi/ao_strata.h"
#include "gi/scenes.h"
#include "ao_test_scene.h"
#include "test_helpers.h"

using namespace gi;

namespace {

using namespace gi::test;

AmbientOptions strata(int rays, uint32_t seed = 1) {
  AmbientOptions o;
  o.estimator = AOEstimator::Strata;
  o.raysPerVertex = rays;
  o.seed = seed;
  return o;
}

AmbientOptions strataTarget(double target, int minRays = 32, uint32_t seed = 1) {
  AmbientOptions o = strata(minRays, seed);
  o.targetError = target;
  o.minRays = minRays;
  return o;
}

// The mean over `seeds` runs of options(seed) against a 65,536-ray
// per-vertex reference: the mean of z^2 over the vertices (exact ones left
// out), z = (mean - reference) / sqrt(var/seeds + se_ref^2) with se_ref the
// reference's binomial bound (its Sobol points do better, so z is
// conservative), and the worst |z|.
template <class Options>
std::pair<double, double> meanZ2OverSeeds(const Scene& s, int seeds, Options&& options) {
  auto caster = makeEmbreeCaster(s, BatchMode::Single);
  AmbientOptions ro;
  ro.raysPerVertex = 65536;
  ro.seed = 99;
  const AmbientResult ref = computeAmbient(s, *caster, ro);
  const size_t nv = s.vertexCount();
  std::vector<double> sum(nv, 0.0), sumSq(nv, 0.0);
  for (int k = 0; k < seeds; ++k) {
    const AmbientResult a = computeAmbient(s, *caster, options(uint32_t(1000 + k)));
    for (size_t i = 0; i < nv; ++i) { sum[i] += a.value[i]; sumSq[i] += double(a.value[i]) * a.value[i]; }
  }
  double z2 = 0, worst = 0;
  size_t counted = 0;
  for (size_t i = 0; i < nv; ++i) {
    const double m = sum[i] / seeds, var = std::max(0.0, sumSq[i] / seeds - m * m) * seeds / (seeds - 1.0);
    const double d = m - double(ref.value[i]);
    const double v = var / seeds + double(ref.stdError[i]) * ref.stdError[i];
    if (v <= 0.0) { EXPECT_EQ(d, 0.0) << i; continue; }  // both exact (all rays open or all blocked)
    z2 += d * d / v;
    worst = std::max(worst, std::fabs(d) / std::sqrt(v));
    ++counted;
  }
  return {z2 / double(counted), worst};
}

// Over a region: the mean (error / reported standard error)^2 against the
// reference, the reference's own reported variance added to the
// denominator, and how many vertices it counts (both exact ones, proven
// open or closed, must agree exactly and are left out).
struct Cover {
  double meanZ2 = 0;
  size_t counted = 0;
};
Cover coverOf(const AmbientResult& a, const AmbientResult& ref, const std::vector<size_t>& region) {
  Cover c;
  for (size_t i : region) {
    const double d = double(a.value[i]) - double(ref.value[i]);
    const double v = double(a.stdError[i]) * a.stdError[i] + double(ref.stdError[i]) * ref.stdError[i];
    if (v == 0.0) { EXPECT_EQ(d, 0.0) << i; continue; }
    c.meanZ2 += d * d / v;
    ++c.counted;
  }
  if (c.counted) c.meanZ2 /= double(c.counted);
  return c;
}

}  // namespace

// Mean (error / reported standard error)^2 in every region of the test
// scene (ao_test_scene.h) at 32, 128 and 512 rays per vertex, the
// reference's own reported variance added to the denominator (at 2048 rays
// its binomial bound, up to 0.011, is of the size of the errors checked).
// The collapsed pairs bound each stratum's variance from above, so an honest
// estimate has E z^2 <= 1; the vertices are independent (each casts its own
// rays), so over 300+ of them the mean has a spread of about sqrt(2/300) =
// 0.08: 1.2 leaves room for the heavier tails of a split rule's misses.
// Measured: 0.04 to 0.40; without the floor of one stratum's variance the
// vertices where every pair agreed (nearly open ones) reached 4.2 on bunny_fine.
TEST(AOStrata, ReportedStandardErrorsCoverTheErrors) {
  const TestScene& t = scene();
  const AmbientResult& ref = reference(t.s);
  for (int n : {32, 128, 512}) {
    const AmbientResult a = run(t.s, strata(n));
    for (const Region& r : regions(t)) {
      const Cover c = coverOf(a, ref, r.v);
      ASSERT_GE(c.counted, 300u) << r.name;
      EXPECT_LE(c.meanZ2, 1.2) << r.name << ", " << n << " rays";
    }
  }
}

// Against the per-vertex estimator on the same scene: 128 strata (8 x 16,
// about 200 rays with the splits) reach a lower RMS error over all vertices
// than 256 scrambled Sobol rays, casting fewer rays (measured: 0.0045
// against 0.0057, the reference's own error included; bunny_fine, 29,394
// vertices: 0.00347 at 209 rays per vertex against 0.00492 at 241; the
// benchmark in bench/ao_bench.py measures the time).
TEST(AOStrata, LowerErrorThanPerVertexWithFewerRays) {
  const TestScene& t = scene();
  const AmbientResult& ref = reference(t.s);
  AmbientOptions pv;
  pv.raysPerVertex = 256;
  pv.seed = 1;
  const AmbientResult a = run(t.s, strata(128)), b = run(t.s, pv);
  const double ea = test::rms(a.value, ref.value), eb = test::rms(b.value, ref.value);
  RecordProperty("strata_rms", std::to_string(ea));
  RecordProperty("per_vertex_rms", std::to_string(eb));
  EXPECT_LT(ea, eb);
  EXPECT_LT(a.stats.get("rays"), b.stats.get("rays"));
}

// Unbiased: the mean over 512 seeds of the estimate with 8 strata (2 rows,
// 4 columns, where most strata have an occlusion edge near them and split)
// against the per-vertex estimator with 65,536 rays, on a floor by a wall
// (a straight occlusion edge at every floor vertex) and a bowl (a curved
// one). z = (mean - reference) / sqrt(var/512 + se_ref^2), se_ref the
// reference's binomial bound (its Sobol points do better, so z is
// conservative); the mean of z^2 over the vertices is about 1 or less for an
// unbiased estimator, its spread over 100+ vertices sqrt(2/100) = 0.14.
// Measured: 0.43 and 0.47 (worst |z| 2.7). The test has power: splitting
// only the strata whose own sample was blocked (a tempting rule: refine
// where occlusion was seen) gives 383 and 602.
TEST(AOStrata, UnbiasedOverSeeds) {
  for (const Scene& s : {scenes::floorWithWall(2.0, 1.0, 6).scene, scenes::hemisphericalBowl(1.0, 8).scene}) {
    const auto [z2, worst] = meanZ2OverSeeds(s, 512, [](uint32_t seed) { return strata(8, seed); });
    EXPECT_LT(z2, 1.5);
    EXPECT_LT(worst, 5.0);
  }
}

// Exact where every ray agrees: 0 inside a closed box (no leak at its
// edges), 1 on an open plane (with the open-vertex proof off, so the rays
// are cast), and the floor-by-a-wall values of test_ambient.cpp within the
// same tolerance at 1024 strata.
TEST(AOStrata, ExactAndAnalyticCases) {
  const Scene box = scenes::closedBox(1.0, 4, true).scene;
  for (float v : run(box, strata(64)).value) EXPECT_EQ(v, 0.f);
  AmbientOptions open = strata(72);
  open.skipOpenVertices = false;
  const AmbientResult p = run(scenes::openPlane(1.0, 8).scene, open);
  for (size_t i = 0; i < p.value.size(); ++i) {
    EXPECT_EQ(p.value[i], 1.f);
    EXPECT_GT(p.rays[i], 72);  // cast: the horizon row split against the tangent plane
  }
  auto sf = scenes::floorWithWall(4.0, 1.0, 20);
  const AmbientResult r = run(sf.scene, strata(1024));
  const auto n = computeVertexNormals(sf.scene);
  for (double d : {0.0, 0.2, 0.6, 1.0, 2.0, 3.0}) {
    const size_t v = test::nearestVertex(sf.scene, {d, 0.0, 0.0}, [&](size_t i) { return n[i].z > 0.99f; });
    const double x = sf.scene.toWorld(sf.scene.positions[v]).x;
    // H = 1; the wall's finite width biases it by < 0.005
    EXPECT_NEAR(r.value[v], wallAO(x, 1.0), 0.02) << "d = " << x;
  }
}

TEST(AOStrata, DeterministicAcrossThreadCountsAndSeeded) {
  const Scene s = scenes::hemisphericalBowl(1.0, 10).scene;
  AmbientResult one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = run(s, strata(128, 7));
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = run(s, strata(128, 7));
  }
  EXPECT_EQ(one.value, two.value);
  EXPECT_EQ(one.stdError, two.stdError);
  EXPECT_GT(test::rms(run(s, strata(128, 8)).value, one.value), 0.0);
}

// Bent normals: the open samples' directions weighted by their cells' areas
// lean away from the wall, as the per-vertex estimator's do.
TEST(AOStrata, BentNormalsLeanAwayFromTheWall) {
  auto sf = scenes::floorWithWall(2.0, 1.0, 8);
  AmbientOptions o = strata(512);
  o.bentNormals = true;
  const AmbientResult r = run(sf.scene, o);
  AmbientOptions pv = o;
  pv.estimator = AOEstimator::PerVertex;
  const AmbientResult q = run(sf.scene, pv);
  const auto n = computeVertexNormals(sf.scene);
  const size_t v = test::nearestVertex(sf.scene, {0.5, 0, 0}, [&](size_t i) { return n[i].z > 0.99f; });
  EXPECT_GT(r.bentNormal[v].x, 0.1f);
  EXPECT_NEAR(glm::length(r.bentNormal[v]), 1.f, 1e-4f);
  EXPECT_GT(glm::dot(r.bentNormal[v], q.bentNormal[v]), 0.999f);  // within 2.6 degrees
}

// To a target standard error (a pilot's rounds size the result's grid,
// gi/ao_strata.h), in every region of the test scene at targets 0.02 and
// 0.01: the pilot misreads some vertices, so the target holds at most of
// them, not all (the reported error over the target: median 0.78 and 0.55,
// 90th percentile 0.90 and 0.87, 99th 1.61 and 1.11; bounds 1, 1.25, 2);
// the mean (error / reported standard error)^2 is at most 1.2 as at fixed
// counts (the reference's variance in the denominator) and the RMS error is
// below the target. Measured: mean z^2 0.22 to 0.34 by region at 0.02, 0.12
// to 0.36 at 0.01 (with the rounds that stopped on their own estimate).
TEST(AOStrata, TargetHoldsEverywhereAgainstTheReference) {
  const TestScene& t = scene();
  const AmbientResult& ref = reference(t.s);
  for (double target : {0.02, 0.01}) {
    const AmbientResult a = run(t.s, strataTarget(target));
    std::vector<double> ratio;
    for (size_t i = 0; i < t.end; ++i)
      if (a.rays[i] > 0) ratio.push_back(a.stdError[i] / target);
    const test::OverTarget over = test::overTarget(ratio);
    EXPECT_LT(over.median, 1.0) << target;
    EXPECT_LT(over.p90, 1.25) << target;
    EXPECT_LT(over.p99, 2.0) << target;
    for (const Region& r : regions(t)) {
      double sq = 0;
      for (size_t i : r.v) sq += (double(a.value[i]) - ref.value[i]) * (double(a.value[i]) - ref.value[i]);
      const Cover c = coverOf(a, ref, r.v);
      ASSERT_GE(c.counted, 300u) << r.name;
      RecordProperty("z2_" + std::to_string(target) + "_" + r.name.substr(0, 12), std::to_string(c.meanZ2));
      EXPECT_LE(c.meanZ2, 1.2) << r.name << ", target " << target;
      EXPECT_LE(std::sqrt(sq / double(r.v.size())), target) << r.name << ", target " << target;
    }
  }
}

// The rounds: a target every vertex meets with its first grid gives the
// fixed grid's bits (round 0 is the fixed estimator with the same key);
// rays go where the error is (at 0.01 the crease's vertices cast more than
// twice the rays of the vertices whose AO is above 0.99, which stop after
// the second round as open ones do: measured 469 against 180); an open
// plane, its rays cast, gives exactly 1 with the rays the schedule predicts
// (the pilot: 4 x 8 strata and the horizon row's splits, 56 rays, a
// standard error of 1/64, within twice 0.01; so the result takes one round
// more: its own 4 x 8 strata, 56 rays, then 8 x 16, whose 128 strata keep
// those 56 rays and cast 72, and its horizon row's splits, 48: 176 rays,
// error 0.5/128; 232 in all, as strataRaysWhenOpen says); and
// max_rays bounds every vertex's rays, with a warning where the target is
// then missed.
TEST(AOStrata, TargetRoundsAdaptAndStayWithinMaxRays) {
  const TestScene& t = scene();
  EXPECT_EQ(run(t.s, strataTarget(0.5)).value, run(t.s, strata(32)).value);

  const AmbientResult a = run(t.s, strataTarget(0.01));
  const AmbientResult& ref = reference(t.s);
  const Region crease = regions(t)[0];
  double creaseRays = 0, openRays = 0;
  size_t nearlyOpen = 0;
  for (size_t i : crease.v) creaseRays += a.rays[i];
  creaseRays /= double(crease.v.size());
  for (size_t i = 0; i < t.end; ++i)
    if (a.rays[i] > 0 && ref.value[i] > 0.99f) { openRays += a.rays[i]; ++nearlyOpen; }
  ASSERT_GT(nearlyOpen, 100u);
  openRays /= double(nearlyOpen);
  RecordProperty("crease_rays", std::to_string(creaseRays));
  RecordProperty("nearly_open_rays", std::to_string(openRays));
  EXPECT_GT(creaseRays, 2.0 * openRays);

  AmbientOptions open = strataTarget(0.01);
  open.skipOpenVertices = false;
  const AmbientResult p = run(scenes::openPlane(1.0, 8).scene, open);
  for (size_t i = 0; i < p.value.size(); ++i) {
    EXPECT_EQ(p.value[i], 1.f);
    EXPECT_EQ(p.rays[i], 56 + 176);
    EXPECT_EQ(p.rays[i], strataRaysWhenOpen(StrataTarget{0.01, 32, 4096}));
    EXPECT_NEAR(p.stdError[i], 0.5 / 128.0, 1e-6);
  }

  AmbientOptions capped = strataTarget(0.001);
  capped.maxRays = 300;
  const AmbientResult c = run(t.s, capped);
  int most = 0;
  for (int r : c.rays) most = std::max(most, r);
  EXPECT_LE(most, 300);
  EXPECT_GT(most, 0);
  bool warned = false;
  for (const auto& w : c.stats.warnings) warned |= w.find("max_rays 300") != std::string::npos;
  EXPECT_TRUE(warned);
}

// Unbiased with rounds, up to the sequential stop: the mean over 512 seeds
// with a first grid of 8 strata and a target of 0.02, where vertices stop
// after one to three rounds, on the floor by a wall and the bowl as above
// (same bounds). Measured: mean z^2 0.16 and 0.24, the vertices casting 56
// to 323 and 89 to 335 rays. Subtle faults in the nesting stay below its
// bound (re-casting a split stratum's blocked own ray: 0.45 and 0.58), so
// the nesting has its own test below.
TEST(AOStrata, TargetRoundsUnbiasedOverSeeds) {
  for (const Scene& s : {scenes::floorWithWall(2.0, 1.0, 6).scene, scenes::hemisphericalBowl(1.0, 8).scene}) {
    const AmbientResult one = run(s, strataTarget(0.02, 8));
    const auto [fewest, most] = std::minmax_element(one.rays.begin(), one.rays.end());
    RecordProperty("rays_" + std::to_string(s.vertexCount()), std::to_string(*fewest) + " to " + std::to_string(*most));
    EXPECT_GE(*most, 2 * *fewest);  // the vertices stop after different rounds
    const auto [z2, worst] = meanZ2OverSeeds(s, 512, [](uint32_t seed) { return strataTarget(0.02, 8, seed); });
    RecordProperty("z2_" + std::to_string(s.vertexCount()), std::to_string(z2));
    EXPECT_LT(z2, 1.5);
    EXPECT_LT(worst, 5.0);
  }
}

// The rounds' grids nest: after each refinement every stratum's base ray
// lies inside that stratum (its x = sin^2 theta within the row's bounds,
// its azimuth within the column's, in the vertex's frame), whether it was
// cast for it or kept from the coarser grid, and the kept ones are a share
// of them (a quarter of the strata at least: every coarser stratum's own
// ray). A vertex on the floor beside the wall, whose rounds run from 8 to
// 128 strata (target 1e-4, max_rays stopping it after 1, 2 and 3 rounds),
// through the public per-vertex entry point.
TEST(AOStrata, RefinedGridsKeepEachRayInItsStratum) {
  const Scene s = scenes::floorWithWall(2.0, 1.0, 6).scene;
  auto caster = makeEmbreeCaster(s, BatchMode::Single);
  const glm::vec3 n(0.f, 0.f, 1.f), org = glm::vec3((glm::dvec3(0.3, 0.0, 1e-4) - s.origin) / s.unit);
  const Frame frame(n);
  for (int rounds : {1, 2, 3}) {
    StrataTarget t;
    t.target = 1e-4;
    t.minRays = 8;
    t.maxRays = rounds == 1 ? 64 : rounds == 2 ? 600 : 2000;  // the next round would not fit
    const StrataEstimate e = strataOcclusionToTarget(*caster, 77u, org, frame, std::numeric_limits<float>::infinity(), t);
    const StrataGridView g = lastStrataGrid();
    EXPECT_EQ(g.rows * g.cols, 8 << (2 * (rounds - 1))) << rounds << " rounds";
    ASSERT_EQ(g.dirs.size(), size_t(g.rows * g.cols));
    size_t kept = 0;
    for (int c = 0; c < g.rows * g.cols; ++c) {
      const int i = c / g.cols, j = c % g.cols;
      const glm::vec3 d = g.dirs[size_t(c)];
      const double z = glm::dot(d, frame.n), x = 1.0 - z * z;
      double y = std::atan2(double(glm::dot(d, frame.b)), double(glm::dot(d, frame.t))) / (2.0 * M_PI);
      if (y < 0.0) y += 1.0;
      EXPECT_GE(x, g.rowX[size_t(i)] - 1e-5) << c;
      EXPECT_LE(x, g.rowX[size_t(i) + 1] + 1e-5) << c;
      const double y0 = double(j) / g.cols, y1 = double(j + 1) / g.cols;
      EXPECT_TRUE((y >= y0 - 1e-5 && y <= y1 + 1e-5) || (j == 0 && y >= 1.0 - 1e-5)) << c << ": " << y;
      kept += g.kept[size_t(c)];
    }
    if (rounds == 1) EXPECT_EQ(kept, 0u);
    else EXPECT_GE(4 * kept, g.dirs.size());
    EXPECT_GT(e.rays, 0);
  }
}

// What it cannot estimate is refused with one line: obscurance (it needs
// hit distances, not a visible/blocked test) and, to a target, a max_rays
// that its first round could pass (rounds never pass it); the cone's ratio estimator
// stays per vertex, said in a note, with the per-vertex bits.
TEST(AOStrata, RefusesWhatItCannotEstimate) {
  const Scene s = scenes::floorWithWall(2.0, 1.0, 4).scene;
  auto caster = makeEmbreeCaster(s);
  AmbientOptions o = strata(64);
  o.mode = AmbientMode::Obscurance;
  o.maxDistance = 0.5;
  EXPECT_THROW(computeAmbient(s, *caster, o), std::invalid_argument);
  o = strataTarget(0.01);
  o.maxRays = 255;  // the first round, 4 x 8 strata, cast twice, may cast 256 with every stratum split
  try {
    computeAmbient(s, *caster, o);
    ADD_FAILURE() << "a max_rays below the first round's worst case was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("above max_rays 255"), std::string::npos) << e.what();
  }
  o.maxRays = 256;
  EXPECT_NO_THROW(computeAmbient(s, *caster, o));
  o = strata(64);
  o.useCone = true;
  const AmbientResult c = computeAmbient(s, *caster, o);
  o.estimator = AOEstimator::PerVertex;
  EXPECT_EQ(c.value, computeAmbient(s, *caster, o).value);
  bool noted = false;
  for (const auto& note : c.stats.notes) noted |= note.find("adaptive strata") != std::string::npos;
  EXPECT_TRUE(noted);
}
