// Hierarchical radiosity with clustering (gi/hierarchical.h) against the flat
// solver: the Cornell box (1.5k and 10k patches) within the flat solver's own
// error, the furnace B = E / (1 - rho) with energy balance, and epsilon -> 0
// giving back the flat solution.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "gi/color.h"
#include "gi/direct.h"
#include "gi/hierarchical.h"
#include "gi/pathtrace.h"
#include "gi/radiosity.h"
#include "gi/scenes.h"
#include "render_test_helpers.h"

using namespace gi;

namespace {

RadiosityOptions patchOptions(RadiositySolver solver) {
  RadiosityOptions o;
  o.solver = solver;
  o.vertexOutput = RadiosityVertexOutput::PatchAverage;
  o.tolerance = 1e-7;
  return o;
}

// Patch values of the hierarchical solver for comparing absorbed powers:
// converged far below the differences measured, 64 shadow rays per point.
RadiosityOptions powerOptions() {
  RadiosityOptions o = patchOptions(RadiositySolver::Hierarchical);
  o.tolerance = 1e-6;
  o.lightSamples = 64;
  return o;
}

// Relative RMS difference over all values: sqrt(sum (Y - Yref)^2 / sum Yref^2).
double rmsAll(const std::vector<glm::vec3>& B, const std::vector<glm::vec3>& ref) {
  double num = 0, den = 0;
  for (size_t k = 0; k < B.size(); ++k) {
    const double r = luminance(ref[k]), d = luminance(B[k]) - r;
    num += d * d;
    den += r * r;
  }
  return std::sqrt(num / den);
}

// The same over what does not emit: the lamps' B (39.6 on the Cornell box,
// against a mean of 0.24 elsewhere) swamped the denominator, so rmsAll
// read 0.21% where the lit surfaces are 2.5% off (an outside audit).
double rmsLit(const std::vector<glm::vec3>& B, const std::vector<glm::vec3>& ref, const std::vector<uint8_t>& emits) {
  double num = 0, den = 0;
  for (size_t k = 0; k < B.size(); ++k) {
    if (emits[k]) continue;
    const double r = luminance(ref[k]), d = luminance(B[k]) - r;
    num += d * d;
    den += r * r;
  }
  return std::sqrt(num / den);
}

// Per face and per vertex (a corner of any emitting face): 1 where it emits.
std::vector<uint8_t> emittingFaces(const Scene& s) {
  std::vector<uint8_t> e(s.faceCount(), 0);
  for (size_t f = 0; f < s.faceCount(); ++f) e[f] = luminance(s.faceEmission(f)) > 0.f;
  return e;
}
std::vector<uint8_t> emittingVertices(const Scene& s) {
  std::vector<uint8_t> e(s.vertexCount(), 0);
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (luminance(s.faceEmission(f)) > 0.f) e[s.triangles[f].x] = e[s.triangles[f].y] = e[s.triangles[f].z] = 1;
  return e;
}

}  // namespace

