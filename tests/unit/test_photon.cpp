// Photon mapping and the specular materials against analytic values: Fresnel
// and Snell's law, power conservation (diffuse and through glass), the furnace,
// determinism across thread counts, the work a scene does not need skipped,
// point and spot lights, and a diffuse Cornell box against radiosity and the
// path tracer. Mirrors and glass: test_photon_mirror.cpp.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>

#include "gi/color.h"
#include "gi/form_factor_analytic.h"
#include "gi/pathtrace.h"
#include "gi/photon.h"
#include "gi/radiosity.h"
#include "gi/sampling.h"
#include "gi/scenes.h"
#include "gi/specular.h"
#include "render_test_helpers.h"
#include "test_helpers.h"

using namespace gi;

namespace {

// The furnace: inside a closed sphere (1,280 faces facing in) of uniform
// reflectance rho and emission E = 1, B = E / (1 - rho) everywhere.
VertexRadiometry furnace(const glm::vec3& rho, const PhotonOptions& o) {
  auto sf = scenes::sphere(1.0, 3, true);
  scenes::setUniform(sf, rho, glm::vec3(1.f));
  auto caster = makeEmbreeCaster(sf.scene);
  return computePhotonMap(sf.scene, *caster, o);
}

}  // namespace

// Fresnel: ((n - 1) / (n + 1))^2 = 0.04 at normal incidence for n = 1.5; the
// same value from both sides along a refracted pair (reciprocity); 1 beyond
// the critical angle asin(1 / 1.5) = 41.8 deg; Snell's law for the direction.
TEST(Specular, FresnelAndSnell) {
  EXPECT_NEAR(fresnelDielectric(1.f, 1.f / 1.5f), 0.04f, 1e-6f);
  EXPECT_NEAR(fresnelDielectric(1.f, 1.5f), 0.04f, 1e-6f);
  EXPECT_NEAR(fresnelDielectric(0.3f, 1.f), 0.f, 1e-7f);
  EXPECT_EQ(fresnelDielectric(std::cos(glm::radians(42.f)), 1.5f), 1.f);
  EXPECT_LT(fresnelDielectric(std::cos(glm::radians(41.f)), 1.5f), 1.f);
  for (float deg : {10.f, 30.f, 60.f, 85.f}) {
    const float cosI = std::cos(glm::radians(deg)), eta = 1.f / 1.5f;
    const float sinT = eta * std::sin(glm::radians(deg)), cosT = std::sqrt(1 - sinT * sinT);
    EXPECT_NEAR(fresnelDielectric(cosI, eta), fresnelDielectric(cosT, 1.f / eta), 1e-5f) << deg;
    // Refraction of d = (sin, -cos, 0) into glass below the face y = 0 (normal +y).
    const glm::vec3 d(std::sin(glm::radians(deg)), -cosI, 0.f);
    const SpecularEvent ev = scatterSpecular(Material::Glass, d, {0, 1, 0}, glm::vec3(1.f), 1.5f, 0.9999f);
    ASSERT_TRUE(ev.transmitted);
    EXPECT_NEAR(ev.d.x, sinT, 1e-5f);
    EXPECT_NEAR(ev.d.y, -cosT, 1e-5f);
    EXPECT_NEAR(ev.radianceScale, eta * eta, 1e-6f);
    const SpecularEvent m = scatterSpecular(Material::Mirror, d, {0, 1, 0}, glm::vec3(0.9f), 1.5f, 0.5f);
    EXPECT_NEAR(m.d.y, cosI, 1e-6f);
    EXPECT_NEAR(m.d.x, d.x, 1e-6f);
    EXPECT_EQ(m.weight, glm::vec3(0.9f));
  }
  // From inside at 60 deg: total internal reflection.
  const glm::vec3 d(std::sin(glm::radians(60.f)), std::cos(glm::radians(60.f)), 0.f);
  const SpecularEvent tir = scatterSpecular(Material::Glass, d, {0, 1, 0}, glm::vec3(1.f), 1.5f, 0.99f);
  EXPECT_TRUE(tir.totalInternal);
  EXPECT_FALSE(tir.transmitted);
}

// The reflect / refract choice is made with probability F: 100k draws at
// 70 deg (F = 0.1751), binomial standard error 0.0012; tolerance 5 sigma.
TEST(Specular, ReflectionProbabilityIsFresnel) {
  const float th = glm::radians(70.f);
  const glm::vec3 d(std::sin(th), -std::cos(th), 0.f);
  const float F = fresnelDielectric(std::cos(th), 1.f / 1.5f);
  Rng rng(7);
  int reflected = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i)
    if (!scatterSpecular(Material::Glass, d, {0, 1, 0}, glm::vec3(1.f), 1.5f, rng.next()).transmitted) ++reflected;
  const double sigma = std::sqrt(F * (1 - F) / n);
  EXPECT_NEAR(double(reflected) / n, F, 5 * sigma);
}

