// The reference path tracer against analytic values: the furnace, sky-lit
// ambient occlusion, a small emitter's irradiance (point-to-square form
// factor), the plate-to-plate form factor, a point light and a sun; its error
// bars against the true error; agreement with the radiosity solver on the
// Cornell box; determinism.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <cmath>
#include <algorithm>
#include <map>

#include "gi/color.h"
#include "gi/direct.h"
#include "gi/pathtrace.h"
#include "gi/radiosity.h"
#include "gi/scenes.h"
#include "test_helpers.h"

using namespace gi;

namespace {
PathTraceResult trace(const Scene& s, int spp, PathTraceOptions o = {}) {
  auto caster = makeEmbreeCaster(s);
  o.samplesPerVertex = spp;
  return pathTrace(s, *caster, o);
}
}  // namespace

// Furnace: B = E / (1 - rho). The scene mean over all vertices must lie within
// 4 standard errors (of the mean) plus 0.2% of the exact value.
TEST(PathTracer, FurnaceSphere) {
  for (float rho : {0.5f, 0.9f, 0.99f}) {
    auto sf = scenes::sphere(1.0, 1, true);
    scenes::setUniform(sf, glm::vec3(rho), glm::vec3(1.f));
    const auto r = trace(sf.scene, rho > 0.95f ? 256 : 128);
    double mean = 0, var = 0;
    for (size_t i = 0; i < r.B.size(); ++i) { mean += r.B[i].g; var += double(r.stdError[i]) * r.stdError[i]; }
    const double n = double(r.B.size()), exact = 1.0 / (1.0 - rho);
    mean /= n;
    EXPECT_NEAR(mean, exact, 4 * std::sqrt(var) / n + 0.002 * exact) << "rho " << rho;
  }
}

// One path a vertex gives no error estimate: the error bars are written as
// 0 (unknown), and a warning says so (an error map's z-scores read them as
// exact, rms_z 0; an outside sweep, 5 December 2026). Two paths: none.
TEST(PathTracer, OnePathAVertexSaysItHasNoErrorBars) {
  auto sf = scenes::sphere(1.0, 1, true);
  scenes::setUniform(sf, glm::vec3(0.5f), glm::vec3(1.f));
  const auto one = trace(sf.scene, 1);
  ASSERT_EQ(one.stats.warnings.size(), 1u);
  EXPECT_NE(one.stats.warnings[0].find("no error estimate"), std::string::npos);
  for (float e : one.stdError) EXPECT_EQ(e, 0.f);
  EXPECT_TRUE(trace(sf.scene, 2).stats.warnings.empty());
}

// A uniform white sky with rho = 0: H = E_sky AO. Floor vertices at distance d
// from a wall of height 1: AO = 1/2 + d / (2 sqrt(d^2 + 1)). 2048 paths: each
// within 4 reported standard errors plus 0.005 (the wall's finite width).
TEST(PathTracer, SkyLitAmbientOcclusion) {
  auto sf = scenes::floorWithWall(4.0, 1.0, 8);
  Scene& s = sf.scene;
  s.rho.assign(s.faceCount(), glm::vec3(0.f));
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  PathTraceOptions o;
  o.skyRadiance = glm::vec3(float(1.0 / M_PI));  // sky irradiance 1
  const auto r = trace(s, 2048, o);
  const auto n = computeVertexNormals(s);
  for (double d : {0.5, 1.0, 2.0, 3.5}) {
    const size_t v = test::nearestVertex(s, {d, 0, 0}, [&](size_t i) { return n[i].z > 0.99f; });
    const double x = s.toWorld(s.positions[v]).x, ao = 0.5 + x / (2 * std::sqrt(x * x + 1));
    // rho = 0: B = E = 0, so check the irradiance; its error = stdError / rho is not defined: use 0.02.
    EXPECT_NEAR(r.H[v].g, ao, 0.02) << "d = " << x;
  }
}