// The 1.5k-patch Cornell box, at the vertices (what the filter writes) and
// per patch. Reference: the flat solution with analytic form factors at 4
// points per patch (within 0.1% of 16 points here), 1024 shadow and 1024 final-gather rays per vertex. The
// flat default (Monte Carlo rows, 1024 rays per patch) and the hierarchical
// default both use 256 gather rays with the same seed, whose noise against
// the reference's (about 1/sqrt(256) per ray-sampled term, averaged over the
// vertices) dominates both vertex errors; the links add their own error
// (measured over the surfaces that do not emit: flat 0.93%, hierarchical
// 1.01% at epsilon 1e-4): the hierarchical vertex error within 1.5 x the
// flat's. Per patch, a cluster receiving light spreads it evenly over its
// triangles (the approximation of hierarchical radiosity), so its patch
// values are less exact than the flat rows' (measured 2.57% against the
// flat Monte Carlo rows' 1.57%): within 3.5%. (Counted with the lamps,
// whose B of 39.6 swamps the rest, these read 0.08% and 0.21%, which the
// README gave until an outside audit.) Fewer links than the flat matrix
// has entries.
TEST(HierarchicalRadiosity, AgreesWithFlatOnCornellBoxWithinFlatError) {
  auto sf = scenes::cornellBox(50.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions ro;
  ro.solver = RadiositySolver::GaussSeidel;
  ro.formFactors.method = FormFactorMethod::Analytic;
  ro.formFactors.analyticPoints = 4;
  ro.lightSamples = 1024;
  ro.gatherRays = 1024;
  const RadiosityResult ref = solveRadiosity(s, *caster, ro);
  RadiosityOptions fo, ho;
  fo.solver = RadiositySolver::GaussSeidel;
  ho.solver = RadiositySolver::Hierarchical;
  const RadiosityResult flat = solveRadiosity(s, *caster, fo);
  const RadiosityResult hier = solveRadiosity(s, *caster, ho);
  const std::vector<uint8_t> ef = emittingFaces(s), ev = emittingVertices(s);
  const double eFlat = rmsLit(flat.Bvertex, ref.Bvertex, ev), eHier = rmsLit(hier.Bvertex, ref.Bvertex, ev);
  const double pFlat = rmsLit(flat.B, ref.B, ef), pHier = rmsLit(hier.B, ref.B, ef);
  std::printf("faces %zu: vertices flat %.5f hierarchical %.5f; patches flat %.5f hierarchical %.5f; %g entries, %g links\n",
              s.faceCount(), eFlat, eHier, pFlat, pHier, flat.stats.get("form_factor_entries"), hier.stats.get("links"));
  EXPECT_GT(s.faceCount(), 1400u);
  EXPECT_LE(eHier, 1.5 * eFlat);
  EXPECT_LT(pHier, 0.035);
  EXPECT_LT(hier.stats.get("links"), flat.stats.get("form_factor_entries"));
  EXPECT_LT(hier.stats.get("links_patch_to_patch"), hier.stats.get("links"));
  EXPECT_LT(hier.residual, 1e-4);
}

// The furnace: a closed box of uniform E = 1 and rho gives B = 1 / (1 - rho)
// on every patch. The box is convex and empty, so the links need no rays and
// the only errors are the link factors' quadrature: links whose factors sum
// to 1 - delta over a row (the closure, measured here as 1 - <H>/<R>, area
// means of the indirect irradiance and the reflected radiosity, equal in a
// closed room) give <B> (1 - rho) = (1 - rho) (1 + rho delta) / (1 - rho +
// rho delta), about 1 - rho delta / (1 - rho). Checked: the closure within
// 1e-3 (the triangle-to-triangle factors' adaptive rule leaves about 6e-5,
// the clusters' 16-point rule 6.5e-4 where many clusters link, measured at
// rho 0.5); the mean B as that closure predicts, within 2e-4 / (1 - rho)
// (the direct light, exact factors to the 6 walls, each one luminaire of 32
// emitting faces, at up to 4 points per patch, is E to about 1e-4,
// amplified by 1 / (1 - rho)); the energy
// balance (emitted = absorbed in a closed box) within rho |delta| / (1 - rho)
// + 2e-4 / (1 - rho); and at rho = 0.99, where the links to bright sources
// are refined to triangles, B within 1% of 1 / (1 - rho). These are the
// links' own bounds, asserted with the closure on (the default, which
// brings delta to 1e-9 here: ClosureConservesEnergyInAClosedRoom) and off.
TEST(HierarchicalRadiosity, FurnaceAndEnergyBalance) {
  auto sf = scenes::closedBox(1.0, 4, true);  // 192 triangles, all emitting: 6 luminaires, exact direct light
  for (int closureRays : {64, 0})
  for (float rho : {0.5f, 0.9f, 0.99f}) {
    SCOPED_TRACE("closure rays " + std::to_string(closureRays));
    scenes::setUniform(sf, glm::vec3(rho), glm::vec3(1.f));
    auto caster = makeEmbreeCaster(sf.scene);
    RadiosityOptions o = patchOptions(RadiositySolver::Hierarchical);
    o.tolerance = 1e-9;
    o.closureRays = closureRays;
    const RadiosityResult r = solveRadiosity(sf.scene, *caster, o);
    if (rho == 0.5f) {
      EXPECT_GT(r.stats.get("links"), r.stats.get("links_patch_to_patch")) << "clusters linked";
    }
    double B = 0, H = 0, R = 0, A = 0;
    for (size_t f = 0; f < r.B.size(); ++f) {
      const double a = faceArea(sf.scene, f);
      B += a * r.B[f].g;
      H += a * r.Hindirect[f].g;
      R += a * r.Rgather[f].g;
      A += a;
    }
    const double delta = 1.0 - H / R, p = rho;
    const double predicted = (1.0 - p) * (1.0 + p * delta) / (1.0 - p + p * delta);
    const double direct = 2e-4 / (1.0 - p);
    EXPECT_LT(std::fabs(delta), 1e-3) << "rho " << rho;
    EXPECT_NEAR(B / A * (1.0 - p), predicted, direct) << "rho " << rho;
    EXPECT_NEAR(r.stats.get("absorbed_power_W") / r.stats.get("emitted_power_W"), 1.0,
                p * std::fabs(delta) / (1.0 - p) + direct) << "rho " << rho;
    if (rho == 0.99f) {
      EXPECT_NEAR(B / A * (1.0 - p), 1.0, 0.01);
    }
  }
}

// The closure (gi/hierarchical.h) in a closed room lit from a patch of its
// ceiling (768 triangles, 8 x 8 patches a side; E = 10 on the 32 triangles
// within 0.2 of the ceiling's centre), where light leaves nowhere: at
// convergence every watt reflected is absorbed in the end, so sum A R =
// rho / (1 - rho) sum A H_direct exactly, whatever the links. The links'
// own row sums spread from 0.94 to 1.06 here: without the closure (rays 0)
// the mean R is 10% high at rho 0.99 (measured 1.10) and the solve
// diverges at 0.999 (a warning; 10.9 times the exact value after 3,000
// sweeps, 2,367 times after 20,000). With it: the mean within 1e-5
// (measured 6e-7 or less: the solve's tolerance), the energy balance within
// 1e-5, and the patch values against the flat solution from Monte Carlo
// rows of 16,384 rays (whose rows are closed too: every ray hits) within
// 0.2% RMS, about ten times that reference's own noise (measured 0.018%
// against 0.027% between two of its seeds; 10% without the closure).
TEST(HierarchicalRadiosity, ClosureConservesEnergyInAClosedRoom) {
  auto sf = scenes::closedBox(1.0, 8, true);
  Scene& s = sf.scene;
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const glm::vec3 c = (s.positions[s.triangles[f].x] + s.positions[s.triangles[f].y] + s.positions[s.triangles[f].z]) / 3.f;
    if (c.y > 0.49f && std::fabs(c.x) < 0.2f && std::fabs(c.z) < 0.2f) s.emission[f] = glm::vec3(10.f);
  }
  for (float rho : {0.9f, 0.99f, 0.999f}) {
    s.rho.assign(s.faceCount(), glm::vec3(rho));
    auto caster = makeEmbreeCaster(s);
    const std::vector<glm::vec3> Hd = patchDirectIrradiance(s, *caster, 64, 0);
    double AHd = 0;
    for (size_t f = 0; f < s.faceCount(); ++f) AHd += faceArea(s, f) * Hd[f].g;
    const double exact = rho / (1.0 - rho) * AHd;
    auto meanR = [&](const HierarchicalSolution& h) {
      double AR = 0;
      for (size_t f = 0; f < s.faceCount(); ++f) AR += faceArea(s, f) * h.R[f].g;
      return AR / exact;
    };
    HierarchySettings hs;
    const HierarchicalSolution closed = solveHierarchical(s, *caster, Hd, hs, -1, 1e-8, 0);
    hs.closureRays = 0;
    const HierarchicalSolution open = solveHierarchical(s, *caster, Hd, hs, -1, 1e-8, rho > 0.99f ? 3000 : 0);
    std::printf("rho %.3f: mean R / exact: closure %.7f (balance %.2g, %g rows moved, RMS %.4f), without %.4f\n", rho,
                meanR(closed), closed.stats.get("energy_balance_error"), closed.stats.get("rows_closed"),
                closed.stats.get("row_closure_rms"), meanR(open));
    EXPECT_NEAR(meanR(closed), 1.0, 1e-5) << "rho " << rho;
    bool noted = false;
    for (const std::string& n : closed.stats.notes) noted |= n.find("closed room without occluders") != std::string::npos;
    EXPECT_TRUE(noted) << "rho " << rho;
    EXPECT_LT(closed.stats.get("energy_balance_error"), 1e-5) << "rho " << rho;
    EXPECT_TRUE(closed.stats.warnings.empty()) << "rho " << rho;
    if (rho == 0.99f) {
      EXPECT_GT(meanR(open), 1.05) << "the links alone create light";
      RadiosityOptions fo = patchOptions(RadiositySolver::GaussSeidel);
      fo.formFactors.method = FormFactorMethod::MonteCarlo;
      fo.formFactors.raysPerPatch = 16384;
      fo.lightSamples = 64;
      const RadiosityResult flat = solveRadiosity(s, *caster, fo);
      std::vector<glm::vec3> B = closed.R;
      for (size_t f = 0; f < B.size(); ++f) B[f] += s.emission[f];
      const double e = rmsAll(B, flat.B);
      std::printf("  patch values against the flat Monte Carlo rows: %.5f RMS\n", e);
      EXPECT_LT(e, 0.002);
    }
    if (rho == 0.999f) {
      EXPECT_GT(meanR(open), 2.0) << "diverges without the closure";
      EXPECT_FALSE(open.stats.warnings.empty());
    }
  }
}