// In a closed box every photon lands somewhere, and each bounce keeps rho of
// the power in expectation: stored power = P (1 + rho + rho^2 + ...) = P / (1 - rho).
// 200k photons, rho = 0.5: tolerance 2%.
TEST(PhotonMap, PowerConservationInClosedBox) {
  auto sf = scenes::closedBox(1.0, 4, true);
  const size_t nf = sf.scene.faceCount();
  sf.scene.rho.assign(nf, glm::vec3(0.5f));
  sf.scene.emission.assign(nf, glm::vec3(0.f));
  sf.scene.emission[0] = sf.scene.emission[1] = glm::vec3(10.f);
  auto caster = makeEmbreeCaster(sf.scene);
  PhotonOptions o;
  PhotonTraceStats st;
  const auto photons = tracePhotons(sf.scene, *caster, o, 0, 200000, Progress(nullptr), st);
  double stored = 0;
  for (const auto& p : photons) stored += p.power.g;
  const double P = 10.0 * (faceArea(sf.scene, 0) + faceArea(sf.scene, 1));
  EXPECT_NEAR(stored / (P / (1 - 0.5)), 1.0, 0.02);
  EXPECT_EQ(st.emitted, 200000u);
  EXPECT_EQ(st.caustic, 0u);
}

// A closed glass cube around a light (a small emitting cube, black) inside a
// black room: every path ends stored on a black face or cut at max_depth, and
// glass changes no photon's power, so stored + cut = emitted exactly (float
// sums: 1e-4). With index 1.0 the glass vanishes: everything reaches the room,
// no reflection at all; with 1.5 total internal reflection occurs and light
// returns to the lamp.
TEST(PhotonMap, GlassBoxAroundTheLightConservesPower) {
  for (float ior : {1.0f, 1.5f}) {
    SCOPED_TRACE(ior);
    auto room = scenes::closedBox(4.0, 2, true);
    scenes::setUniform(room, glm::vec3(0.f), glm::vec3(0.f));
    auto glass = scenes::closedBox(1.0, 2, false);
    glass.scene.rho.assign(glass.scene.faceCount(), glm::vec3(1.f));
    glass.scene.material.assign(glass.scene.faceCount(), Material::Glass);
    glass.scene.ior.assign(glass.scene.faceCount(), ior);
    auto lamp = scenes::closedBox(0.2, 1, false);
    scenes::setUniform(lamp, glm::vec3(0.f), glm::vec3(5.f));
    Scene s = room.scene;
    const size_t roomFaces = s.faceCount();
    s.append(glass.scene);
    s.append(lamp.scene);
    auto caster = makeEmbreeCaster(s);
    PhotonOptions o;
    o.maxDepth = 200;
    PhotonTraceStats st;
    const auto photons = tracePhotons(s, *caster, o, 0, 100000, Progress(nullptr), st);
    double toRoom = 0, total = 0;
    for (const auto& p : photons) {
      total += luminance(p.power);
      const glm::vec3 q = glm::abs(p.p);
      if (std::max({q.x, q.y, q.z}) > 1.9f) toRoom += luminance(p.power);
    }
    (void)roomFaces;
    EXPECT_NEAR((total + st.lostPower) / st.emittedPower, 1.0, 1e-4);
    EXPECT_EQ(st.escaped, 0u);
    if (ior == 1.0f) {
      EXPECT_NEAR(toRoom / st.emittedPower, 1.0, 1e-4);
      EXPECT_EQ(st.totalInternal, 0u);
    } else {
      EXPECT_GT(st.totalInternal, 1000u);
      EXPECT_LT(toRoom / st.emittedPower, 0.999);
      EXPECT_GT(toRoom / st.emittedPower, 0.5);
    }
  }
}