// Irradiance at the centre of the receiving plate from the emitting unit
// square at distance L: E F(dA -> square). 4096 paths; within 4 reported
// standard errors (each below 1%).
TEST(PathTracer, SmallEmitterIrradiance) {
  for (double L : {0.5, 1.0, 2.0}) {
    auto sf = scenes::parallelPlates(L, 8);
    const auto r = trace(sf.scene, 4096);
    const size_t v = test::nearestVertex(sf.scene, {0, 0, L});
    const double X = 1 / (2 * L), sx = std::sqrt(1 + X * X);
    const double F = 2.0 / M_PI * 2 * (X / sx * std::atan(X / sx));
    EXPECT_NEAR(r.H[v].g, F, 4 * r.stdErrorH[v]) << "L = " << L;
    EXPECT_LT(r.stdErrorH[v], 0.01 * F);
  }
}

// The area-weighted mean irradiance on the receiving plate is E F12 with the
// parallel-plate closed form (0.199825 at L = 1). 256 paths per vertex, 1.5%
// (vertex quadrature of the plate plus noise).
TEST(PathTracer, PlateToPlateFormFactor) {
  auto sf = scenes::parallelPlates(1.0, 16);
  const Scene& s = sf.scene;
  const auto r = trace(s, 256);
  std::vector<double> w(s.vertexCount(), 0.0);
  for (size_t f = s.faceCount() / 2; f < s.faceCount(); ++f)
    for (int k = 0; k < 3; ++k) w[s.triangles[f][k]] += faceArea(s, f) / 3;
  double num = 0, den = 0;
  for (size_t i = 0; i < w.size(); ++i) { num += w[i] * r.H[i].g; den += w[i]; }
  EXPECT_NEAR(num / den, 0.199825, 0.015 * 0.199825);
}

// Delta lights: a point light of intensity I at height h above an open plane
// gives I cos / r^2 exactly; a sun at 60 degrees gives E_sun cos 60.
TEST(PathTracer, PointLightAndSun) {
  auto sf = scenes::openPlane(2.0, 4);
  Scene& s = sf.scene;
  s.rho.assign(s.faceCount(), glm::vec3(0.f));
  s.emission.clear();
  PathTraceOptions o;
  o.point.position = glm::vec3(glm::dvec3(0.3, -0.2, 1.5) - s.origin);
  o.point.intensity = glm::vec3(2.f);
  const auto r = trace(s, 4, o);
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    const glm::dvec3 p = s.toWorld(s.positions[i]);
    const glm::dvec3 d = glm::dvec3(0.3, -0.2, 1.5) - p;
    const double r2 = glm::dot(d, d), c = d.z / std::sqrt(r2);
    EXPECT_NEAR(r.H[i].g, 2.0 * c / r2, 1e-4 * 2.0 * c / r2);
  }
  PathTraceOptions sun;
  sun.sunIrradiance = glm::vec3(3.f);
  sun.sunAngularRadiusDeg = 0.f;
  sun.sunDirection = glm::normalize(glm::vec3(std::sin(glm::radians(60.f)), 0.f, 0.5f));
  for (float h : trace(s, 4, sun).stdError) EXPECT_EQ(h, 0.f);  // rho = 0: B = 0 exactly
  const auto rs = trace(s, 4, sun);
  for (const auto& H : rs.H) EXPECT_NEAR(H.g, 1.5, 1e-5);
}

