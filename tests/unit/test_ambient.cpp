// Ambient occlusion, obscurance and sky lighting against the analytic values
// of docs/design.md, "Analytic references", plus convergence, determinism, skipping and stress cases.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gi/ambient.h"
#include "gi/form_factor_analytic.h"
#include "gi/open_space.h"
#include "gi/scenes.h"
#include "ao_test_scene.h"
#include "mesh_io.h"
#include "test_helpers.h"

using namespace gi;
using gi::test::wallAO;

namespace {

AmbientResult runAO(const Scene& s, int rays, double maxDist = 0.0, uint32_t seed = 0,
                    BatchMode batch = BatchMode::Packet8) {
  auto caster = makeEmbreeCaster(s, batch);
  AmbientOptions o;
  o.raysPerVertex = rays;
  o.maxDistance = maxDist;
  o.seed = seed;
  o.batch = batch;
  return computeAmbient(s, *caster, o);
}


}  // namespace

// 4096 rays per vertex: standard error <= 0.5/64 = 0.008; tolerance 0.02
// (2.5 sigma plus < 0.005 bias from the wall's finite width of 20 H).
TEST(AmbientOcclusion, FloorNearWallMatchesAnalytic) {
  auto sf = scenes::floorWithWall(4.0, 1.0, 20);
  const Scene& s = sf.scene;
  AmbientResult r = runAO(s, 4096);
  for (double d : {0.2, 0.6, 1.0, 2.0, 3.0}) {
    // Floor vertex at (d, 0, 0) whose normal is +z (not the wall's).
    const size_t v = test::nearestVertex(s, {d, 0.0, 0.0}, [&](size_t i) {
      return computeVertexNormals(s)[i].z > 0.99f;
    });
    const double x = s.toWorld(s.positions[v]).x;
    EXPECT_NEAR(r.value[v], wallAO(x, 1.0), 0.02) << "d = " << x;
  }
}

// Crease vertex shared by floor and wall cannot exist here (separate grids),
// so the crease value 0.5 is checked on the floor vertex at d = 0.
TEST(AmbientOcclusion, CreaseIsHalf) {
  auto sf = scenes::floorWithWall(4.0, 1.0, 20);
  const Scene& s = sf.scene;
  const auto n = computeVertexNormals(s);
  AmbientResult r = runAO(s, 4096);
  const size_t v = test::nearestVertex(s, {0, 0, 0}, [&](size_t i) { return n[i].z > 0.99f; });
  EXPECT_NEAR(r.value[v], 0.5, 0.02);  // 4096 rays, sigma 0.008
}

TEST(AmbientOcclusion, OpenPlaneIsOne) {
  auto sf = scenes::openPlane(1.0, 8);
  AmbientResult r = runAO(sf.scene, 64);
  for (float v : r.value) EXPECT_EQ(v, 1.f);  // no geometry above: exact
}

TEST(AmbientOcclusion, InsideClosedBoxIsZero) {
  auto sf = scenes::closedBox(1.0, 4, true);
  AmbientResult r = runAO(sf.scene, 256);
  for (float v : r.value) EXPECT_EQ(v, 0.f);  // every ray hits a wall: exact, no leaks at edges
}

// Bottom of a hemispherical bowl: 0.5. 4096 rays: sigma 0.008, tolerance 0.025
// (the polygonal bowl of 16 rings deviates slightly from the sphere).
TEST(AmbientOcclusion, BowlBottomIsHalf) {
  auto sf = scenes::hemisphericalBowl(1.0, 16);
  AmbientResult r = runAO(sf.scene, 4096);
  const size_t v = test::nearestVertex(sf.scene, {0, 0, -1});
  EXPECT_NEAR(r.value[v], 0.5, 0.025);
}

// Bottom centre of a cylindrical hole, radius a and depth h: a^2 / (a^2 + h^2).
TEST(AmbientOcclusion, CylinderHoleBottom) {
  for (double h : {0.5, 1.0, 2.0}) {
    auto sf = scenes::cylindricalHole(1.0, h, 12);
    AmbientResult r = runAO(sf.scene, 4096);
    const size_t v = test::nearestVertex(sf.scene, {0, 0, -h});
    EXPECT_NEAR(r.value[v], 1.0 / (1.0 + h * h), 0.02) << "h = " << h;  // sigma <= 0.008
  }
}