// The furnace: B = E / (1 - rho) = 2 for E = 1, rho = 0.5 (all bounces),
// in each of the three modes. 200k photons, k = 200 (50 per gather lookup):
// mean within 3%; every vertex within 15% (all light from photons), 10%
// (direct light apart), 8% (final gather, 32 rays).
TEST(PhotonMap, FurnaceSphere) {
  auto sf = scenes::sphere(1.0, 3, true);
  scenes::setUniform(sf, glm::vec3(0.5f), glm::vec3(1.f));
  auto caster = makeEmbreeCaster(sf.scene);
  for (int mode = 0; mode < 3; ++mode) {
    PhotonOptions o;
    o.photons = 200000;
    o.kNearest = mode == 2 ? 50 : 200;  // the gather averages 32 lookups: fewer photons each
    o.directLight = mode > 0;
    o.finalGather = mode == 2;
    o.gatherRays = 32;
    const VertexRadiometry r = computePhotonMap(sf.scene, *caster, o);
    double mean = 0;
    const double tol = mode == 0 ? 0.3 : mode == 1 ? 0.2 : 0.16;
    for (const auto& b : r.B) {
      mean += b.g;
      EXPECT_NEAR(b.g, 2.0, tol) << "mode " << mode;
    }
    EXPECT_NEAR(mean / double(r.B.size()), 2.0, 0.06) << "mode " << mode;
  }
}

// rho -> 1: rho = 0.98 gives B = E / (1 - rho) = 50 (paths of 50 bounces on
// average; Russian roulette survives with rho, so weights stay bounded).
// 20k photons (about 1M stored), k = 400: mean within 3%, every vertex within 25%.
TEST(PhotonMap, FurnaceNearOne) {
  PhotonOptions o;
  o.photons = 20000;
  o.kNearest = 400;
  o.maxDepth = 5000;
  const VertexRadiometry r = furnace(glm::vec3(0.98f), o);
  double mean = 0;
  for (const auto& b : r.B) {
    mean += b.g;
    EXPECT_NEAR(b.g, 50.0, 12.5);
  }
  EXPECT_NEAR(mean / double(r.B.size()), 50.0, 1.5);
}

// The warning of max_depth bounds how dark the result is in a coloured
// furnace: rho (0.9, 0.5, 0.1), E = 1, 8 bounces. Red keeps 0.9^9 = 39% of
// its power past the cut and the luminance of B = E / (1 - rho) is 58% red,
// so the result is about 20% dark (measured: 20.4%); the luminance of the
// cut paths' power is only 8.4% of the emitted (what the warning said
// before: an outside audit found 5% said for 16.5% dark). The stated share
// must cover the measured darkness (within 2%: 60,000 photons, k = 200)
// and be red's own share (39.0%; at most 0.9^8 = 43%).
TEST(PhotonMap, DepthCutWarningBoundsTheDarknessOfAColour) {
  const glm::vec3 rho(0.9f, 0.5f, 0.1f);
  PhotonOptions o;
  o.photons = 60000;
  o.kNearest = 200;
  o.maxDepth = 8;
  const VertexRadiometry r = furnace(rho, o);
  double mean = 0;
  for (const auto& b : r.B) mean += luminance(b);
  mean /= double(r.B.size());
  const double exact = luminance(glm::vec3(1.f) / (glm::vec3(1.f) - rho)), dark = 1.0 - mean / exact;
  EXPECT_GT(dark, 0.15);
  double stated = -1;
  for (const std::string& w : r.stats.warnings)
    if (w.find("paths cut at max_depth") != std::string::npos)
      stated = std::stod(w.substr(w.find("still carried ") + 14)) / 100.0;
  ASSERT_GT(stated, 0.0) << "no warning of the cut";
  std::printf("coloured furnace, 8 bounces: %.1f%% dark, the warning says up to %.1f%%\n", 100 * dark, 100 * stated);
  EXPECT_GE(stated, dark - 0.02) << "stated " << stated << ", measured darkness " << dark;
  EXPECT_LE(stated, std::pow(0.9, 8) * 1.02);
}

TEST(PhotonMap, DeterministicAcrossThreadCounts) {
  const Scene s = scenes::causticCornell(100.0, 50.0, 2, 1.5f);
  auto caster = makeEmbreeCaster(s);
  PhotonOptions o;
  o.photons = 20000;
  o.lightSamples = 16;
  VertexRadiometry a, b;
  { tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1); a = computePhotonMap(s, *caster, o); }
  { tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2); b = computePhotonMap(s, *caster, o); }
  EXPECT_EQ(a.B, b.B);
  o.progressive = true;
  o.passes = 2;
  { tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1); a = computePhotonMap(s, *caster, o); }
  { tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2); b = computePhotonMap(s, *caster, o); }
  EXPECT_EQ(a.B, b.B);
}