// A two-sided surface (every face with a reversed copy) has no vertex
// normal: its vertices get the mean of their two sides, as radiosity's patch
// average does there (they got 0 before 4 December 2026). A plane under a
// sky of radiance 1 / pi (H = 1 on either side) and a sun of 2 straight
// above: the top (rho 0.5) gets H = 3, the bottom (rho 0.2) H = 1, so B =
// (0.5 x 3 + 0.2 x 1) / 2 = 0.85 and H = 2 at every vertex, borders
// included (nothing is occluded: exact within float rounding); the light
// path parts sum to B, and the log says how many vertices.
TEST(PathTracer, TwoSidedSurfaceTakesTheMeanOfItsSides) {
  const auto [pts, tris] = test::twoSided(scenes::openPlane(2.0, 4).scene);
  const size_t n = tris.size() / 2;
  Scene s = Scene::fromAbsolute(pts, tris);
  s.rho.assign(s.faceCount(), glm::vec3(0.2f));
  for (size_t f = 0; f < n; ++f) s.rho[f] = glm::vec3(0.5f);  // the originals face up
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  PathTraceOptions o;
  o.skyRadiance = glm::vec3(float(1.0 / M_PI));
  o.sunIrradiance = glm::vec3(2.f);
  o.sunAngularRadiusDeg = 0.f;
  o.sunDirection = glm::vec3(0.f, 0.f, 1.f);
  o.lightPathSplit = true;
  const auto r = trace(s, 16, o);
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    EXPECT_NEAR(r.B[i].g, 0.85, 1e-5) << i;
    EXPECT_NEAR(r.H[i].g, 2.0, 1e-5) << i;
    const glm::vec3 sum = r.split.emitted[i] + r.split.direct[i] + r.split.caustic[i] + r.split.indirect[i];
    EXPECT_NEAR(sum.g, r.B[i].g, 1e-5) << i;
  }
  EXPECT_NE(r.stats.line("reference").find(std::to_string(s.vertexCount()) + " vertices on a two-sided surface"),
            std::string::npos)
      << r.stats.line("reference");
  EXPECT_EQ(r.stats.get("paths"), 2.0 * 16 * double(s.vertexCount()));  // a path from either side per sample

  // Error bars where the sides differ: a sun of 2 at 60 degrees from the
  // zenith half-shadowed by a black strip above the plane, the top rho 0.9,
  // the bottom 0.1. 8 seeds of 4 samples against 4,096: mean z^2 below 2
  // (measured 0.87; 1.17 with the pool weighted by the sides' mean
  // reflectance, which a reviewer showed 0.56 times too narrow where rare
  // light reaches the brighter side: this bound checks the calibration, it
  // does not separate the two).
  Scene shaded = s;
  for (size_t f = 0; f < n; ++f) shaded.rho[f] = glm::vec3(0.9f);
  for (size_t f = n; f < shaded.faceCount(); ++f) shaded.rho[f] = glm::vec3(0.1f);
  std::vector<glm::dvec3> all = pts;
  std::vector<glm::uvec3> allTris = tris;
  const uint32_t b = uint32_t(all.size());
  for (const glm::dvec3 q : {glm::dvec3(-0.3, -2, 0.6), glm::dvec3(0.1, -2, 0.6), glm::dvec3(0.1, 2, 0.6), glm::dvec3(-0.3, 2, 0.6)})
    all.push_back(q);
  allTris.push_back({b, b + 2, b + 1});  // facing down
  allTris.push_back({b, b + 3, b + 2});
  Scene strip = Scene::fromAbsolute(all, allTris);
  strip.rho = shaded.rho;
  strip.rho.push_back(glm::vec3(0.f));
  strip.rho.push_back(glm::vec3(0.f));
  strip.emission.assign(strip.faceCount(), glm::vec3(0.f));
  PathTraceOptions sun = o;
  sun.skyRadiance = glm::vec3(0.f);
  sun.sunAngularRadiusDeg = 5.f;
  sun.sunDirection = glm::normalize(glm::vec3(std::sin(glm::radians(60.f)), 0.f, 0.5f));
  sun.lightPathSplit = false;
  const auto truth = trace(strip, 4096, sun);
  double z2 = 0;
  int count = 0;
  for (uint32_t seed = 1; seed <= 8; ++seed) {
    sun.seed = seed;
    const auto e = trace(strip, 4, sun);
    for (size_t i = 0; i < s.vertexCount(); ++i) {
      if (!(e.stdError[i] > 0.f)) continue;
      const double z = (e.B[i].g - truth.B[i].g) / std::sqrt(double(e.stdError[i]) * e.stdError[i] +
                                                             double(truth.stdError[i]) * truth.stdError[i]);
      z2 += z * z;
      ++count;
    }
  }
  std::printf("two-sided, sides 0.9 and 0.1: mean z^2 %.3f over %d\n", z2 / count, count);
  ASSERT_GT(count, 40);
  EXPECT_LT(z2 / count, 2.0);
}