// The statistical tests above can fail: a wrong estimator (uniform instead of
// cosine weighting) is off by far more than the tolerance at the crease point
// at d = 1 (uniform-weighted value 0.75 - atan-term differs by > 0.05).
TEST(AmbientOcclusion, ToleranceRejectsWrongAnswer) {
  auto sf = scenes::floorWithWall(4.0, 1.0, 20);
  AmbientResult r = runAO(sf.scene, 4096);
  const auto n = computeVertexNormals(sf.scene);
  const size_t v = test::nearestVertex(sf.scene, {1.0, 0, 0}, [&](size_t i) { return n[i].z > 0.99f; });
  EXPECT_GT(std::fabs(r.value[v] - 0.75), 0.05);  // 0.75 = value for an H = 0 "wall": would be wrong
}

// RMS error against a 16384-ray reference falls at least as N^-0.6 (plain
// Monte Carlo: N^-0.5; scrambled Sobol: about N^-0.75) between 16 and 1024 rays.
TEST(AmbientOcclusion, ConvergesFasterThanMonteCarlo) {
  auto sf = scenes::floorWithWall(2.0, 1.0, 8);
  const Scene& s = sf.scene;
  const AmbientResult ref = runAO(s, 16384, 0.0, 99);
  std::vector<double> logN, logE;
  for (int n : {16, 64, 256, 1024}) {
    double e2 = 0;
    const int seeds = 4;
    for (int seed = 1; seed <= seeds; ++seed) {
      const double e = test::rms(runAO(s, n, 0.0, uint32_t(seed)).value, ref.value);
      e2 += e * e;
    }
    logN.push_back(std::log(double(n)));
    logE.push_back(0.5 * std::log(e2 / seeds));
  }
  double mx = 0, my = 0;
  for (size_t i = 0; i < logN.size(); ++i) { mx += logN[i]; my += logE[i]; }
  mx /= logN.size(); my /= logN.size();
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < logN.size(); ++i) { sxy += (logN[i] - mx) * (logE[i] - my); sxx += (logN[i] - mx) * (logN[i] - mx); }
  const double slope = sxy / sxx;
  RecordProperty("slope", std::to_string(slope));
  EXPECT_LT(slope, -0.6);
}

TEST(AmbientOcclusion, DeterministicAcrossThreadCounts) {
  auto sf = scenes::floorWithWall(2.0, 1.0, 10);
  AmbientResult one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = runAO(sf.scene, 128, 0.0, 7);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = runAO(sf.scene, 128, 0.0, 7);
  }
  ASSERT_EQ(one.value.size(), two.value.size());
  for (size_t i = 0; i < one.value.size(); ++i) ASSERT_EQ(one.value[i], two.value[i]) << i;
  // Another seed gives another (equally valid) answer.
  EXPECT_GT(test::rms(runAO(sf.scene, 128, 0.0, 8).value, one.value), 0.0);
}

TEST(AmbientOcclusion, BatchModesGiveIdenticalResults) {
  auto sf = scenes::hemisphericalBowl(1.0, 6);
  const auto a = runAO(sf.scene, 64, 0.0, 3, BatchMode::Single);
  const auto b = runAO(sf.scene, 64, 0.0, 3, BatchMode::Packet8);
  const auto c = runAO(sf.scene, 64, 0.0, 3, BatchMode::Stream);
  EXPECT_EQ(a.value, b.value);
  EXPECT_EQ(a.value, c.value);
}

// Adaptive sampling to a target standard error of 0.01: a pilot left out of
// the result sizes each vertex's count (gi/sampling.h), so the target holds
// at most vertices (measured: the reported error over the target has a
// median of 0.89, a 90th percentile of 0.92; bounds 1 and 1.25); the true
// RMS error (against 16,384 rays) stays below 0.015 (measured 0.0017; 0.0020
// when the rounds stopped on their own estimate, at 1,697 rays a vertex
// where the pilot and the count cast 2,537) and fewer rays are cast than at
// the fixed maximum.
TEST(AmbientOcclusion, AdaptiveMeetsTargetError) {
  auto sf = scenes::floorWithWall(2.0, 1.0, 8);
  auto caster = makeEmbreeCaster(sf.scene);
  AmbientOptions o;
  o.targetError = 0.01;
  o.minRays = 32;
  o.maxRays = 4096;
  const AmbientResult r = computeAmbient(sf.scene, *caster, o);
  const AmbientResult ref = runAO(sf.scene, 16384, 0.0, 99);
  std::printf("RMS error %.5f with %.1f rays a vertex\n", test::rms(r.value, ref.value),
              r.stats.get("rays") / double(sf.scene.vertexCount()));
  EXPECT_LT(test::rms(r.value, ref.value), 0.015);
  EXPECT_LT(r.stats.get("rays"), 0.75 * 4096.0 * double(sf.scene.vertexCount()));
  std::vector<double> ratio;
  for (size_t i = 0; i < r.value.size(); ++i)
    if (r.rays[i] > 0) ratio.push_back(r.stdError[i] / 0.01);
  const test::OverTarget over = test::overTarget(ratio);
  EXPECT_LT(over.median, 1.0);
  EXPECT_LT(over.p90, 1.25);
}