// Work the scene does not need is skipped and said: with rho = 0 everywhere
// and no mirror or glass, the direct light is the whole answer and no photon
// is traced; without specular faces there is no caustic map.
TEST(PhotonMap, SkipsWhatTheSceneDoesNotNeed) {
  auto sf = scenes::parallelPlates(1.0, 4);
  auto caster = makeEmbreeCaster(sf.scene);
  PhotonOptions o;
  o.photons = 10000;
  const VertexRadiometry r = computePhotonMap(sf.scene, *caster, o);
  EXPECT_EQ(r.stats.get("photons_emitted", -1.0), -1.0);
  bool said = false;
  for (const auto& n : r.stats.notes) said |= n.find("no photons traced") != std::string::npos;
  EXPECT_TRUE(said);
  const size_t top = test::nearestVertex(sf.scene, {0, 0, 1});
  EXPECT_NEAR(r.H[top].g, 0.2394, 0.005);  // point-to-square factor at the centre, 1 apart (direct light only)
  auto box = scenes::cornellBox(100.0);
  auto c2 = makeEmbreeCaster(box.scene);
  const VertexRadiometry r2 = computePhotonMap(box.scene, *c2, o);
  EXPECT_EQ(r2.stats.get("photons_caustic_map", -1.0), 0.0);
  said = false;
  for (const auto& n : r2.stats.notes) said |= n.find("no caustic map") != std::string::npos;
  EXPECT_TRUE(said);
}

// Point and spot lights: a point light of intensity I at height h over a
// black plane gives H = I cos / r^2 (at the centre I / h^2); photons alone
// (2M photons, k = 400, max radius 0.05: bias below 1% from the curvature of
// H) within 5%, the direct light by sampling exactly (up to the ray offset:
// 1e-3 absolute, 3e-4 relative). A spot of half
// angle 20 degrees pointing down lights the centre and not a point 45 degrees
// off the axis, and its photons carry its power 2 pi (1 - cos a) I.
TEST(PhotonMap, PointAndSpotLights) {
  auto sf = scenes::openPlane(4.0, 40);
  sf.scene.rho.assign(sf.scene.faceCount(), glm::vec3(0.f));
  sf.scene.emission.assign(sf.scene.faceCount(), glm::vec3(0.f));
  auto caster = makeEmbreeCaster(sf.scene);
  const float I = 3.f, h = 1.f;
  PhotonOptions o;
  o.point.position = glm::vec3(glm::dvec3(0, 0, h) - sf.scene.origin);
  o.point.intensity = glm::vec3(I);
  o.photons = 2000000;
  o.kNearest = 400;
  o.maxRadius = 0.05;
  o.directLight = false;
  const size_t centre = test::nearestVertex(sf.scene, {0, 0, 0}), off = test::nearestVertex(sf.scene, {1, 0, 0});
  const VertexRadiometry photonsOnly = computePhotonMap(sf.scene, *caster, o);
  EXPECT_NEAR(photonsOnly.H[centre].g / (I / (h * h)), 1.0, 0.05);
  const double cosOff = 1 / std::sqrt(2.0);
  EXPECT_NEAR(photonsOnly.H[off].g / (I * cosOff / 2.0), 1.0, 0.05);
  o.directLight = true;
  o.photons = 1000;
  const VertexRadiometry direct = computePhotonMap(sf.scene, *caster, o);
  EXPECT_NEAR(direct.H[centre].g, I / (h * h), 1e-3);
  EXPECT_NEAR(direct.H[off].g, I * cosOff / 2.0, 1e-3);
  o.point.spotDirection = glm::vec3(0, 0, -1);
  o.point.spotAngleDeg = 20.f;
  const VertexRadiometry spot = computePhotonMap(sf.scene, *caster, o);
  EXPECT_NEAR(spot.H[centre].g, I / (h * h), 1e-3);
  EXPECT_EQ(spot.H[off].g, 0.f);
  PhotonTraceStats st;
  o.photons = 10000;
  const auto ph = tracePhotons(sf.scene, *caster, o, 0, 10000, Progress(nullptr), st);
  double stored = 0;
  for (const auto& p : ph) stored += p.power.g;
  const double power = 2 * M_PI * (1 - std::cos(glm::radians(20.0))) * I;
  EXPECT_NEAR(stored / power, 1.0, 1e-3);  // every photon of a 20-degree cone lands on the 4 x 4 plane
}