// The reported standard errors are honest: on the sky-lit floor with 256
// paths, the true error is below 2 reported standard errors at about 95% of
// the vertices (accepted: 88% to 99.5%) and below 3 at >= 97%. Vertices
// farther than 2 wall heights are left out: almost no ray is blocked there,
// and a sample variance of rare events is itself unreliable.
TEST(PathTracer, ErrorBarsCoverTheTrueError) {
  auto sf = scenes::floorWithWall(3.0, 1.0, 12);
  Scene& s = sf.scene;
  s.rho.assign(s.faceCount(), glm::vec3(0.5f));  // B = rho H: its standard error is reported
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  PathTraceOptions o;
  o.skyRadiance = glm::vec3(float(1.0 / M_PI));
  o.maxDepth = 0;  // sky-lit AO only (a bounce would add floor-wall light the formula lacks)
  const auto r = trace(s, 256, o);
  const auto n = computeVertexNormals(s);
  int inside2 = 0, inside3 = 0, count = 0;
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    if (n[i].z < 0.99f) continue;
    const glm::dvec3 p = s.toWorld(s.positions[i]);
    if (std::fabs(p.y) > 5 || p.x > 2) continue;  // where the wall is effectively infinite and AO < 0.95
    const double exact = 0.5 * (0.5 + p.x / (2 * std::sqrt(p.x * p.x + 1)));
    const double err = std::fabs(r.B[i].g - exact);
    inside2 += err < 2 * r.stdError[i];
    inside3 += err < 3 * r.stdError[i];
    ++count;
  }
  ASSERT_GT(count, 60);
  const double f2 = double(inside2) / count, f3 = double(inside3) / count;
  RecordProperty("coverage_2sigma", std::to_string(f2));
  EXPECT_GT(f2, 0.88);
  EXPECT_LT(f2, 0.995);
  EXPECT_GT(f3, 0.97);
}