// With a finite max distance, vertices with nothing above them within reach are
// proved open and skipped; the result equals the traced one exactly.
TEST(AmbientOcclusion, SkipsProvablyOpenVertices) {
  auto sf = scenes::floorWithWall(4.0, 1.0, 20);
  auto caster = makeEmbreeCaster(sf.scene);
  AmbientOptions o;
  o.raysPerVertex = 64;
  o.maxDistance = 0.5;
  const AmbientResult skipped = computeAmbient(sf.scene, *caster, o);
  o.skipOpenVertices = false;
  const AmbientResult traced = computeAmbient(sf.scene, *caster, o);
  EXPECT_GT(skipped.stats.get("skipped_open"), 0.5 * double(sf.scene.vertexCount()));
  EXPECT_EQ(skipped.value, traced.value);
  EXPECT_LT(skipped.stats.get("rays"), traced.stats.get("rays"));
}

TEST(AmbientOcclusion, DuplicateVerticesComputedOnce) {
  auto sf = scenes::openPlane(1.0, 4);
  Scene s = sf.scene;
  s.append(sf.scene);  // the same plane twice: every vertex duplicated
  const AmbientResult r = runAO(s, 32);
  EXPECT_EQ(r.stats.get("skipped_duplicates"), double(sf.scene.vertexCount()));
}

// Scale and offset invariance: 1e-6, 1e6 and an offset of 1e6 give the same AO.
TEST(AmbientOcclusionStress, ScaleAndOffsetInvariant) {
  auto sf = scenes::floorWithWall(2.0, 1.0, 8);
  const AmbientResult base = runAO(sf.scene, 256);
  for (auto [scale, off] : {std::pair{1e-6, 0.0}, std::pair{1e6, 0.0}, std::pair{1.0, 1e6}, std::pair{1e3, 1e6}}) {
    const Scene t = test::transformed(sf.scene, scale, glm::dvec3(off, -off, off));
    const AmbientResult r = runAO(t, 256);
    EXPECT_LT(test::rms(r.value, base.value), 0.01) << "scale " << scale << " offset " << off;
  }
}

// A vertex no face uses, far away (1e5 from a scene of size 2, as a stray
// point left in a scan), moves nothing: the local frame, the scene's scale
// and ray offset and every AO value are those of the scene without it, bit
// for bit. (It made the diagonal 173,000 and the ray offsets 1.7: every value
// 1; and the local frame's centre 5e4 away, so positions lost their float
// precision.)
TEST(AmbientOcclusionStress, FarUnusedVertexChangesNothing) {
  const auto sf = scenes::floorWithWall(2.0, 0.5, 10);
  std::vector<glm::dvec3> pts;
  for (const auto& p : sf.scene.positions) pts.push_back(sf.scene.toWorld(p));
  const Scene plain = Scene::fromAbsolute(pts, sf.scene.triangles);
  pts.push_back(glm::dvec3(1e5));
  const Scene stray = Scene::fromAbsolute(pts, sf.scene.triangles);
  EXPECT_EQ(stray.origin, plain.origin);
  EXPECT_EQ(stray.unit, plain.unit);
  EXPECT_EQ(sceneScale(stray).rayEpsilon, sceneScale(plain).rayEpsilon);
  EXPECT_EQ(sceneDiagonal(stray), sceneDiagonal(plain));
  const AmbientResult a = runAO(plain, 64), b = runAO(stray, 64);
  ASSERT_EQ(b.value.size(), a.value.size() + 1);
  for (size_t i = 0; i < a.value.size(); ++i) ASSERT_EQ(b.value[i], a.value[i]) << "vertex " << i;
  // Appended as a part of its own: the union's frame is still the surface's.
  Scene joined = plain;
  joined.append(Scene::fromAbsolute({glm::dvec3(1e5), glm::dvec3(-1e5)}, {}));
  EXPECT_EQ(joined.unit, plain.unit);
  EXPECT_EQ(sceneScale(joined).rayEpsilon, sceneScale(plain).rayEpsilon);
  // One at the other end of the float range from the faces (the readers'
  // fuzzer found its offset overflowing float): the frame of all the
  // vertices, as before, every position finite.
  const Scene edge = Scene::fromAbsolute({{-3e38, 0, 0}, {-3e38, 1, 0}, {-3e38, 0, 1}, {3e38, 0, 0}}, {{0, 1, 2}});
  for (const auto& p : edge.positions) EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
}