// The diffuse Cornell box: photon mapping agrees with the radiosity filter
// and with the path tracer. Per wall (area-weighted mean over faces off the
// sheets' borders, the vertex values averaged per face): progressive photon
// mapping (32 passes of 100k photons) within 3% of radiosity (4,096 rays per
// patch, converged) on the walls and 8% on the block sides (few patches,
// steep gradients), the same against the path tracer (256 paths per vertex).
TEST(PhotonMap, DiffuseCornellBoxAgreesWithRadiosityAndPathTracer) {
  auto sf = scenes::cornellBox(50.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions ro;
  ro.formFactors.raysPerPatch = 4096;
  ro.lightSamples = 1024;
  ro.tolerance = 1e-7;
  const auto rad = solveRadiosity(s, *caster, ro);
  PathTraceOptions po;
  po.samplesPerVertex = 256;
  const auto pt = pathTrace(s, *caster, po);
  PhotonOptions o;
  o.photons = 100000;
  o.progressive = true;
  o.passes = 32;
  o.lightSamples = 1024;
  const VertexRadiometry pm = computePhotonMap(s, *caster, o);
  auto faceMean = [&](const std::vector<glm::vec3>& B) {
    return [&s, &B](size_t f) {
      double m = 0;
      for (int k = 0; k < 3; ++k) m += luminance(B[s.triangles[f][k]]) / 3;
      return m;
    };
  };
  // Per vertex against the path tracer (the same per-vertex quantity), the
  // creases and corners included (the per-wall sums leave them out): the
  // sums of B over the vertices the light reaches agree within 3% (their
  // standard error, from the errors both report, is 0.06%; the rest is
  // progressive photon mapping's remaining bias: 0.6% seen). Before the
  // estimates divided by the surface inside the gather sphere, 0.958.
  double sumPM = 0, sumPT = 0;
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    if (luminance(pt.B[i]) <= 0.f) continue;  // under the blocks
    sumPM += luminance(pm.B[i]);
    sumPT += luminance(pt.B[i]);
  }
  EXPECT_NEAR(sumPM / sumPT, 1.0, 0.03);
  int compared = 0;
  for (const auto& [name, reference] : {std::pair<std::string, int>{"radiosity", 0}, {"path tracer", 1}}) {
    const auto groups = test::wallSums(
        s, reference == 0 ? std::function<double(size_t)>([&](size_t f) { return test::wholePatchMean(rad, f); })
                          : std::function<double(size_t)>(faceMean(pt.B)),
        faceMean(pm.B));
    for (const auto& [k, g] : groups) {
      if (g[0] < 5e3) continue;  // tiny groups (mm^2)
      EXPECT_NEAR(g[2] / g[1], 1.0, g[0] > 1e5 ? 0.03 : 0.08) << name << " " << k;
      ++compared;
    }
  }
  EXPECT_GE(compared, 16);
}

// More luminaires than direct light takes one by one (a 20 x 20 grid of
// separate emitting squares above a floor: power sampling with MIS) make the
// direct light a Monte Carlo estimate, whose noise the error bars now hold:
// they were the photons' alone, 0 where the photons added nothing (1,600
// squares read 9% off in RMS, up to 44%, with error bars of 0; an outside
// audit). The same photons, 16 against 4,096 light samples: the difference
// is the direct light's noise, and its z-scores by the 16-sample run's bars
// spread at most 1.5 wide (their quasi-random samples beat the bound).
TEST(PhotonMap, SampledDirectLightIsInTheErrorBars) {
  test::SceneBuilder b;
  b.quad({0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, glm::vec3(0.5f), glm::vec3(0.f), Material::Diffuse, 8);  // floor, +y
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) {
      const double x = 0.05 * i + 0.01, z = 0.05 * j + 0.01;
      b.quad({x, 0.05, z}, {x + 0.03, 0.05, z}, {x + 0.03, 0.05, z + 0.03}, {x, 0.05, z + 0.03}, glm::vec3(0.f),
             glm::vec3(1.f));  // facing down
    }
  const Scene s = b.build();
  auto caster = makeEmbreeCaster(s);
  PhotonOptions o;
  o.photons = 20000;
  o.lightSamples = 16;
  const VertexRadiometry few = computePhotonMap(s, *caster, o);
  o.lightSamples = 4096;
  const VertexRadiometry many = computePhotonMap(s, *caster, o);
  double z2 = 0;
  int n = 0, zeroBars = 0;
  for (size_t v = 0; v < 81; ++v) {  // the floor's vertices
    const double d = luminance(few.B[v]) - luminance(many.B[v]);
    if (few.stdError[v] == 0.f) { ++zeroBars; continue; }
    z2 += d * d / (double(few.stdError[v]) * few.stdError[v]), ++n;
  }
  std::printf("%d floor vertices: RMS z %.2f, %d with an error bar of 0\n", n, std::sqrt(z2 / std::max(n, 1)), zeroBars);
  EXPECT_EQ(zeroBars, 0);
  ASSERT_GT(n, 70);
  EXPECT_LT(std::sqrt(z2 / n), 1.5);
}
