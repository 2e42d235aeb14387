// Direct light (radiosity's zero-bounce case) against analytic values:
// point-to-square form factors. Photon mapping: test_photon.cpp.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "gi/color.h"
#include "gi/direct.h"
#include "gi/photon.h"
#include "gi/scenes.h"
#include "test_helpers.h"

using namespace gi;

namespace {
// Differential area facing a coaxial a x b rectangle at distance c, below its centre.
double pointToRectangleCentre(double a, double b, double c) {
  const double X = a / (2 * c), Y = b / (2 * c);
  const double sx = std::sqrt(1 + X * X), sy = std::sqrt(1 + Y * Y);
  return 2.0 / M_PI * (X / sx * std::atan(Y / sx) + Y / sy * std::atan(X / sy));
}
}  // namespace

// Irradiance at the centre of the receiving plate = E * F(dA -> emitter square).
// 4096 light samples; tolerance 1% relative (standard error about 0.3%).
TEST(DirectLight, PointToSquareFormFactor) {
  for (double L : {0.5, 1.0, 2.0}) {
    auto sf = scenes::parallelPlates(L, 8);
    auto caster = makeEmbreeCaster(sf.scene);
    DirectOptions o;
    o.lightSamples = 4096;
    const VertexRadiometry r = computeDirect(sf.scene, *caster, o);
    const size_t v = test::nearestVertex(sf.scene, {0, 0, L});
    EXPECT_NEAR(r.H[v].g / pointToRectangleCentre(1, 1, L), 1.0, 0.01) << "L = " << L;
  }
}

// Inside a closed sphere emitting E = 1 everywhere, the irradiance is E, so
// the zero-bounce radiosity is E + rho E = 1.5 for rho = 0.5. 256 samples: 2%.
TEST(DirectLight, FurnaceSphereOneBounce) {
  auto sf = scenes::sphere(1.0, 3, true);
  scenes::setUniform(sf, glm::vec3(0.5f), glm::vec3(1.f));
  auto caster = makeEmbreeCaster(sf.scene);
  DirectOptions o;
  o.lightSamples = 256;
  const VertexRadiometry r = computeDirect(sf.scene, *caster, o);
  double mean = 0;
  for (const auto& b : r.B) mean += b.r;
  mean /= double(r.B.size());
  EXPECT_NEAR(mean, 1.5, 0.02);
}

TEST(DirectLight, NoEmitterIsAClearError) {
  auto sf = scenes::openPlane(1.0, 2);
  sf.scene.emission.clear();
  auto caster = makeEmbreeCaster(sf.scene);
  EXPECT_THROW(computeDirect(sf.scene, *caster, DirectOptions{}), std::invalid_argument);
}

TEST(DirectLight, DeterministicAcrossThreadCounts) {
  auto sf = scenes::cornellBox(100.0);
  auto caster = makeEmbreeCaster(sf.scene);
  DirectOptions o;
  o.lightSamples = 16;
  VertexRadiometry a, b;
  { tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1); a = computeDirect(sf.scene, *caster, o); }
  { tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2); b = computeDirect(sf.scene, *caster, o); }
  EXPECT_EQ(a.B, b.B);
}