TEST(AmbientOcclusionStress, BadGeometryNeverGivesNaN) {
  auto sf = scenes::floorWithWall(2.0, 1.0, 4);
  Scene s = sf.scene;
  const size_t nv = s.vertexCount();
  s.positions.push_back({NAN, 0.f, 0.f});           // NaN vertex used by a face
  s.positions.push_back({0.f, 0.f, 5.f});           // isolated vertex
  s.triangles.push_back({0u, 1u, uint32_t(nv)});
  s.triangles.push_back({0u, 0u, 1u});              // repeated index
  s.triangles.push_back({0u, 1u, 999999u});         // out of range
  s.triangles.push_back({2u, 2u, 2u});
  if (!s.rho.empty()) s.rho.resize(s.faceCount(), glm::vec3(0.5f));  // per-face arrays: one per face
  if (!s.emission.empty()) s.emission.resize(s.faceCount(), glm::vec3(0.f));
  const AmbientResult r = runAO(s, 64);
  for (float v : r.value) { ASSERT_TRUE(std::isfinite(v)); ASSERT_GE(v, 0.f); ASSERT_LE(v, 1.f); }
  EXPECT_EQ(r.stats.get("skipped_invalid"), 2.0);  // the NaN and the isolated vertex
}

TEST(AmbientOcclusionStress, NoFacesIsAClearError) {
  Scene s;
  s.positions = {{0, 0, 0}, {1, 0, 0}};
  auto caster = makeEmbreeCaster(s);
  try {
    computeAmbient(s, *caster, AmbientOptions{});
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no usable triangles"), std::string::npos);
  }
}

// Flipping every face turns the floor and wall away from each other: nothing
// is above any vertex any more, so AO is exactly 1.
TEST(AmbientOcclusionStress, FlippedNormals) {
  auto sf = scenes::floorWithWall(2.0, 1.0, 6);
  Scene s = sf.scene;
  for (auto& t : s.triangles) std::swap(t.y, t.z);
  const AmbientResult r = runAO(s, 128);
  for (float v : r.value) EXPECT_EQ(v, 1.f);
}

TEST(AmbientObscurance, BoundsAndFalloff) {
  auto sf = scenes::floorWithWall(4.0, 1.0, 20);
  auto caster = makeEmbreeCaster(sf.scene);
  AmbientOptions o;
  o.raysPerVertex = 256;
  o.maxDistance = 1.0;
  const AmbientResult ao = computeAmbient(sf.scene, *caster, o);
  o.mode = AmbientMode::Obscurance;
  const AmbientResult ob = computeAmbient(sf.scene, *caster, o);
  double diff = 0;
  for (size_t i = 0; i < ao.value.size(); ++i) {
    EXPECT_GE(ob.value[i] + 1e-6f, ao.value[i]);  // rho(d) >= 0: never darker than AO
    EXPECT_LE(ob.value[i], 1.f);
    diff += ob.value[i] - ao.value[i];
  }
  EXPECT_GT(diff, 0.0);  // and strictly lighter somewhere
  // A vertex farther than d_max from every other surface is fully open.
  const auto n = computeVertexNormals(sf.scene);
  const size_t far = test::nearestVertex(sf.scene, {3.0, 0, 0}, [&](size_t i) { return n[i].z > 0.99f; });
  EXPECT_EQ(ob.value[far], 1.f);
  o.maxDistance = 0.0;
  EXPECT_THROW(computeAmbient(sf.scene, *caster, o), std::invalid_argument);
}

// Obscurance at the foot of a wall is 0.5 for any falloff: every ray towards
// the wall meets it at distance 0 (rho = 0), every other ray escapes. The
// distances were measured from the rays' origin, lifted off the floor and
// pulled away from the wall's edge: the wall lay about 1e-5 of the diagonal
// away, and (t / d_max)^k turned that into a weight near 0.5 at k = 0.1 (an
// outside audit: 0.76 for 0.5). Now from the vertex, for every estimator.
// 4096 rays, sigma 0.008; tolerance 0.025.
TEST(AmbientObscurance, WallFootIsHalfForAnyFalloff) {
  auto sf = scenes::floorWithWall(4.0, 1.0, 20);
  const Scene& s = sf.scene;
  const auto n = computeVertexNormals(s);
  const size_t v = test::nearestVertex(s, {0, 0, 0}, [&](size_t i) { return n[i].z > 0.99f; });
  const size_t near = test::nearestVertex(s, {0.5, 0, 0}, [&](size_t i) { return n[i].z > 0.99f; });
  auto caster = makeEmbreeCaster(s);
  for (const AOEstimator e : {AOEstimator::PerVertex, AOEstimator::Shared}) {
    AmbientOptions o;
    o.mode = AmbientMode::Obscurance;
    o.estimator = e;
    o.raysPerVertex = 4096;
    o.maxDistance = 2.0;
    o.falloffExponent = 0.1f;
    const AmbientResult r = computeAmbient(s, *caster, o);
    EXPECT_NEAR(r.value[v], 0.5, 0.025) << kAOEstimators.logName(e);
    // Half a unit from the wall the same falloff is far from 0.5 and from 1:
    // the correction leaves a distance of 0.5 alone (rho(t) >= (0.5 / 2)^0.1 = 0.87 there).
    EXPECT_GT(r.value[near], 0.9) << kAOEstimators.logName(e);
  }
}