// The closure applies to closed rooms without occluders only: a room with
// a hole (one wall's 4 central patches missing), an open floor beside a
// wall, and a closed room with a block in it (its links need visibility
// rays) get the same bits with closure_rays 64 as with 0; the energy
// balance is reported for them all.
TEST(HierarchicalRadiosity, ClosureLeavesOtherScenesAlone) {
  auto lit = [](Scene s) {
    s.rho.assign(s.faceCount(), glm::vec3(0.95f));
    s.emission.assign(s.faceCount(), glm::vec3(0.f));
    for (size_t f = 0; f < s.faceCount(); ++f) {
      const glm::dvec3 c = (s.toWorld(s.positions[s.triangles[f].x]) + s.toWorld(s.positions[s.triangles[f].y]) +
                            s.toWorld(s.positions[s.triangles[f].z])) / 3.0;
      if (c.y > 0.49 && std::fabs(c.x) < 0.2 && std::fabs(c.z) < 0.2) s.emission[f] = glm::vec3(10.f);
    }
    return s;
  };
  auto pieces = [](const std::vector<Scene>& parts, auto keep) {
    std::vector<glm::dvec3> pts;
    std::vector<glm::uvec3> tris;
    for (const Scene& p : parts) {
      const uint32_t off = uint32_t(pts.size());
      for (const auto& v : p.positions) pts.push_back(p.toWorld(v));
      for (const auto& t : p.triangles) {
        const glm::dvec3 c = (pts[off + t.x] + pts[off + t.y] + pts[off + t.z]) / 3.0;
        if (keep(c)) tris.push_back(t + glm::uvec3(off));
      }
    }
    return Scene::fromAbsolute(pts, tris);
  };
  const Scene room = scenes::closedBox(1.0, 8, true).scene;
  const Scene block = scenes::closedBox(0.3, 2, false).scene;
  const Scene withHole = lit(pieces({room}, [](glm::dvec3 c) { return !(c.z > 0.49 && std::fabs(c.x) < 0.25 && std::fabs(c.y) < 0.25); }));
  const Scene withBlock = lit(pieces({room, block}, [](glm::dvec3) { return true; }));
  const Scene floorWall = lit(pieces({room}, [](glm::dvec3 c) { return c.y < -0.49 || c.x < -0.49 || c.y > 0.49; }));
  for (const Scene* s : {&withHole, &withBlock, &floorWall}) {
    auto caster = makeEmbreeCaster(*s);
    const std::vector<glm::vec3> Hd = patchDirectIrradiance(*s, *caster, 64, 0);
    HierarchySettings hs;
    const HierarchicalSolution a = solveHierarchical(*s, *caster, Hd, hs, -1, 1e-6, 0);
    hs.closureRays = 0;
    const HierarchicalSolution b = solveHierarchical(*s, *caster, Hd, hs, -1, 1e-6, 0);
    ASSERT_EQ(a.R.size(), b.R.size());
    for (size_t f = 0; f < a.R.size(); ++f) ASSERT_EQ(a.R[f], b.R[f]) << "face " << f;
    EXPECT_GT(a.stats.get("energy_balance_error", -1.0), 0.0);
    EXPECT_EQ(a.stats.get("rows_closed", -1.0), -1.0);
  }
}