// Agreement with the radiosity solver on the diffuse Cornell box: the
// area-weighted mean radiosity of each wall within 3% and of each block side
// (few patches, steep gradients towards the floor) within 8%,
// away from the sheets' borders (creases, the rim around the light), where
// the exact per-vertex value and the constant-patch average legitimately
// differ (the corner falloff a 50 mm patch cannot represent: up to 20%).
TEST(PathTracer, AgreesWithRadiosityOnCornellBox) {
  auto sf = scenes::cornellBox(50.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions ro;
  ro.formFactors.raysPerPatch = 4096;
  ro.lightSamples = 1024;
  ro.tolerance = 1e-7;
  const auto rad = solveRadiosity(s, *caster, ro);
  const auto pt = trace(s, 256);
  const auto groups = test::wallSums(
      s, [&](size_t f) { return test::wholePatchMean(rad, f); },
      [&](size_t f) {
        double ptB = 0;
        for (int k = 0; k < 3; ++k) ptB += luminance(pt.B[s.triangles[f][k]]) / 3;
        return ptB;
      });
  int compared = 0;
  for (const auto& [k, g] : groups) {
    if (g[0] < 5e3) continue;  // ignore tiny groups (mm^2)
    EXPECT_NEAR(g[2] / g[1], 1.0, g[0] > 1e5 ? 0.03 : 0.08) << k;
    ++compared;
  }
  EXPECT_GE(compared, 8);
  // Per-vertex output against the path tracer at vertices off the borders:
  // the final gather beats interpolating the patches, which beats the plain
  // patch average (the error of each printed as a test property).
  const std::vector<uint8_t> border = test::borderVertices(s);
  auto vertexError = [&](RadiosityVertexOutput mode) {
    RadiosityOptions o = ro;
    o.vertexOutput = mode;
    const auto r = solveRadiosity(s, *caster, o);
    double num = 0, den = 0;
    for (size_t v = 0; v < s.vertexCount(); ++v) {
      if (border[v] || luminance(pt.B[v]) > 5.0) continue;  // borders and the light
      num += std::pow(luminance(r.Bvertex[v]) - luminance(pt.B[v]), 2.0);
      den += luminance(pt.B[v]);
    }
    return std::sqrt(num / double(s.vertexCount())) / (den / double(s.vertexCount()));
  };
  const double eGather = vertexError(RadiosityVertexOutput::FinalGather);
  const double eInterp = vertexError(RadiosityVertexOutput::InterpolatedIndirect);
  const double ePatch = vertexError(RadiosityVertexOutput::PatchAverage);
  RecordProperty("vertex_error_final_gather", std::to_string(eGather));
  RecordProperty("vertex_error_patch_average", std::to_string(ePatch));
  EXPECT_LT(eGather, eInterp);
  EXPECT_LT(eInterp, ePatch);
}

// A block standing on a coarse floor: the floor patches under its edges are
// half in its shadow, and the vertices along the block's foot gather light
// from them at close range. The final gather relights such near hits at the
// hit point (direct light there, plus the patch's indirect light), so those
// vertices agree with the path tracer: RMS relative difference over the 16
// foot vertices below 15% (4096 paths per vertex: noise about 1%). Without
// the relighting it is 27% (10% with it).
TEST(PathTracer, RadiosityFinalGatherAtTheFootOfABlock) {
  Scene s;
  auto quad = [&s](glm::dvec3 p0, glm::dvec3 p1, glm::dvec3 p2, glm::dvec3 p3, int n, glm::vec3 rho, glm::vec3 E) {
    std::vector<glm::dvec3> pts;
    std::vector<glm::uvec3> tris;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const double u = double(i) / n, v = double(j) / n;
        pts.push_back((1 - u) * (1 - v) * p0 + u * (1 - v) * p1 + u * v * p2 + (1 - u) * v * p3);
      }
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const uint32_t a = uint32_t(j * (n + 1) + i);
        tris.push_back({a, a + 1, a + uint32_t(n) + 2});
        tris.push_back({a, a + uint32_t(n) + 2, a + uint32_t(n) + 1});
      }
    Scene q = Scene::fromAbsolute(pts, tris);
    q.rho.assign(q.faceCount(), rho);
    q.emission.assign(q.faceCount(), E);
    if (s.faceCount() == 0) s = q; else s.append(q);
  };
  const glm::vec3 grey(0.7f), none(0.f);
  quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 5, grey, none);          // floor, facing +y, patches 0.4
  // Block [-0.3, 0.3] x [0, 0.5] x [-0.3, 0.3]: sides facing out, the top up.
  quad({-0.3, 0, 0.3}, {0.3, 0, 0.3}, {0.3, 0.5, 0.3}, {-0.3, 0.5, 0.3}, 3, grey, none);
  quad({0.3, 0, -0.3}, {-0.3, 0, -0.3}, {-0.3, 0.5, -0.3}, {0.3, 0.5, -0.3}, 3, grey, none);
  quad({0.3, 0, 0.3}, {0.3, 0, -0.3}, {0.3, 0.5, -0.3}, {0.3, 0.5, 0.3}, 3, grey, none);
  quad({-0.3, 0, -0.3}, {-0.3, 0, 0.3}, {-0.3, 0.5, 0.3}, {-0.3, 0.5, -0.3}, 3, grey, none);
  quad({-0.3, 0.5, 0.3}, {0.3, 0.5, 0.3}, {0.3, 0.5, -0.3}, {-0.3, 0.5, -0.3}, 3, grey, none);
  quad({-0.8, 2, -0.8}, {0.8, 2, -0.8}, {0.8, 2, 0.8}, {-0.8, 2, 0.8}, 2, none, glm::vec3(5.f));  // light, facing down
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions ro;
  ro.formFactors.raysPerPatch = 4096;
  ro.lightSamples = 1024;
  ro.gatherRays = 1024;
  const auto r = solveRadiosity(s, *caster, ro);
  PathTraceOptions po;
  po.samplesPerVertex = 4096;
  const auto pt = pathTrace(s, *caster, po);
  const VertexMaterial mat = vertexMaterial(s);
  double e2 = 0;
  int foot = 0;
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    if (std::abs(s.toWorld(s.positions[v]).y) > 1e-4 || std::abs(mat.n[v].y) > 0.5f) continue;  // the block's foot
    const double rel = luminance(r.Bvertex[v]) / luminance(pt.B[v]) - 1.0;
    e2 += rel * rel;
    ++foot;
  }
  ASSERT_GE(foot, 12);
  const double rms = std::sqrt(e2 / foot);
  RecordProperty("foot_rms_relative_error", std::to_string(rms));
  EXPECT_LT(rms, 0.15);
}

// Bounces = 0 at vertices is direct light only: B = E + rho H_direct there.
TEST(PathTracer, RadiosityZeroBouncesAtVerticesIsDirectLight) {
  auto sf = scenes::cornellBox(100.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions o;
  o.bounces = 0;
  o.formFactors.raysPerPatch = 64;
  const auto r = solveRadiosity(s, *caster, o);
  const auto Hd = vertexDirectIrradiance(s, *caster, o.lightSamples, o.formFactors.seed);
  const VertexMaterial m = vertexMaterial(s);
  for (size_t v = 0; v < s.vertexCount(); ++v)
    EXPECT_NEAR(luminance(r.Bvertex[v]), luminance(m.E[v] + m.rho[v] * Hd[v]), 1e-5f * (1 + luminance(r.Bvertex[v])));
}

TEST(PathTracer, DeterministicAcrossThreadCounts) {
  auto sf = scenes::cornellBox(150.0);
  PathTraceResult a, b;
  { tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1); a = trace(sf.scene, 8); }
  { tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2); b = trace(sf.scene, 8); }
  EXPECT_EQ(a.B, b.B);
}