// The sun's error bar where all its rays agree: 8 rays into a wall's
// penumbra, all blocked, read 0.334 low with an error of 0.024 (an outside
// audit, 14 standard errors). The Laplace bound of their visibility stands
// in, as for AO's rays. A 5-degree sun 45 degrees behind a wall of height 1:
// floor vertices at 0.8 < x < 1.25 against 4096 sun rays, 10 seeds of 8.
TEST(SkyLighting, SunErrorBarsHoldInAPenumbraWithFewRays) {
  auto sf = scenes::floorWithWall(4.0, 1.0, 20);
  const Scene& s = sf.scene;
  const auto n = computeVertexNormals(s);
  auto caster = makeEmbreeCaster(s);
  AmbientOptions o;
  o.mode = AmbientMode::Sky;
  o.skyIrradiance = 0.f;
  o.sunIrradiance = 1.f;
  o.sunColor = glm::vec3(1.f);
  o.sunDirection = glm::normalize(glm::vec3(-1.f, 0.f, 1.f));
  o.sunAngularRadiusDeg = 5.f;
  o.raysPerVertex = 16;
  o.sunRays = 4096;
  const AmbientResult ref = computeAmbient(s, *caster, o);
  o.sunRays = 8;
  double z2 = 0, zMax = 0;
  int count = 0;
  for (uint32_t seed = 0; seed < 10; ++seed) {
    o.seed = seed;
    const AmbientResult r = computeAmbient(s, *caster, o);
    for (size_t i = 0; i < s.vertexCount(); ++i) {
      const double x = s.toWorld(s.positions[i]).x;
      if (!(n[i].z > 0.99f && x > 0.8 && x < 1.25)) continue;
      ASSERT_GT(r.stdError[i], 0.f) << "vertex " << i;
      const double z = (r.value[i] - ref.value[i]) / r.stdError[i];
      z2 += z * z, zMax = std::max(zMax, std::abs(z)), ++count;
    }
  }
  ASSERT_GT(count, 100);
  EXPECT_LT(std::sqrt(z2 / count), 1.5) << count << " vertex-seeds";
  EXPECT_LT(zMax, 5.0);
  // Nothing above (an open plane): no shadow to miss, the sun's bar stays its
  // rays' spread; a sharp sun's one direction is exact, even from one ray (a
  // review: 1.5% of the sun and the whole sun).
  auto plane = scenes::openPlane(1.0, 4);
  auto planeCaster = makeEmbreeCaster(plane.scene);
  o.sunDirection = glm::vec3(0.f, 0.f, 1.f);
  o.sunIrradiance = 3.f;
  for (const float radius : {0.f, 0.27f, 5.f})
    for (const int rays : {1, 64}) {
      o.sunAngularRadiusDeg = radius;
      o.sunRays = rays;
      if (radius > 0.f && rays == 1) continue;  // one ray of a disk: the spread is unknown
      const AmbientResult r = computeAmbient(plane.scene, *planeCaster, o);
      for (size_t i = 0; i < r.value.size(); ++i)
        ASSERT_LE(r.stdError[i], 1e-3f * 3.f) << "radius " << radius << ", " << rays << " rays, vertex " << i;
    }
}

// Sun only, on an open plane: E = E_sun cos(theta) for a sun 60 degrees from
// the normal (0.5), exact up to the sun disk's spread (< 1e-3 for 0.27 deg).
TEST(SkyLighting, SunOnOpenPlane) {
  auto sf = scenes::openPlane(1.0, 4);
  auto caster = makeEmbreeCaster(sf.scene);
  AmbientOptions o;
  o.mode = AmbientMode::Sky;
  o.skyIrradiance = 0.f;
  o.sunIrradiance = 2.f;
  o.sunDirection = glm::normalize(glm::vec3(std::sin(glm::radians(60.f)), 0.f, 0.5f));
  o.sunColor = glm::vec3(1.f);
  const AmbientResult r = computeAmbient(sf.scene, *caster, o);
  for (float v : r.value) EXPECT_NEAR(v, 1.0, 2e-3);
}