// Where the room is open or has occluders the links' sums stand, and their
// visibility rays and quadrature can create light; the energy balance,
// against the closure rays' count of what escapes, indicates how much. The
// shadow-leak room (a partition cutting through coarse patches, the
// light's back 2 cm below the ceiling): the hierarchy absorbs 3.2% more
// than the flat solution from Monte Carlo rows (whose balance is within
// 0.02%), and its balance says 3.2%; asserted within half a percent of
// each other. It is an indicator, not a measurement (the links are not
// reciprocal), and in a closed room with a lamp quad at rho
// 0.956 it said 5.8% where the absorbed power was 1.2% off (a 20k scan
// room: 0.39% for -0.37%). The Cornell box balances within 1%. Above 5% it
// warns: a sealed room parted by a floating block (gaps of 0.05 all round),
// lit on one side, at rho 0.991 absorbed about twice the power its lamp
// emits (an outside check, 4 December 2026, 2,470 patches: 109%) without a
// word; here (960 patches) 1.14 times (1.08 before the partial-visibility
// refinement of 5 December 2026: at this reflectance a link's error is
// magnified a hundredfold, and which links are split moves it either way),
// where the flat Gauss-Seidel solve absorbs 0.86 and balances (the rest
// meets the lamp's back).
TEST(HierarchicalRadiosity, EnergyBalanceSaysWhatTheLinksCreate) {
  auto leak = scenes::shadowLeak();
  auto caster = makeEmbreeCaster(leak.scene);
  RadiosityOptions o = patchOptions(RadiositySolver::GaussSeidel);
  o.tolerance = 1e-6;
  o.formFactors.raysPerPatch = 16384;
  const RadiosityResult flat = solveRadiosity(leak.scene, *caster, o);
  o.solver = RadiositySolver::Hierarchical;
  const RadiosityResult hier = solveRadiosity(leak.scene, *caster, o);
  const double created = hier.stats.get("absorbed_power_W") / flat.stats.get("absorbed_power_W") - 1.0;
  const double balance = hier.stats.get("energy_balance_error");
  std::printf("shadow leak: absorbed %+.2f%% against the flat rows (balance %.2g), energy balance %.2f%%\n",
              100 * created, flat.stats.get("energy_balance_error"), 100 * balance);
  EXPECT_LT(flat.stats.get("energy_balance_error"), 1e-3);
  EXPECT_NEAR(balance, std::fabs(created), 0.005);
  auto box = scenes::cornellBox(50.0);
  auto boxCaster = makeEmbreeCaster(box.scene);
  const RadiosityResult cornell = solveRadiosity(box.scene, *boxCaster, o);
  EXPECT_LT(cornell.stats.get("energy_balance_error"), 0.01);
  for (const std::string& w : cornell.stats.warnings) EXPECT_EQ(w.find("energy balance"), std::string::npos) << w;
  // The shadow leak's links create 2.6% (the warning's threshold was 5%
  // until an outside audit found a sealed room 4.3% bright without a word):
  // said, as light created, with its sign in energy_created_fraction.
  bool said = false;
  for (const std::string& w : hier.stats.warnings) said = said || w.find("energy balance off by") != std::string::npos;
  EXPECT_TRUE(said);
  EXPECT_NEAR(hier.stats.get("energy_created_fraction"), balance, 1e-12);
  EXPECT_LT(flat.stats.get("energy_created_fraction", 1.0), 1e-3);

  test::SceneBuilder b;
  const glm::vec3 rho(0.991f);
  b.box({-1, -0.5, -0.5}, {1, 0.5, 0.5}, rho, glm::vec3(0.f), Material::Diffuse, true, 8);
  b.box({-0.05, -0.45, -0.45}, {0.05, 0.45, 0.45}, rho, glm::vec3(0.f), Material::Diffuse, false, 4);
  b.quad({-0.6, 0.49, -0.1}, {-0.4, 0.49, -0.1}, {-0.4, 0.49, 0.1}, {-0.6, 0.49, 0.1}, glm::vec3(0.f), glm::vec3(1.f));
  const Scene parted = b.build();
  auto partedCaster = makeEmbreeCaster(parted);
  const RadiosityResult room = solveRadiosity(parted, *partedCaster, o);
  o.solver = RadiositySolver::GaussSeidel;
  const RadiosityResult roomFlat = solveRadiosity(parted, *partedCaster, o);
  const double emitted = room.stats.get("emitted_power_W");
  std::printf("parted room at rho 0.991: absorbed / emitted %.3f hierarchical (balance %.2f), %.3f flat (balance "
              "%.2g; the rest meets the lamp's back)\n",
              room.stats.get("absorbed_power_W") / emitted, room.stats.get("energy_balance_error"),
              roomFlat.stats.get("absorbed_power_W") / emitted, roomFlat.stats.get("energy_balance_error"));
  EXPECT_LT(roomFlat.stats.get("energy_balance_error"), 0.01);
  ASSERT_GT(room.stats.get("energy_balance_error"), 0.05);
  bool warned = false;
  for (const std::string& w : room.stats.warnings) warned = warned || w.find("energy balance off by") != std::string::npos;
  EXPECT_TRUE(warned);
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

// bounces = 0 is the direct light only, B = E + rho H_direct, whatever the
// solver: the same bits as the flat solver's (the same direct-light code);
// one bounce adds light.
TEST(HierarchicalRadiosity, FixedBouncesMatchTheFlatDefinition) {
  auto sf = scenes::cornellBox(100.0);
  auto caster = makeEmbreeCaster(sf.scene);
  RadiosityOptions o;
  o.bounces = 0;
  o.gatherRays = 16;
  o.solver = RadiositySolver::GaussSeidel;
  const RadiosityResult flat = solveRadiosity(sf.scene, *caster, o);
  o.solver = RadiositySolver::Hierarchical;
  const RadiosityResult h0 = solveRadiosity(sf.scene, *caster, o);
  o.bounces = 1;
  const RadiosityResult h1 = solveRadiosity(sf.scene, *caster, o);
  ASSERT_EQ(flat.Bvertex.size(), h0.Bvertex.size());
  double sum0 = 0, sum1 = 0;
  for (size_t v = 0; v < h0.Bvertex.size(); ++v) {
    ASSERT_EQ(flat.Bvertex[v], h0.Bvertex[v]) << "vertex " << v;
    sum0 += luminance(h0.Bvertex[v]);
    sum1 += luminance(h1.Bvertex[v]);
  }
  EXPECT_GT(sum1, sum0 * 1.05);
  EXPECT_EQ(h1.iterations, 1);
}

// The Cornell box at about 10k patches (20 mm patches), the filter's
// defaults (flat: Gauss-Seidel on Monte Carlo rows; hierarchical: epsilon
// 1e-4, 4 link rays; both 256 shadow and final-gather rays per vertex),
// against the path-traced reference at 400 vertices drawn at random
// (traced_vertices; 4,096 paths each) away from the light. e(X): the RMS of
// the relative differences (X - ref) / ref there. The reference's own noise
// n (the RMS of its relative standard errors, about 1%) is in both; the
// hierarchical solution agrees with the flat one within the flat solver's
// error: the RMS relative difference between them is below e(flat) (which
// holds n as well: the test fails when the hierarchy's own error exceeds
// the flat's and the reference's together), and e(hierarchical) is within
// 1.2 e(flat). Measured: 9,526 faces, 387 vertices, e(flat) 2.6%,
// e(hierarchical) 2.7%, their difference 0.5%, n 1.9% (3.4%, 3.3% and 1.1%
// before the final gather's near hits gathered their own indirect light:
// test_final_gather.cpp); with the gathered indirect light 5% short in the
// hierarchy the test fails (5.4%, 4.5%).
// About 13 s of CPU (Release).
TEST(HierarchicalRadiosity, AgreesWithFlatOnTenThousandPatchCornellBox) {
  auto sf = scenes::cornellBox(20.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions fo, ho;
  fo.solver = RadiositySolver::GaussSeidel;
  ho.solver = RadiositySolver::Hierarchical;
  const RadiosityResult flat = solveRadiosity(s, *caster, fo);
  const RadiosityResult hier = solveRadiosity(s, *caster, ho);
  PathTraceOptions po;
  po.samplesPerVertex = 4096;
  po.tracedVertices = 400;
  po.tracedVertexSeed = 1;
  const PathTraceResult ref = pathTrace(s, *caster, po);
  const VertexMaterial mat = vertexMaterial(s);
  double eF = 0, eH = 0, dHF = 0, noise = 0;
  int n = 0;
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    if (!ref.traced[v] || luminance(mat.E[v]) > 0.f) continue;
    const double r = luminance(ref.B[v]), f = luminance(flat.Bvertex[v]), h = luminance(hier.Bvertex[v]);
    if (!(r > 0)) continue;
    eF += (f - r) * (f - r) / (r * r);
    eH += (h - r) * (h - r) / (r * r);
    dHF += (h - f) * (h - f) / (f * f);
    noise += double(ref.stdError[v]) * ref.stdError[v] / (r * r);
    ++n;
  }
  eF = std::sqrt(eF / n), eH = std::sqrt(eH / n), dHF = std::sqrt(dHF / n), noise = std::sqrt(noise / n);
  std::printf("faces %zu, %d reference vertices: e(flat) %.4f, e(hierarchical) %.4f, hierarchical - flat %.4f, "
              "reference noise %.4f\n", s.faceCount(), n, eF, eH, dHF, noise);
  EXPECT_GT(s.faceCount(), 9000u);
  EXPECT_GT(n, 350);
  EXPECT_LT(dHF, eF);
  EXPECT_LT(eH, 1.2 * eF);
}

// Links from clusters gather the radiosity at the source points their
// visibility rays reached, not the cluster's area mean: in a room with
// objects, the triangles a receiver sees are the brighter ones (a nook is
// both dark and hidden), so the area mean times the visible fraction carried
// too little (-1.2% of the power absorbed here, README), and behind a
// window it counted a partition's bright far face (+230% to +360% at 17 or
// 32 link rays, which took the area mean until 5 December 2026). Measured
// as the power absorbed in the Cornell box (direct and indirect; the direct
// light is the same code for every run): epsilon 0 (every link joins two
// triangles, no cluster anywhere) is the reference; the default 4 rays stay
// within 0.8% of it, and 32 rays, which now gather at the points they reach
// too, come closer (-0.18% against -0.41%). The links are compared as they
// give them, without the closure's balance (closure_rays 0).
TEST(HierarchicalRadiosity, ClusterSourcesGatherWhatTheirRaysSee) {
  auto sf = scenes::cornellBox(50.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  const RadiosityOptions o = powerOptions();
  auto absorbed = [&](double epsilon, int linkRays) {
    RadiosityOptions x = o;
    x.hierarchyEpsilon = epsilon;
    x.linkRays = linkRays;
    x.closureRays = 0;
    return solveRadiosity(s, *caster, x).stats.get("absorbed_power_W");
  };
  const double exact = absorbed(0.0, 4), four = absorbed(1e-4, 4), many = absorbed(1e-4, 32);
  const double e4 = four / exact - 1, e32 = many / exact - 1;
  std::printf("absorbed: epsilon 0 %.6g, 4 link rays %.6g (%+.3f%%), 32 link rays %.6g (%+.3f%%)\n", exact, four,
              100 * e4, many, 100 * e32);
  EXPECT_LT(std::fabs(e4), 0.008);
  EXPECT_LT(std::fabs(e32), std::fabs(e4));
}

// A memory budget that stops the link refinement stops it where the links
// carry the least power: once the budget is hit the refinement is redone
// best first, so that the coarse links left are the weakest ones everywhere
// (depth-first, the part of the tree visited last stayed coarse: 10% error
// on a 30k-triangle scan room at half its links, 1.5% best first, the same
// as without the budget). The Cornell box with a third of its links:
// measured 2.3% RMS from the unbudgeted values of the patches that do not
// emit (0.21% counted with the lamps; depth-first: 1.8% so counted) and
// -0.12% absorbed power (depth-first: -15%); asserted within 3.5% and 1.5%.
TEST(HierarchicalRadiosity, BudgetStopsTheWeakestLinksFirst) {
  auto sf = scenes::cornellBox(50.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions o = powerOptions();
  const RadiosityResult full = solveRadiosity(s, *caster, o);
  const double links = full.stats.get("links");
  const double fixedMB = double(s.faceCount()) * (kSolverBytesPerPatch + 2 * kHierarchyBytesPerNode) / 1048576.0;
  o.memoryBudgetMB = fixedMB + links / 3 * kHierarchyBytesPerLink / 1048576.0;
  const RadiosityResult cut = solveRadiosity(s, *caster, o);
  bool warned = false;
  for (const std::string& w : cut.stats.warnings) warned |= w.find("memory budget") != std::string::npos;
  const double e = rmsLit(cut.B, full.B, emittingFaces(s));
  const double dP = cut.stats.get("absorbed_power_W") / full.stats.get("absorbed_power_W") - 1;
  std::printf("links %g -> %g: patch values %.4f RMS, absorbed power %+.4f\n", links, cut.stats.get("links"), e, dP);
  EXPECT_TRUE(warned);
  EXPECT_LT(cut.stats.get("links"), 0.4 * links);
  EXPECT_LT(e, 0.035);
  EXPECT_LT(std::fabs(dP), 0.015);
}

// max_links stops the refinement as the memory budget does, best first,
// with a note instead of the budget's warning (the user asked for it): the
// Cornell box with a third of its links gives the same patch values as
// the budget above (the same links: the cap is the other way of saying
// it), asserted within the same 3.5% RMS of the uncapped values; and the
// same bits on one thread as on all.
TEST(HierarchicalRadiosity, LinkCapRefinesBestFirst) {
  auto sf = scenes::cornellBox(50.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions o = powerOptions();
  const RadiosityResult full = solveRadiosity(s, *caster, o);
  const double links = full.stats.get("links");
  o.maxLinks = std::floor(links / 3);
  const RadiosityResult cut = solveRadiosity(s, *caster, o);
  bool noted = false;
  for (const std::string& n : cut.stats.notes) noted |= n.find("links capped at") != std::string::npos;
  const double e = rmsLit(cut.B, full.B, emittingFaces(s));
  std::printf("links %g -> %g (cap %g): patch values %.4f RMS\n", links, cut.stats.get("links"), o.maxLinks, e);
  EXPECT_TRUE(noted);
  for (const std::string& w : cut.stats.warnings) EXPECT_EQ(w.find("memory budget"), std::string::npos) << w;
  EXPECT_LE(cut.stats.get("links"), o.maxLinks);
  EXPECT_LT(e, 0.035);
  // The refinement decides batches of candidates on all threads and applies
  // them in order: one thread gives the same bits.
  RadiosityResult one;
  {
    tbb::global_control g(tbb::global_control::max_allowed_parallelism, 1);
    one = solveRadiosity(s, *caster, o);
  }
  ASSERT_EQ(one.B.size(), cut.B.size());
  for (size_t f = 0; f < cut.B.size(); ++f) ASSERT_EQ(one.B[f], cut.B[f]) << "patch " << f;
}

// What the hierarchy cannot give is refused before any work, naming the
// parameter: the linear system (there is no form-factor matrix) and
// snapshots of whole solutions (there are no sweeps). Both used to be left
// out without a word.
TEST(HierarchicalRadiosity, RefusesExportAndSnapshots) {
  const Scene s = scenes::cornellBox(100.0).scene;
  auto caster = makeEmbreeCaster(s);
  for (int k = 0; k < 2; ++k) {
    RadiosityOptions o = patchOptions(RadiositySolver::Hierarchical);
    if (k == 0) o.exportSystem = "unused";
    else o.snapshotSteps = {1};
    try {
      solveRadiosity(s, *caster, o);
      ADD_FAILURE() << "not refused";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(k == 0 ? "export_system" : "snapshot_steps"), std::string::npos) << e.what();
    }
  }
}