TEST(PathTracer, NoLightIsAClearError) {
  auto sf = scenes::openPlane(1.0, 2);
  sf.scene.emission.clear();
  auto caster = makeEmbreeCaster(sf.scene);
  EXPECT_THROW(pathTrace(sf.scene, *caster, PathTraceOptions{}), std::invalid_argument);
}

// A disk emitter (a 256-gon fan, E = 1, facing down) at height h above the
// centre vertex of a black floor: H = E R^2 / (R^2 + h^2) (docs/design.md, "Analytic references", the
// polygon's deficit is below 1e-4). 4096 paths: within 4 standard errors.
TEST(PathTracer, PointToDiskIrradiance) {
  const double R = 0.5, h = 0.8;
  auto sf = scenes::openPlane(2.0, 2);  // 3 x 3 vertices, one at the centre
  Scene floor = sf.scene;
  floor.rho.assign(floor.faceCount(), glm::vec3(0.f));
  floor.emission.assign(floor.faceCount(), glm::vec3(0.f));
  std::vector<glm::dvec3> pts = {{0, 0, h}};
  std::vector<glm::uvec3> tris;
  const int m = 256;
  for (int k = 0; k < m; ++k) pts.push_back({R * std::cos(2 * M_PI * k / m), R * std::sin(2 * M_PI * k / m), h});
  for (int k = 0; k < m; ++k) tris.push_back({0u, uint32_t(1 + (k + 1) % m), uint32_t(1 + k)});  // facing -z
  Scene disk = Scene::fromAbsolute(pts, tris);
  disk.rho.assign(disk.faceCount(), glm::vec3(0.f));
  disk.emission.assign(disk.faceCount(), glm::vec3(1.f));
  Scene s = floor;
  s.append(disk);
  ASSERT_LT(glm::normalize(faceNormalUnnormalized(s, s.faceCount() - 1)).z, -0.99f);
  const auto r = trace(s, 4096);
  const size_t v = test::nearestVertex(s, {0, 0, 0});
  const double exact = R * R / (R * R + h * h);
  EXPECT_NEAR(r.H[v].g, exact, 4 * r.stdErrorH[v] + 1e-4);
  EXPECT_LT(r.stdErrorH[v], 0.01 * exact);
}

namespace {
// A closed shaft of white mirrors, w x w across and hbox high, over a diffuse
// floor (a separate sheet: 4 triangles around a centre vertex) with emission
// E and reflectance rho. Unfolded, the mirrors tile the floor into an
// infinite plane that sees only itself: B = E / (1 - rho) exactly, while a
// ray leaving the floor at angle theta from the normal bounces about
// (2 hbox / w) tan(theta) (|cos phi| + |sin phi|) times before it lands on it
// again: thousands of mirror bounces per path.
Scene mirrorShaft(double w, double hbox, float rho, float E) {
  const double a = 0.5 * w;
  std::vector<glm::dvec3> p = {{-a, -a, 0}, {a, -a, 0}, {a, a, 0}, {-a, a, 0},
                               {-a, -a, hbox}, {a, -a, hbox}, {a, a, hbox}, {-a, a, hbox},
                               {-a, -a, 0}, {a, -a, 0}, {a, a, 0}, {-a, a, 0}, {0, 0, 0}};
  // Walls and ceiling facing in (counter-clockwise seen from inside).
  std::vector<glm::uvec3> t = {{0, 4, 5}, {0, 5, 1}, {1, 5, 6}, {1, 6, 2}, {2, 6, 7},
                               {2, 7, 3}, {3, 7, 4}, {3, 4, 0}, {4, 7, 6}, {4, 6, 5}};
  const size_t mirrors = t.size();
  for (uint32_t k = 0; k < 4; ++k) t.push_back({12u, 8 + k, 8 + (k + 1) % 4});  // floor, facing +z
  Scene s = Scene::fromAbsolute(p, t);
  s.rho.assign(s.faceCount(), glm::vec3(1.f));
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  s.material.assign(s.faceCount(), Material::Mirror);
  for (size_t f = mirrors; f < s.faceCount(); ++f) {
    s.rho[f] = glm::vec3(rho);
    s.emission[f] = glm::vec3(E);
    s.material[f] = Material::Diffuse;
  }
  return s;
}
}  // namespace