// max_distance: geometry farther than it does not occlude, for the sun's
// shadow rays as for the sky's (an outside audit found the sun still
// shadowed by a wall 1.13 away at max_distance 0.3: 0 for 0.707). A sharp
// sun at 45 degrees behind the wall (floor x in [0, 2], wall at x = 0, 1
// high): a floor vertex at x = 0.75 is in the wall's shadow (its sun ray
// meets the wall 1.06 away), and lit with E_sun cos 45 when max_distance is
// 0.3.
TEST(SkyLighting, MaxDistanceLimitsTheSunsShadowsToo) {
  auto sf = scenes::floorWithWall(2.0, 1.0, 8);
  auto caster = makeEmbreeCaster(sf.scene);
  AmbientOptions o;
  o.mode = AmbientMode::Sky;
  o.raysPerVertex = 32;
  o.skyIrradiance = 0.f;
  o.sunIrradiance = 1.f;
  o.sunColor = glm::vec3(1.f);
  o.sunAngularRadiusDeg = 0.f;
  o.sunRays = 1;
  o.sunDirection = glm::normalize(glm::vec3(-1.f, 0.f, 1.f));
  const auto n = computeVertexNormals(sf.scene);
  const size_t v = test::nearestVertex(sf.scene, {0.75, 0, 0}, [&](size_t i) { return n[i].z > 0.99f; });
  EXPECT_EQ(computeAmbient(sf.scene, *caster, o).value[v], 0.f);
  o.maxDistance = 0.3;
  EXPECT_NEAR(computeAmbient(sf.scene, *caster, o).value[v], std::sqrt(0.5), 1e-4);
}

// Adaptive sky lighting: target_error is the standard error of the sky's
// light in W/m^2 (it was of the sky fraction: at a sky of 100 W/m^2 a target
// of 0.01 gave errors of 0.97 W/m^2). At 100 times the sky, 100 times the
// target stops every vertex where the plain one did; the plain target there
// needs 10,000 times the rays, which max_rays (4,096) cuts short, and the
// log says the target is not met (it said nothing, as an audit found).
TEST(SkyLighting, TargetErrorIsInWattsPerSquareMetre) {
  auto sf = scenes::floorWithWall(2.0, 1.0, 8);
  auto caster = makeEmbreeCaster(sf.scene);
  AmbientOptions o;
  o.mode = AmbientMode::Sky;
  o.sunIrradiance = 0.f;
  o.minRays = 32;
  o.maxRays = 4096;
  auto run = [&](float sky, double target) {
    o.skyIrradiance = sky;
    o.targetError = target;
    return computeAmbient(sf.scene, *caster, o);
  };
  const AmbientResult one = run(1.f, 0.02), hundred = run(100.f, 2.0), strict = run(100.f, 0.02);
  double rays1 = 0, raysStrict = 0;
  std::vector<double> ratio;
  for (size_t i = 0; i < one.value.size(); ++i) {
    if (one.rays[i] == 0) continue;
    EXPECT_EQ(one.rays[i], hundred.rays[i]) << "vertex " << i;
    ratio.push_back(hundred.stdError[i] / 2.0);
    rays1 += one.rays[i], raysStrict += strict.rays[i];
  }
  // Counts sized by a pilot (gi/sampling.h): the target holds at most vertices.
  const test::OverTarget over = test::overTarget(ratio);
  EXPECT_LT(over.median, 1.0);
  EXPECT_LT(over.p90, 1.25);
  std::printf("sky rays: %.0f at 0.02 of a sky of 1 W/m^2, %.0f at 0.02 of 100 W/m^2\n", rays1, raysStrict);
  EXPECT_GT(raysStrict, 5 * rays1);
  EXPECT_TRUE(hundred.stats.warnings.empty()) << hundred.stats.line("sky");
  bool warned = false;
  for (const auto& w : strict.stats.warnings) warned |= w.find("the target is not met") != std::string::npos;
  EXPECT_TRUE(warned) << strict.stats.line("sky");
}

