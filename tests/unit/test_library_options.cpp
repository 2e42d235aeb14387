// A library caller fills AmbientOptions and ThicknessOptions directly, without
// the parameter table's ranges: every value the table would refuse is refused
// by the algorithm itself with std::invalid_argument (never a NaN, a negative
// AO or a silent no-op), and directions of any length act as unit ones.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "gi/ambient.h"
#include "gi/scenes.h"
#include "gi/thickness.h"

using namespace gi;

TEST(LibraryOptions, AmbientRefusesWhatTheTableRefuses) {
  const auto sf = scenes::floorWithWall(2.0, 1.0, 4);
  const auto caster = makeEmbreeCaster(sf.scene);
  using Edit = std::function<void(AmbientOptions&)>;
  const std::vector<std::pair<const char*, Edit>> bad = {
      {"target_error NaN", [](AmbientOptions& o) { o.targetError = NAN; }},
      {"target_error < 0", [](AmbientOptions& o) { o.targetError = -0.1; }},
      {"max_rays 0", [](AmbientOptions& o) { o.targetError = 0.01; o.minRays = 0; o.maxRays = 0; }},
      {"min_rays 0", [](AmbientOptions& o) { o.targetError = 0.01; o.minRays = 0; }},
      {"min_rays < 0, shared", [](AmbientOptions& o) { o.targetError = 0.01; o.minRays = -1; o.estimator = AOEstimator::Shared; }},
      {"share_rings -2", [](AmbientOptions& o) { o.estimator = AOEstimator::Shared; o.shareRings = -2; }},
      {"share_rings 65", [](AmbientOptions& o) { o.estimator = AOEstimator::Shared; o.shareRings = 65; }},
      {"share_normal_angle NaN", [](AmbientOptions& o) { o.estimator = AOEstimator::Shared; o.shareNormalAngleDeg = NAN; }},
      {"falloff NaN", [](AmbientOptions& o) { o.mode = AmbientMode::Obscurance; o.maxDistance = 1; o.falloffExponent = NAN; }},
      {"falloff < 0", [](AmbientOptions& o) { o.mode = AmbientMode::Obscurance; o.maxDistance = 1; o.falloffExponent = -1; }},
      {"cone angle NaN", [](AmbientOptions& o) { o.useCone = true; o.coneAngleDeg = NAN; }},
      {"cone angle 270", [](AmbientOptions& o) { o.useCone = true; o.coneAngleDeg = 270; }},
      {"cone direction 0", [](AmbientOptions& o) { o.useCone = true; o.coneDirection = glm::vec3(0.f); }},
      {"sky NaN", [](AmbientOptions& o) { o.mode = AmbientMode::Sky; o.skyIrradiance = NAN; }},
      {"sky < 0", [](AmbientOptions& o) { o.mode = AmbientMode::Sky; o.skyIrradiance = -1; }},
      {"sun Inf", [](AmbientOptions& o) { o.mode = AmbientMode::Sky; o.sunIrradiance = INFINITY; }},
      {"sun colour NaN", [](AmbientOptions& o) { o.mode = AmbientMode::Sky; o.sunColor.g = NAN; }},
      {"sky colour < 0", [](AmbientOptions& o) { o.mode = AmbientMode::Sky; o.skyRadiantColor.b = -1; }},
      {"sun direction 0", [](AmbientOptions& o) { o.mode = AmbientMode::Sky; o.sunDirection = glm::vec3(0.f); }},
      {"sun radius 135", [](AmbientOptions& o) { o.mode = AmbientMode::Sky; o.sunAngularRadiusDeg = 135; }},
      {"sun radius NaN", [](AmbientOptions& o) { o.mode = AmbientMode::Sky; o.sunAngularRadiusDeg = NAN; }},
      {"sun rays 0", [](AmbientOptions& o) { o.mode = AmbientMode::Sky; o.sunRays = 0; }},
  };
  for (const auto& [what, edit] : bad) {
    AmbientOptions o;
    o.raysPerVertex = 8;
    edit(o);
    EXPECT_THROW(computeAmbient(sf.scene, *caster, o), std::invalid_argument) << what;
  }
  // At the edges of what is allowed: computed, and finite.
  AmbientOptions o;
  o.raysPerVertex = 8;
  o.mode = AmbientMode::Sky;
  o.sunAngularRadiusDeg = 90.f;
  o.skyIrradiance = 0.f;
  for (float v : computeAmbient(sf.scene, *caster, o).value) ASSERT_TRUE(std::isfinite(v));
}

// The sun's and the cone's directions act the same at any length (they were
// used as given: a sun direction of length 2 doubled the sun's light).
TEST(LibraryOptions, DirectionsOfAnyLengthActAsUnit) {
  const auto sf = scenes::floorWithWall(2.0, 1.0, 4);
  const auto caster = makeEmbreeCaster(sf.scene);
  AmbientOptions sky;
  sky.raysPerVertex = 16;
  sky.mode = AmbientMode::Sky;
  sky.skyIrradiance = 0.f;
  sky.sunDirection = glm::vec3(0.f, 0.f, 1.f);
  AmbientOptions cone;
  cone.raysPerVertex = 16;
  cone.useCone = true;
  cone.coneDirection = glm::vec3(0.f, 0.f, 1.f);
  for (AmbientOptions* o : {&sky, &cone}) {
    const AmbientResult unit = computeAmbient(sf.scene, *caster, *o);
    o->sunDirection *= 2.f;
    o->coneDirection *= 0.5f;
    const AmbientResult scaled = computeAmbient(sf.scene, *caster, *o);
    EXPECT_EQ(unit.value, scaled.value);
  }
}

TEST(LibraryOptions, ThicknessRefusesAdaptiveWithoutRays) {
  const auto sf = scenes::sphere(1.0, 1, false);
  const auto caster = makeEmbreeCaster(sf.scene);
  for (auto [target, lo, hi] : {std::tuple{double(NAN), 32, 64}, std::tuple{-0.1, 32, 64}, std::tuple{0.01, 0, 0},
                                std::tuple{0.01, -5, -1}}) {
    ThicknessOptions o;
    o.targetError = target;
    o.minRays = lo;
    o.maxRays = hi;
    EXPECT_THROW(computeThickness(sf.scene, *caster, o), std::invalid_argument) << target << " " << lo << " " << hi;
  }
}

// An adaptive run whose target is never met casts max_rays at every vertex
// and gives exactly the fixed run of max_rays (the same directions, the same
// lengths); its stopping test no longer sorts every length after each round
// (65,536 rays took 78 s a vertex, now about the fixed run's time).
TEST(LibraryOptions, ThicknessUnreachableTargetEqualsTheFixedRun) {
  const auto sf = scenes::sphere(1.0, 0, false);  // an icosahedron
  const auto caster = makeEmbreeCaster(sf.scene);
  ThicknessOptions fixed;
  fixed.raysPerVertex = 1 << 16;
  ThicknessOptions adaptive;
  adaptive.targetError = 1e-9;
  adaptive.maxRays = 1 << 16;
  const ThicknessResult a = computeThickness(sf.scene, *caster, fixed);
  const ThicknessResult b = computeThickness(sf.scene, *caster, adaptive);
  for (int r : b.rays) EXPECT_EQ(r, 1 << 16);
  EXPECT_EQ(a.value, b.value);
  EXPECT_EQ(a.stdError, b.stdError);
}