// Paths of tens of thousands of bounces (the limit is 100,000) used to
// recurse once per bounce and overflow a worker thread's stack. Now a loop:
// it terminates, with the furnace value B = E / (1 - rho) = 2 at the floor's
// vertices. A shaft 1 wide and 1000 high: a round trip takes 2000 tan(theta)
// c(phi) bounces (4000 on average); one longer than the 100,000 limit needs
// tan(theta) c(phi) > 50, probability E[c^2] / (1 + 50^2) < 1e-3 under cosine
// weighting (P(tan theta > T) = 1 / (1 + T^2)), so truncation costs under
// 0.1% per round trip and a path makes about 1 / (1 - rho) = 2 of them:
// tolerance 4 standard errors of the mean over the floor vertices + 0.5%.
TEST(PathTracer, DeepMirrorShaftTerminatesWithTheFurnaceValue) {
  const Scene s = mirrorShaft(1.0, 1000.0, 0.5f, 1.f);
  PathTraceOptions o;
  o.maxDepth = 100000;
  const auto r = trace(s, 96, o);
  const VertexMaterial m = vertexMaterial(s);
  double sum = 0, var = 0, n = 0;
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    if (!m.valid[i]) continue;
    sum += r.B[i].g;
    var += double(r.stdError[i]) * r.stdError[i];
    ++n;
  }
  ASSERT_EQ(n, 5);
  const double exact = 2.0, mean = sum / n, se = std::sqrt(var) / n;
  EXPECT_NEAR(mean, exact, 4 * se + 0.005 * exact);
  EXPECT_LT(se, 0.05 * exact);  // the test can tell a loss of a few percent
  // Thousands of rays per path: the deep paths were really traced.
  EXPECT_GT(r.stats.get("rays") / r.stats.get("paths"), 1000.0);
}

namespace {
bool warned(const RunStats& st, const std::string& what) {
  for (const auto& w : st.warnings)
    if (w.find(what) != std::string::npos) return true;
  return false;
}
}  // namespace

// A closed box at rho = 0.999: B = E / (1 - rho) = 1000. The default depth
// (-1: Russian roulette alone ends paths) is unbiased: the mean over the
// vertices within 4 standard errors of 1000 (plus 0.5% for the directional
// error of 16 paths' light samples), no warning. Paths average 1000 bounces;
// the old default cap of 1000 bounces lost 0.999^1001 = 37% of B.
TEST(PathTracer, FurnaceNearOneUnbiasedWithTheDefaults) {
  auto sf = scenes::closedBox(1.0, 3, true);
  scenes::setUniform(sf, glm::vec3(0.999f), glm::vec3(1.f));
  const auto r = trace(sf.scene, 16);
  double sum = 0, var = 0;
  for (size_t i = 0; i < r.B.size(); ++i) { sum += r.B[i].g; var += double(r.stdError[i]) * r.stdError[i]; }
  const double n = double(r.B.size()), mean = sum / n, se = std::sqrt(var) / n;
  EXPECT_NEAR(mean, 1000.0, 4 * se + 5.0);
  EXPECT_LT(se, 40.0);  // 4 SE well below the 37% the cap lost
  EXPECT_TRUE(r.stats.warnings.empty()) << r.stats.line("reference");
  EXPECT_EQ(r.stats.get("paths_cut_at_max_depth"), 0.0);
  EXPECT_GT(r.stats.get("rays") / r.stats.get("paths"), 500.0);  // the long paths were traced
}

