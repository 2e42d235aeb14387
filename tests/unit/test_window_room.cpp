// A room lit only through a window: photon mapping's final gather reads
// no far estimate where photons are sparse.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>

#include "filter_input.h"
#include "gi/ambient.h"
#include "gi/color.h"
#include "gi/filter_run.h"
#include "gi/pathtrace.h"
#include "render_test_helpers.h"

using namespace gi;

namespace {

// A closed 4 m room of 0.5 m cells (each cell its own four vertices), lit
// only by a uniform sky through a 1 m window in the wall x = 4.
// Reflectance: the sRGB grey 188 the filters' constant reflectance takes.
Scene windowRoom() {
  test::SceneBuilder b;
  const glm::vec3 rho = srgb8ToLinear(188, 188, 188);
  const double h = 0.5;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) {
      const double u = i * h, v = j * h;
      b.quad({u, 0, v}, {u, 0, v + h}, {u + h, 0, v + h}, {u + h, 0, v}, rho);      // floor, up
      b.quad({u, 4, v}, {u + h, 4, v}, {u + h, 4, v + h}, {u, 4, v + h}, rho);      // ceiling, down
      b.quad({0, u, v}, {0, u + h, v}, {0, u + h, v + h}, {0, u, v + h}, rho);      // x = 0, +x
      if (!(i >= 3 && i < 5 && j >= 3 && j < 5))                                   // the window
        b.quad({4, u, v}, {4, u, v + h}, {4, u + h, v + h}, {4, u + h, v}, rho);    // x = 4, -x
      b.quad({u, v, 0}, {u + h, v, 0}, {u + h, v + h, 0}, {u, v + h, 0}, rho);      // z = 0, +z
      b.quad({u, v, 4}, {u, v + h, 4}, {u + h, v + h, 4}, {u + h, v, 4}, rho);      // z = 4, -z
    }
  return b.build();
}

// Mean and standard error of the mean of luminance(B) over the traced vertices.
std::pair<double, double> meanAndError(const Scene& s, const PathTraceResult& r) {
  double sum = 0, var = 0;
  size_t n = 0;
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    if (!r.traced[v]) continue;
    sum += luminance(r.B[v]);
    var += double(r.stdError[v]) * r.stdError[v];
    ++n;
  }
  return {sum / double(n), std::sqrt(var) / double(n)};
}

}  // namespace

// The sun alone through the window: photon mapping's final gather (200,000
// photons, 64 gather rays) against the reference (1,024 paths a vertex),
// the room's mean B. A gather ray read the nearest kept estimate (a site)
// however far: where photons are sparse that was one in the sunlit patch
// metres away. Bound: 4 combined standard errors plus 3% (the density
// estimates' own blur). Measured: +1.8%; reading the nearest site
// anywhere: +9.4%. And the gathered vertices' error bars.
TEST(WindowRoom, PhotonFinalGatherReadsNoFarEstimate) {
  const Scene s = windowRoom();
  auto caster = makeEmbreeCaster(s);
  PathTraceOptions po;
  po.samplesPerVertex = 1024;
  po.sunIrradiance = glm::vec3(3.f);
  po.sunDirection = glm::normalize(glm::vec3(1.f, 0.8f, 0.2f));
  const auto [refMean, refError] = meanAndError(s, pathTrace(s, *caster, po));
  scenes::SceneFile sf;
  sf.scene = s;
  FilterInput in = test::filterInput(FilterKind::PhotonMapping, sf);
  const auto specs = filterSpecs(FilterKind::PhotonMapping);
  const double diag = analyzeScene(in.scene).diagonal;
  for (const auto& [k, v] : {std::pair<const char*, const char*>{"reflectance_source", "Constant"},
                             {"reflectance", "188,188,188"}, {"emitter_source", "None"}, {"sun_irradiance", "3"},
                             {"sun_direction", "1,0.8,0.2"}, {"sky_irradiance", "0"}, {"final_gather", "true"}})
    in.values.set(k, parseValue(*findSpec(specs, k), v, diag));
  const FilterResult r = runFilter(FilterKind::PhotonMapping, in);
  const VertexAttribute* B = r.attribute("Radiosity");
  ASSERT_NE(B, nullptr);
  double sum = 0;
  for (size_t v = 0; v < s.vertexCount(); ++v)
    sum += luminance(glm::vec3(B->values[3 * v], B->values[3 * v + 1], B->values[3 * v + 2]));
  const double mean = sum / double(s.vertexCount());
  std::printf("sun through a window: photon final gather mean B %.5f against the reference %.5f +- %.5f (ratio %.4f)\n",
              mean, refMean, refError, mean / refMean);
  EXPECT_NEAR(mean, refMean, 4 * refError + 0.03 * refMean);
  // Every vertex's value is gathered: each has its gather's error bar (they
  // were all 0, which an error map reads as exact).
  const VertexAttribute* se = r.attribute("StdError");
  ASSERT_NE(se, nullptr);
  size_t lit = 0, withError = 0;
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    const bool isLit = luminance(glm::vec3(B->values[3 * v], B->values[3 * v + 1], B->values[3 * v + 2])) > 0.f;
    lit += isLit;
    withError += isLit && se->values[v] > 0.f;
  }
  EXPECT_GT(lit, s.vertexCount() / 2);
  EXPECT_EQ(withError, lit);
}