// Sky only: E = E_sky AO; with the wall, the crease gets half the sky.
TEST(SkyLighting, SkyIsScaledAO) {
  auto sf = scenes::floorWithWall(2.0, 1.0, 8);
  auto caster = makeEmbreeCaster(sf.scene);
  AmbientOptions o;
  o.mode = AmbientMode::Sky;
  o.raysPerVertex = 128;
  o.skyIrradiance = 3.f;
  o.sunIrradiance = 0.f;
  const AmbientResult sky = computeAmbient(sf.scene, *caster, o);
  const AmbientResult ao = runAO(sf.scene, 128);
  for (size_t i = 0; i < ao.value.size(); ++i) EXPECT_NEAR(sky.value[i], 3.f * ao.value[i], 1e-5f);
}

// Bent normals lean away from the wall.
TEST(AmbientOcclusion, BentNormalsLeanAwayFromOccluder) {
  auto sf = scenes::floorWithWall(2.0, 1.0, 8);
  auto caster = makeEmbreeCaster(sf.scene);
  AmbientOptions o;
  o.raysPerVertex = 512;
  o.bentNormals = true;
  const AmbientResult r = computeAmbient(sf.scene, *caster, o);
  const auto n = computeVertexNormals(sf.scene);
  const size_t v = test::nearestVertex(sf.scene, {0.5, 0, 0}, [&](size_t i) { return n[i].z > 0.99f; });
  EXPECT_GT(r.bentNormal[v].x, 0.1f);
  EXPECT_NEAR(glm::length(r.bentNormal[v]), 1.f, 1e-4f);
}

// With rays of any length, a vertex is open when the whole scene lies at or
// below its tangent plane (eps/2 above it at most): the tree's answer equals
// the brute-force maximum height over every vertex of a usable face, on the
// bunny (about a tenth of its vertices open), a floor by a wall (none) and a
// sphere seen from outside (all), and the per-vertex estimator gives the
// same bits with the proof as without it, for fewer rays.
TEST(AmbientOcclusion, SceneBelowTangentPlaneMatchesBruteForce) {
  const Scene bunny = io::loadMesh(std::string(GI_TEST_MESHES) + "/bunny.ply").scene;
  const Scene floor = scenes::floorWithWall(4.0, 1.0, 12).scene;  // the wall rises over every plane: none open
  const Scene ball = scenes::sphere(1.0, 3, false).scene;         // convex, seen from outside: all open
  for (const Scene* s : {&bunny, &floor, &ball}) {
    const std::vector<glm::vec3> normals = computeVertexNormals(*s);
    const float eps = float(sceneScale(*s).rayEpsilon);
    const SceneBelowTest test(*s, eps, normals);
    const auto usable = usableFaceMask(*s);
    std::vector<uint8_t> used(s->vertexCount(), 0);
    for (size_t f = 0; f < usable.size(); ++f)
      if (usable[f]) used[s->triangles[f].x] = used[s->triangles[f].y] = used[s->triangles[f].z] = 1;
    size_t open = 0, near = 0;
    for (uint32_t v = 0; v < s->vertexCount(); ++v) {
      double h = -HUGE_VAL;
      for (uint32_t u = 0; u < s->vertexCount(); ++u)
        if (used[u]) h = std::max(h, glm::dot(glm::dvec3(normals[v]), glm::dvec3(s->positions[u]) - glm::dvec3(s->positions[v])));
      const bool below = test.sceneBelow(v);
      open += below;
      if (std::fabs(h - 0.5 * eps) < 1e-3 * eps) { ++near; continue; }  // too close to call either way
      EXPECT_EQ(below, h <= 0.5 * eps) << "vertex " << v << ": highest point " << h << " over its plane, eps " << eps;
    }
    if (s == &bunny) {
      EXPECT_GT(open, s->vertexCount() / 20);
    } else if (s == &floor) {
      EXPECT_EQ(open, 0u);
    } else {
      EXPECT_EQ(open, s->vertexCount());
    }
    EXPECT_LT(near, 3u);
  }
  auto caster = makeEmbreeCaster(bunny);
  AmbientOptions o;
  o.raysPerVertex = 256;
  const AmbientResult skipped = computeAmbient(bunny, *caster, o);
  o.skipOpenVertices = false;
  const AmbientResult traced = computeAmbient(bunny, *caster, o);
  const double open = skipped.stats.get("skipped_open");
  EXPECT_GT(open, 0.05 * double(bunny.vertexCount()));
  EXPECT_EQ(skipped.value, traced.value);
  // The same standard errors where rays were cast; a proven vertex reports 0
  // (its rays, all escaping, report the Laplace bound instead).
  for (size_t v = 0; v < bunny.vertexCount(); ++v)
    if (skipped.rays[v] > 0) EXPECT_EQ(skipped.stdError[v], traced.stdError[v]) << v;
    else EXPECT_EQ(skipped.stdError[v], 0.f) << v;
  EXPECT_EQ(skipped.stats.get("rays"), traced.stats.get("rays") - 256.0 * open);
  // Below 128 rays per vertex the proof costs more than it saves: not run.
  o.skipOpenVertices = true;
  o.raysPerVertex = 64;
  EXPECT_EQ(computeAmbient(bunny, *caster, o).stats.get("skipped_open"), 0.0);
}