// A depth limit that cuts paths: B short by about rho^(k+1) and a warning
// saying the missing light is not in the error bars. k = 100 at rho 0.999
// loses 90%: the mean lies far below 1000 while the reported errors are
// small. A perfect mirror trap with no limit: cut at the cap, and warned.
TEST(PathTracer, DepthLimitThatTruncatesWarns) {
  auto sf = scenes::closedBox(1.0, 3, true);
  scenes::setUniform(sf, glm::vec3(0.999f), glm::vec3(1.f));
  PathTraceOptions o;
  o.maxDepth = 100;
  const auto r = trace(sf.scene, 16, o);
  double mean = 0;
  for (const auto& b : r.B) mean += b.g / double(r.B.size());
  EXPECT_LT(mean, 200.0);
  EXPECT_NEAR(mean, 1000.0 * (1.0 - std::pow(0.999, 101)), 15.0);  // the truncated furnace sum
  ASSERT_TRUE(warned(r.stats, "max_depth = 100 cut")) << r.stats.line("reference");
  EXPECT_NE(r.stats.line("reference").find("WARNING: max_depth"), std::string::npos);
  // Light that needs no more bounces than the limit: nothing cut, no warning.
  scenes::setUniform(sf, glm::vec3(0.f), glm::vec3(1.f));
  o.maxDepth = 0;
  const auto d = trace(sf.scene, 4, o);
  EXPECT_TRUE(d.stats.warnings.empty()) << d.stats.line("reference");
  // A grey room (0.5) with one white mirror wall at 8 bounces misses about
  // 0.58^9 = 0.7% of B, below the run's error: no warning. The share was
  // the largest reflectance's, 1^9 = 100%, whenever a white mirror was in
  // the scene (an outside audit, 5 December 2026).
  scenes::setUniform(sf, glm::vec3(0.5f), glm::vec3(1.f));
  sf.scene.material.assign(sf.scene.faceCount(), Material::Diffuse);
  size_t mirrors = 0;
  for (size_t f = 0; f < sf.scene.faceCount(); ++f)
    if (sf.scene.toWorld(sf.scene.positions[sf.scene.triangles[f].x]).x > 0.499 &&
        sf.scene.toWorld(sf.scene.positions[sf.scene.triangles[f].y]).x > 0.499 &&
        sf.scene.toWorld(sf.scene.positions[sf.scene.triangles[f].z]).x > 0.499) {
      sf.scene.material[f] = Material::Mirror;
      sf.scene.rho[f] = glm::vec3(1.f);
      sf.scene.emission[f] = glm::vec3(0.f);
      ++mirrors;
    }
  ASSERT_GT(mirrors, 0u);
  o.maxDepth = 8;
  const auto m = trace(sf.scene, 16, o);
  EXPECT_GT(m.stats.get("paths_cut_at_max_depth"), 0.0);
  EXPECT_LT(m.stats.get("mean_relative_std_error"), 0.5);
  EXPECT_FALSE(warned(m.stats, "max_depth = 8 cut")) << m.stats.line("reference");
}

// No limit, yet a path caught between perfect mirrors (which Russian roulette
// never ends) must stop: a closed box of white mirrors (floor included) over
// a diffuse patch 1/1000 of its side: a path leaving the patch lands on it
// again with probability about 1e-6 per return to the floor, so nearly every
// path reaches the cap of 100,000 bounces: cut, counted and warned about.
TEST(PathTracer, PathsCaughtBetweenMirrorsAreCutAndWarned) {
  Scene s = mirrorShaft(1.0, 1.0, 0.5f, 1.f);
  const size_t nf = s.faceCount();
  for (size_t f = nf - 4; f < nf; ++f) {  // the floor becomes a mirror too
    s.material[f] = Material::Mirror;
    s.rho[f] = glm::vec3(1.f);
    s.emission[f] = glm::vec3(0.f);
  }
  const double a = 0.0005, z = 1e-4;
  Scene patch = Scene::fromAbsolute({{-a, -a, z}, {a, -a, z}, {a, a, z}, {-a, a, z}, {0, 0, z}},
                                    {{4, 0, 1}, {4, 1, 2}, {4, 2, 3}, {4, 3, 0}});
  patch.rho.assign(4, glm::vec3(0.5f));
  patch.emission.assign(4, glm::vec3(1.f));
  patch.material.assign(4, Material::Diffuse);
  s.append(patch);
  const auto r = trace(s, 1);
  const double paths = r.stats.get("paths"), cut = r.stats.get("paths_cut_at_max_depth");
  ASSERT_EQ(paths, 5.0);
  EXPECT_GE(cut, 4.0);
  EXPECT_TRUE(warned(r.stats, "still going after 100000 bounces")) << r.stats.line("reference");
}