// The reference adaptive to a target relative error, against 1,024 paths a
// vertex, the room under a uniform sky seen through the window only: the
// mean B. The count was decided from the paths it kept (rounds until each
// vertex's error bar met the target relative to its own mean), so a vertex
// whose paths came out bright stopped early and one whose few paths all
// missed the window stopped dark. Measured over six seeds: +9.7% (+-0.5%)
// at a target of 0.3 with the default 64-path pilot, -12.5% (+-1.2%) at
// 0.2 with 16; now the count is fixed from a pilot left out before the
// paths kept are traced: -0.4% (+-0.2%, the reference's own error 0.4%)
// and -0.5% (+-0.8%), at 1.5 and 1.6 times the paths. Bound: 4
// combined standard errors of the two means (their vertices' error bars).
TEST(WindowRoom, AdaptiveReferenceIsUnbiased) {
  const Scene s = windowRoom();
  auto caster = makeEmbreeCaster(s);
  PathTraceOptions po;
  po.samplesPerVertex = 1024;
  po.skyRadiance = glm::vec3(1.f);
  const auto [refMean, refError] = meanAndError(s, pathTrace(s, *caster, po));
  for (const auto& [target, pilot] : {std::pair{0.3, 64}, std::pair{0.2, 16}}) {
    PathTraceOptions a = po;
    a.targetRelativeError = target;
    a.minSamples = pilot;
    const PathTraceResult r = pathTrace(s, *caster, a);
    const auto [mean, error] = meanAndError(s, r);
    std::printf("target %.1f, %d-path pilot: mean B %.5f +- %.5f against %.5f +- %.5f (ratio %.4f), %.0f paths a "
                "vertex and %.0f in the pilot\n",
                target, pilot, mean, error, refMean, refError, mean / refMean,
                r.stats.get("paths") / double(s.vertexCount()), r.stats.get("pilot_paths") / double(s.vertexCount()));
    EXPECT_NEAR(mean, refMean, 4 * std::hypot(error, refError)) << target;
    EXPECT_GT(r.stats.get("pilot_paths"), 0.0);
  }
}


// Ambient occlusion to a target error in the same room (the window is the
// only opening: AO about 0.010), per vertex and in adaptive strata, against
// 4,096 fixed rays: the mean AO. Stopping when the kept rays' own error met
// the target biased it low (a vertex whose rays all missed the window reads
// a small error and stops at 0): measured over 4 seeds at a target of 0.005,
// -0.00096 per vertex and -0.00098 in strata (-9%, about -0.2 target
// units). Now a pilot left out of the result sizes each count. Bound: 4
// combined standard errors of the two means (their vertices' error bars).
TEST(WindowRoom, AmbientOcclusionToATargetIsUnbiased) {
  const Scene s = windowRoom();
  auto caster = makeEmbreeCaster(s);
  auto mean = [&](const AmbientResult& r) {
    double sum = 0, var = 0;
    for (size_t v = 0; v < r.value.size(); ++v) sum += r.value[v], var += double(r.stdError[v]) * r.stdError[v];
    return std::pair{sum / double(r.value.size()), std::sqrt(var) / double(r.value.size())};
  };
  AmbientOptions f;
  f.raysPerVertex = 4096;
  f.seed = 77;
  const auto [refMean, refError] = mean(computeAmbient(s, *caster, f));
  for (const AOEstimator est : {AOEstimator::PerVertex, AOEstimator::Strata}) {
    AmbientOptions a;
    a.estimator = est;
    a.targetError = 0.005;
    a.maxRays = 1 << 15;
    a.seed = 1;
    const AmbientResult r = computeAmbient(s, *caster, a);
    const auto [m, e] = mean(r);
    std::printf("%s to 0.005: mean AO %.5f +- %.5f against %.5f +- %.5f, %.0f rays a vertex\n",
                kAOEstimators.choices()[size_t(kAOEstimators.index(est))].c_str(), m, e, refMean, refError, r.stats.get("rays") / double(r.value.size()));
    EXPECT_NEAR(m, refMean, 4 * std::hypot(e, refError)) << int(est);
  }
}