// A two-sided sheet (each face with a reversed copy: its vertices have no
// normal) 0.5 wide at height 1 over a 4 x 4 ground facing up: its top side
// sees nothing (AO 1), its bottom side the ground (AO 1 - F, F the exact
// point-to-square form factor), so each vertex gets the mean 1 - F / 2;
// they got 0 before 4 December 2026. 1,024 rays per vertex, and the shared
// estimator adaptive to 0.01: within 4 reported standard errors plus 0.002
// (the shared estimator's pools do not take these vertices: they are
// computed per vertex), and the log says how many.
TEST(AmbientOcclusion, TwoSidedSurfaceTakesTheMeanOfItsSides) {
  std::vector<glm::dvec3> pts;
  std::vector<glm::uvec3> tris;
  const int cells = 4;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) pts.push_back({-0.25 + 0.5 * i / cells, -0.25 + 0.5 * j / cells, 1.0});
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const uint32_t a = uint32_t(j * (cells + 1) + i), b = a + 1, c = a + cells + 2, d = a + cells + 1;
      for (const glm::uvec3 t : {glm::uvec3(a, b, c), glm::uvec3(a, c, d)}) {
        tris.push_back(t);
        tris.push_back({t.x, t.z, t.y});
      }
    }
  const uint32_t sheet = uint32_t(pts.size());
  const glm::dvec3 g0(-2, -2, 0), g1(2, -2, 0), g2(2, 2, 0), g3(-2, 2, 0);
  for (const glm::dvec3& p : {g0, g1, g2, g3}) pts.push_back(p);
  tris.push_back({sheet, sheet + 1, sheet + 2});
  tris.push_back({sheet, sheet + 2, sheet + 3});
  const Scene s = Scene::fromAbsolute(pts, tris);
  auto caster = makeEmbreeCaster(s);
  for (const bool shared : {false, true}) {
    SCOPED_TRACE(shared ? "shared, adaptive" : "per vertex");
    AmbientOptions o;
    o.raysPerVertex = 1024;
    if (shared) {
      o.estimator = AOEstimator::Shared;
      o.targetError = 0.01;
    }
    const AmbientResult r = computeAmbient(s, *caster, o);
    for (uint32_t v = 0; v < sheet; ++v) {
      const glm::dvec3 p = pts[v], down(0, 0, -1);
      const double F = pointToTriangleFormFactor(p, down, g0, g1, g2) + pointToTriangleFormFactor(p, down, g0, g2, g3);
      const double exact = 1.0 - 0.5 * F;
      EXPECT_GT(r.stdError[v], 0.f) << v;
      EXPECT_NEAR(r.value[v], exact, 4.0 * r.stdError[v] + 0.002) << v;
    }
    EXPECT_NE(r.stats.line("ao").find(std::to_string(sheet) + " vertices on a two-sided surface"), std::string::npos)
        << r.stats.line("ao");
  }
}

// Fewer than 8 rays a vertex give no usable value in any mode, and the log
// says so with the standard error's bound (sky and obscurance at 1 ray wrote
// 0 or 1 in silence; an outside audit); 8 rays say nothing.
TEST(AmbientOcclusion, TooFewRaysAreSaidInEveryMode) {
  auto sf = scenes::floorWithWall(4.0, 1.0, 8);
  auto caster = makeEmbreeCaster(sf.scene);
  for (AmbientMode mode : {AmbientMode::Occlusion, AmbientMode::Obscurance, AmbientMode::Sky}) {
    for (int rays : {1, 7, 8}) {
      AmbientOptions o;
      o.mode = mode;
      o.raysPerVertex = rays;
      if (mode == AmbientMode::Obscurance) o.maxDistance = 1.0;
      if (mode == AmbientMode::Sky) o.skyIrradiance = 1.f;
      const AmbientResult r = computeAmbient(sf.scene, *caster, o);
      bool said = false;
      for (const std::string& w : r.stats.warnings)
        said = said || (w.find("rays_per_vertex = " + std::to_string(rays)) != std::string::npos &&
                        w.find("usable estimate") != std::string::npos);
      EXPECT_EQ(said, rays < 8) << "mode " << int(mode) << ", " << rays << " rays";
    }
  }
}
