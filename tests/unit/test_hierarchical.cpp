// Hierarchical radiosity with clustering (gi/hierarchical.h) against the flat
// solver: the Cornell box within the flat solver's own error, the furnace
// B = E / (1 - rho) with energy balance, and epsilon -> 0 giving back the
// flat solution.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "gi/color.h"
#include "gi/radiosity.h"
#include "gi/scenes.h"

using namespace gi;

namespace {

RadiosityOptions patchOptions(RadiositySolver solver) {
  RadiosityOptions o;
  o.solver = solver;
  o.vertexOutput = RadiosityVertexOutput::PatchAverage;
  o.tolerance = 1e-7;
  return o;
}

// Area-weighted RMS of the relative difference of patch luminance (non-emitting patches).
double rmsRel(const Scene& s, const std::vector<glm::vec3>& B, const std::vector<glm::vec3>& ref) {
  double num = 0, den = 0;
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (s.faceEmission(f) != glm::vec3(0.f)) continue;
    const double r = luminance(ref[f]);
    if (!(r > 0)) continue;
    const double d = (luminance(B[f]) - r) / r;
    num += faceArea(s, f) * d * d;
    den += faceArea(s, f);
  }
  return std::sqrt(num / den);
}

}  // namespace

// The 1.5k-patch Cornell box. The reference is the flat solution with
// analytic form factors at 16 points per patch (its error against the exact
// patch solution is the visibility noise of 16 rays per pair, far below the
// Monte Carlo rows'). The flat default (Monte Carlo, 1024 rays per patch)
// differs from it by its own noise, sqrt(F (1 - F) / 1024) per factor; the
// hierarchical solution must be at least as close to the reference as that,
// with fewer links than the flat matrix has entries.
TEST(HierarchicalRadiosity, AgreesWithFlatOnCornellBoxWithinFlatError) {
  auto sf = scenes::cornellBox(50.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions ro = patchOptions(RadiositySolver::GaussSeidel);
  ro.formFactors.method = FormFactorMethod::Analytic;
  ro.formFactors.analyticPoints = 16;
  const RadiosityResult ref = solveRadiosity(s, *caster, ro);
  const RadiosityResult flat = solveRadiosity(s, *caster, patchOptions(RadiositySolver::GaussSeidel));
  const RadiosityResult hier = solveRadiosity(s, *caster, patchOptions(RadiositySolver::Hierarchical));
  const double eFlat = rmsRel(s, flat.B, ref.B), eHier = rmsRel(s, hier.B, ref.B);
  std::printf("faces %zu: flat Monte Carlo rms error %.4f (%g entries), hierarchical %.4f (%g links)\n", s.faceCount(),
              eFlat, flat.stats.get("form_factor_entries"), eHier, hier.stats.get("links"));
  EXPECT_GT(s.faceCount(), 1400u);
  EXPECT_LE(eHier, eFlat);
  EXPECT_LT(hier.stats.get("links"), flat.stats.get("form_factor_entries"));
  EXPECT_LT(hier.residual, 1e-7);
}

// The furnace: a closed box of uniform E = 1 and rho gives B = 1 / (1 - rho)
// on every patch. The box is convex and empty, so the links need no rays and
// the only errors are the link factors' quadrature: a row of factors summing
// to 1 - delta gives B = 1 / (1 - rho + rho delta), a relative error of
// rho delta / (1 - rho). The direct light (exact factors at 256 points per
// patch to the 192 emitting faces) is E to about 1e-4. Tolerance 0.5% at
// rho = 0.99 allows delta = 5e-5; the energy balance (emitted = absorbed in
// a closed box) within 1e-3.
TEST(HierarchicalRadiosity, FurnaceAndEnergyBalance) {
  auto sf = scenes::closedBox(1.0, 6, true);  // 432 triangles
  for (float rho : {0.5f, 0.9f, 0.99f}) {
    scenes::setUniform(sf, glm::vec3(rho), glm::vec3(1.f));
    auto caster = makeEmbreeCaster(sf.scene);
    RadiosityOptions o = patchOptions(RadiositySolver::Hierarchical);
    o.tolerance = 1e-9;
    o.hierarchyEpsilon = 1e-3;
    const RadiosityResult r = solveRadiosity(sf.scene, *caster, o);
    EXPECT_GT(r.stats.get("links"), r.stats.get("links_patch_to_patch")) << "clusters linked";
    double worst = 0;
    for (const auto& b : r.B) worst = std::max(worst, std::fabs(double(b.g) * (1.0 - rho) - 1.0));
    EXPECT_LT(worst, 5e-3) << "rho " << rho;
    const double Pe = r.stats.get("emitted_power_W"), Pa = r.stats.get("absorbed_power_W");
    EXPECT_NEAR(Pa / Pe, 1.0, 1e-3) << "rho " << rho;
  }
}

// Epsilon 0: every link joins two triangles, and the solution is the flat
// one with the analytic factors (both exact up to their quadrature in this
// empty, convex room: no visibility rays; relative 1e-3 per patch).
TEST(HierarchicalRadiosity, ZeroToleranceReproducesFlat) {
  auto sf = scenes::closedBox(1.0, 4, true);
  Scene& s = sf.scene;
  s.rho.assign(s.faceCount(), glm::vec3(0.7f));
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  for (size_t f = 0; f < 8; ++f) s.emission[f] = glm::vec3(10.f);  // one side's first patches emit
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions fo = patchOptions(RadiositySolver::GaussSeidel);
  fo.formFactors.method = FormFactorMethod::Analytic;
  fo.formFactors.analyticPoints = 16;
  const RadiosityResult flat = solveRadiosity(s, *caster, fo);
  RadiosityOptions ho = patchOptions(RadiositySolver::Hierarchical);
  ho.hierarchyEpsilon = 0;
  const RadiosityResult hier = solveRadiosity(s, *caster, ho);
  EXPECT_EQ(hier.stats.get("links"), hier.stats.get("links_patch_to_patch"));
  for (size_t f = 0; f < s.faceCount(); ++f)
    ASSERT_NEAR(luminance(hier.B[f]) / luminance(flat.B[f]), 1.0, 1e-3) << "face " << f;
}

// Same bits for 1 and 2 threads; a budget too small for the hierarchy is refused.
TEST(HierarchicalRadiosity, DeterministicAndRefusesTinyBudget) {
  auto sf = scenes::cornellBox(100.0);
  auto caster = makeEmbreeCaster(sf.scene);
  RadiosityOptions o = patchOptions(RadiositySolver::Hierarchical);
  o.vertexOutput = RadiosityVertexOutput::FinalGather;
  o.gatherRays = 16;
  RadiosityResult a, b;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    a = solveRadiosity(sf.scene, *caster, o);
  }
  {
    tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    b = solveRadiosity(sf.scene, *caster, o);
  }
  ASSERT_EQ(a.Bvertex.size(), b.Bvertex.size());
  for (size_t v = 0; v < a.Bvertex.size(); ++v) ASSERT_EQ(a.Bvertex[v], b.Bvertex[v]);
  o.memoryBudgetMB = 0.01;
  EXPECT_THROW(solveRadiosity(sf.scene, *caster, o), std::invalid_argument);
}
