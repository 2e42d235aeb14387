// The eye pass at the ends of its parameter ranges, where single precision
// or a missing light gave wrong pictures (an outside review, 6 December
// 2026): a small sun seen directly or in a mirror, a telephoto camera far
// from the scene, the sun through glass in the two-pass view's caustic map,
// and caustic_k below 3; the path-traced error bars at few samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "gi/photon.h"
#include "gi/render.h"
#include "gi/scenes.h"
#include "gi/sky.h"
#include "render_test_helpers.h"

using namespace gi;
using gi::test::SceneBuilder;

namespace {

RenderResult run(const Scene& s, const RenderOptions& o) {
  auto caster = makeEmbreeCaster(s);
  return render(s, *caster, o);
}

bool warned(const RunStats& st, const std::string& text) {
  for (const std::string& w : st.warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

// A camera looking at the sun, directly and in a horizontal mirror (rho 1),
// one pixel of fov 0.1 degrees around the disk: the pixel's mean radiance is
// L_sun Omega_disk / A_pixel = E_sun sunDiskScale(a) / (4 tan^2(fov / 2))
// (the disk wholly inside the pixel; the image plane's cos^3 is 1 - 1e-6
// there). The cone of the disk was tested in single precision: at 0.01
// degrees a cos test admitted 6.5 times the disk (the sun 6.5 times too
// bright), at 0.05 degrees 1.2 times. Tolerance: 4 of the pixel's reported
// standard errors plus 1%.
TEST(RenderPrecision, SmallSunHasItsIrradianceDirectlyAndInAMirror) {
  SceneBuilder b;
  b.quad({-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, glm::vec3(1.f), glm::vec3(0.f), Material::Mirror);
  const Scene s = b.build();
  const double fov = 0.1, t = std::tan(0.5 * fov * M_PI / 180.0);
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.3, 1.0, 0.2));
  for (float a : {0.01f, 0.05f}) {
    for (bool mirror : {false, true}) {
      RenderOptions o;
      o.mode = RenderMode::PathTraced;
      o.samplesPerPixel = 1 << 16;
      o.sunIrradiance = glm::vec3(2.f);
      o.sunDirection = glm::vec3(sun);
      o.sunAngularRadiusDeg = a;
      // Directly: from above the mirror, towards the sun; in the mirror:
      // towards the mirror's image of the sun (its point at the origin).
      const glm::dvec3 eye = mirror ? glm::dvec3(-3 * sun.x, 3 * sun.y, -3 * sun.z) : glm::dvec3(0, 1, 0);
      const glm::dvec3 target = mirror ? glm::dvec3(0.0) : eye + sun;
      o.camera = Camera::lookAt(eye, target, {0, 0, 1}, fov, 1, 1);
      const RenderResult r = run(s, o);
      const double expected = 2.0 * double(sunDiskScale(a)) / (4 * t * t);
      const double got = r.image.px[0].g;
      EXPECT_NEAR(got, expected, 4 * r.stdError[0] + 0.01 * expected)
          << "sun radius " << a << (mirror ? " in the mirror" : " directly");
    }
  }
}

// An oblique telephoto view of a floor lit by a sharp sun from 400 scene
// diagonals (fov 0.12 degrees): every pixel that sees the floor shows
// rho E cos / pi (Whitted's one shadow ray is exact here). The hit point
// computed along the float ray was off the floor by about D 6e-8, beyond the
// ray offset: shadow rays from below the floor made 17 to 36% of such pixels
// black (acne). Allowed: pixels on the floor's border.
TEST(RenderPrecision, FarTelephotoCameraKeepsHitsOnTheirFaces) {
  SceneBuilder b;
  b.quad({-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, glm::vec3(0.6f), glm::vec3(0.f), Material::Diffuse, 8);
  const Scene s = b.build();
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.4, 1.0, -0.3));
  const glm::dvec3 view = glm::normalize(glm::dvec3(0.53, 0.71, -0.46));
  const double D = 400 * std::sqrt(32.0);
  RenderOptions o;
  o.mode = RenderMode::Whitted;
  o.samplesPerPixel = 4;
  o.sunIrradiance = glm::vec3(3.f);
  o.sunDirection = glm::vec3(sun);
  o.sunAngularRadiusDeg = 0.f;
  const int W = 48, H = 32;
  o.camera = Camera::lookAt(D * view, {0.1, 0, 0.05}, {0, 1, 0}, 0.12, W, H);
  const RenderResult r = run(s, o);
  const double expected = 0.6 * 3.0 * sun.y / M_PI;
  int inside = 0, dark = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      bool all = true;  // the pixel's four corners' rays meet the floor within it
      for (float cx : {0.f, 1.f})
        for (float cy : {0.f, 1.f}) {
          const Ray ray = o.camera.ray({float(x) + cx, float(y) + cy}, {0.5f, 0.5f}, {0, 0, 0});
          const glm::dvec3 d(ray.d), p = glm::dvec3(ray.o) + d * (-double(ray.o.y) / d.y);
          all = all && d.y < 0 && std::fabs(p.x) < 1.99 && std::fabs(p.z) < 1.99;
        }
      if (!all) continue;
      ++inside;
      const double v = r.image.at(x, y).g;
      if (std::fabs(v - expected) > 1e-3 * expected) ++dark;
    }
  ASSERT_GT(inside, W * H / 4);
  EXPECT_EQ(dark, 0) << "of " << inside << " pixels on the floor, expected " << expected;
}

// The sun through a glass cube onto a floor, seen in the two-pass view's
// final-gather mode: direct light treats glass as a blocker, so the floor
// under the cube is lit only by the caustic map. The map held the emitters'
// and the point light's photons only: that floor was black. Now the global
// trace's caustic photons carry the sun's; the window's mean against the
// path-traced image (1024 paths a pixel) within 4 combined standard errors
// plus 5% (the density estimate's blur over a 10-degree sun's soft edge).
TEST(RenderPrecision, TwoPassCausticMapHoldsTheSun) {
  SceneBuilder b;
  b.quad({-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, glm::vec3(0.5f), glm::vec3(0.f), Material::Diffuse, 20);
  b.box({-0.5, 0.5, -0.5}, {0.5, 1.1, 0.5}, glm::vec3(1.f), glm::vec3(0.f), Material::Glass, false);
  const Scene s = b.build();
  auto caster = makeEmbreeCaster(s);
  PhotonOptions po;
  po.photons = 100000;
  po.outside.sunIrradiance = glm::vec3(4.f);
  po.outside.sunDirection = glm::vec3(0.f, 1.f, 0.f);
  po.outside.sunAngularRadiusDeg = 10.f;
  const VertexRadiometry first = computePhotonMap(s, *caster, po);
  RenderOptions o;
  o.camera = Camera::lookAt({0, 1.2, -2.5}, {0, 0, 0}, {0, 1, 0}, 14, 40, 30);
  o.mode = RenderMode::TwoPass;
  o.twoPass = TwoPassDiffuse::FinalGather;
  o.samplesPerPixel = 16;
  o.sunIrradiance = po.outside.sunIrradiance;
  o.sunDirection = po.outside.sunDirection;
  o.sunAngularRadiusDeg = po.outside.sunAngularRadiusDeg;
  o.causticPhotons = 400000;
  o.firstPassB = first.B;
  const RenderResult tp = render(s, *caster, o);
  EXPECT_GT(tp.stats.get("caustic_photons_stored"), 10000.0);
  o.mode = RenderMode::PathTraced;
  o.samplesPerPixel = 1024;
  const RenderResult pt = render(s, *caster, o);
  const double w = 0.2;  // the floor under the cube's middle, seen below the floating cube
  double a = 0, c = 0, va = 0, vc = 0;
  int n = 0;
  for (int j = 0; j < 30; ++j)
    for (int i = 0; i < 40; ++i) {
      const Ray r = o.camera.ray({i + 0.5f, j + 0.5f}, {0.5f, 0.5f}, {0, 0, 0});
      if (r.d.y >= 0.f) continue;
      const glm::dvec3 x = glm::dvec3(r.o) + glm::dvec3(r.d) * (-double(r.o.y) / r.d.y);
      if (std::fabs(x.x) > w || std::fabs(x.z) > w) continue;
      const size_t p = size_t(j) * 40 + size_t(i);
      a += luminance(tp.image.px[p]);
      c += luminance(pt.image.px[p]);
      va += double(tp.stdError[p]) * tp.stdError[p];
      vc += double(pt.stdError[p]) * pt.stdError[p];
      ++n;
    }
  ASSERT_GT(n, 20);
  const double sigma = std::sqrt(va + vc) / n;
  EXPECT_GT(c / n, 0.1) << "the path-traced window is lit: the test measures the sun's caustic";
  EXPECT_NEAR(a / n, c / n, 4 * sigma + 0.05 * c / n) << "two-pass " << a / n << ", path traced " << c / n;
}

// caustic_k 1 and 2: the k-nearest estimate has no finite mean or variance;
// the view warns as photon mapping does (it said nothing).
TEST(RenderPrecision, CausticKBelowThreeIsWarned) {
  SceneBuilder b;
  b.quad({-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, glm::vec3(0.5f), glm::vec3(0.f), Material::Diffuse, 4);
  b.quad({-1, 2, -1}, {1, 2, -1}, {1, 2, 1}, {-1, 2, 1}, glm::vec3(0.f), glm::vec3(10.f));
  b.box({-0.4, 0.5, -0.4}, {0.4, 1.1, 0.4}, glm::vec3(1.f), glm::vec3(0.f), Material::Glass, false);
  const Scene s = b.build();
  for (int k : {1, 2, 3}) {
    RenderOptions o;
    o.camera = Camera::lookAt({0, 0.45, -2.5}, {0, 0, 0}, {0, 1, 0}, 30, 8, 6);
    o.mode = RenderMode::TwoPass;
    o.twoPass = TwoPassDiffuse::FinalGather;
    o.samplesPerPixel = 1;
    o.causticPhotons = 2000;
    o.causticK = k;
    o.firstPassB.assign(s.vertexCount(), glm::vec3(0.f));
    const RunStats st = run(s, o).stats;
    EXPECT_EQ(warned(st, "caustic_k = " + std::to_string(k)), k < 3) << k;
  }
}

// A closed room lit by the sky through a glass pane over a hole in its
// ceiling: Whitted and the distributed view are black by design (their
// shadow rays stop at glass); the warning says so, where it asked only
// whether the camera was inside an object or looking away. The path-traced
// view is not black.
TEST(RenderPrecision, BlackBehindGlassNamesTheGlass) {
  SceneBuilder b;
  b.box({-1, -1, -1}, {1, 1, 1}, glm::vec3(0.7f), glm::vec3(0.f), Material::Diffuse, true);
  for (auto* v : {&b.rho, &b.E}) v->erase(v->begin() + 6, v->begin() + 8);  // the ceiling (y = 1): a hole
  b.mat.erase(b.mat.begin() + 6, b.mat.begin() + 8);
  b.rough.erase(b.rough.begin() + 6, b.rough.begin() + 8);
  b.tris.erase(b.tris.begin() + 6, b.tris.begin() + 8);
  b.box({-1.2, 1.05, -1.2}, {1.2, 1.3, 1.2}, glm::vec3(1.f), glm::vec3(0.f), Material::Glass, false);
  const Scene s = b.build();
  for (RenderMode m : {RenderMode::Whitted, RenderMode::Distributed, RenderMode::PathTraced}) {
    RenderOptions o;
    o.mode = m;
    o.samplesPerPixel = 16;
    o.skyRadiance = glm::vec3(1.f);
    o.camera = Camera::lookAt({0, 0.5, -0.9}, {0, -1, 0.5}, {0, 1, 0}, 60, 12, 8);
    const RunStats st = run(s, o).stats;
    const bool black = m != RenderMode::PathTraced;
    EXPECT_EQ(warned(st, "the image is black"), black) << renderModeName(m);
    EXPECT_EQ(warned(st, "only reached through mirrors or glass"), black) << renderModeName(m);
  }
}

// The path-traced view's per-pixel error bars at the default 16 samples: in
// a white furnace (every face emits E = 1, reflects rho = 1/2: radiance
// 2 / pi everywhere) 19.5% of the pixels lay beyond 3 of their own standard
// errors (0.27% expected; an outside audit): a few paths' sample variance
// is skewed low. Pooled with the pixels around (at least their mean
// variance): at most 1% beyond 3, over 3 seeds. At one sample per pixel
// the error bars were all 0 (another audit); they are the spread of the
// pixels around, and a single path's value is far from normal (its bounce
// count is geometric), so up to 5% may lie beyond 3. At 1 and 2 samples the
// 5 x 5 pixels held too few paths: seen from inside the furnace sphere
// (another audit) mean z^2 4.7 and 1.3, pooled now over at least 100 paths
// (11 x 11 pixels at 1 sample, 9 x 9 at 2): 0.9 to 1.1 and 0.4 to 0.6.
// Bounded here at 1.5 (and 0.3 below: bars too wide).
TEST(RenderPrecision, PathTracedErrorBarsHoldAtOneTwoAndSixteenSamples) {
  SceneBuilder b;
  b.box({-2, -2, -2}, {2, 2, 2}, glm::vec3(0.5f), glm::vec3(1.f), Material::Diffuse, true, 2);
  const Scene box = b.build();
  Scene sphere = scenes::sphere(1.0, 3, true).scene;  // the furnace seen from inside
  sphere.rho.assign(sphere.faceCount(), glm::vec3(0.5f));
  sphere.emission.assign(sphere.faceCount(), glm::vec3(1.f));
  const double L = 2 / M_PI;
  for (int scene = 0; scene < 2; ++scene)
    for (int spp : {16, 2, 1})
      for (uint32_t seed = 0; seed < 3; ++seed) {
        RenderOptions o;
        o.camera = scene == 0 ? Camera::lookAt({-0.5, 0.3, -1.5}, {0.2, 0, 1}, {0, 1, 0}, 70, 32, 32)
                              : Camera::lookAt({0.1, 0.05, -0.2}, {1, 0.3, 0.5}, {0, 1, 0}, 90, 64, 48);
        o.mode = RenderMode::PathTraced;
        o.samplesPerPixel = spp;
        o.maxDepth = 64;
        o.seed = seed;
        const RenderResult p = run(scene == 0 ? box : sphere, o);
        int beyond = 0;
        double z2 = 0;
        for (size_t i = 0; i < p.image.px.size(); ++i) {
          ASSERT_GT(p.stdError[i], 0.f) << spp << " samples, pixel " << i;
          const double z = (luminance(p.image.px[i]) - L) / p.stdError[i];
          beyond += std::fabs(z) > 3, z2 += z * z;
        }
        const double n = double(p.image.px.size());
        std::printf("%s, %d samples, seed %u: %d of %.0f pixels beyond 3 standard errors, mean z^2 %.2f\n",
                    scene == 0 ? "box" : "sphere", spp, seed, beyond, n, z2 / n);
        EXPECT_LE(beyond, (spp == 1 ? 0.05 : 0.01) * n) << scene << ", " << spp << " samples, seed " << seed;
        EXPECT_LT(z2 / n, 1.5) << scene << ", " << spp << " samples, seed " << seed;
        EXPECT_GT(z2 / n, 0.3) << scene << ", " << spp << " samples, seed " << seed << ": the error bars are too wide";
      }
}

// The two-pass view's own point light, sky and sun light the diffuse
// surfaces only through the first pass: 'First pass alone' showed a plane
// under a point light exactly as without it, silently (an outside audit).
// The log says so, and how the other choices use them.
TEST(RenderPrecision, TwoPassSaysWhatItsOwnLightsDo) {
  SceneBuilder b;
  b.quad({-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, glm::vec3(0.5f), glm::vec3(0.f), Material::Diffuse, 4);
  b.quad({-1, 3, -1}, {1, 3, -1}, {1, 3, 1}, {-1, 3, 1}, glm::vec3(0.f), glm::vec3(1.f));  // facing down
  const Scene s = b.build();
  const auto noted = [](const RunStats& st, const std::string& text) {
    return std::any_of(st.notes.begin(), st.notes.end(),
                       [&](const std::string& n) { return n.find(text) != std::string::npos; });
  };
  for (TwoPassDiffuse d : {TwoPassDiffuse::Map, TwoPassDiffuse::DirectIndirect})
    for (bool point : {false, true}) {
      RenderOptions o;
      o.camera = Camera::lookAt({0, 2, -3}, {0, 0, 0}, {0, 1, 0}, 40, 8, 6);
      o.mode = RenderMode::TwoPass;
      o.twoPass = d;
      o.samplesPerPixel = 1;
      o.firstPassB.assign(s.vertexCount(), glm::vec3(0.1f));
      if (point) o.point.position = {0, 1, 0}, o.point.intensity = glm::vec3(1.f);
      const RunStats st = run(s, o).stats;
      const std::string text = d == TwoPassDiffuse::Map ? "'First pass alone': the diffuse surfaces take no light from this view's point light"
                                                        : "this view's point light adds its direct light";
      EXPECT_EQ(noted(st, text), point) << int(d) << (point ? " with" : " without") << " a point light";
    }
}

// Path traced, the per-vertex radiance towards the camera carries its error
// bar (there was none: an outside audit). In the white furnace of the test
// above (radiance 2 / pi everywhere), 16 samples a vertex: mean z^2 near 1,
// at most 1% beyond 3 (the own variance alone put some 20% of the pixels
// there); the other modes give none.
TEST(RenderPrecision, PathTracedVertexRadianceHasErrorBars) {
  SceneBuilder b;
  b.box({-2, -2, -2}, {2, 2, 2}, glm::vec3(0.5f), glm::vec3(1.f), Material::Diffuse, true, 6);
  const Scene s = b.build();
  const double L = 2 / M_PI;
  for (RenderMode m : {RenderMode::PathTraced, RenderMode::Distributed}) {
    RenderOptions o;
    o.camera = Camera::lookAt({-0.5, 0.3, -1.5}, {0.2, 0, 1}, {0, 1, 0}, 70, 8, 8);
    o.mode = m;
    o.renderImage = false;
    o.vertexRadiance = true;
    o.samplesPerPixel = 16;
    o.maxDepth = 64;
    const RenderResult r = run(s, o);
    if (m != RenderMode::PathTraced) {
      EXPECT_TRUE(r.vertexStdError.empty());
      continue;
    }
    ASSERT_EQ(r.vertexStdError.size(), s.vertexCount());
    int n = 0, beyond = 0;
    double z2 = 0;
    for (size_t v = 0; v < s.vertexCount(); ++v) {
      if (!(luminance(r.vertexRadiance[v]) > 0.f)) continue;  // facing away from the camera
      ASSERT_GT(r.vertexStdError[v], 0.f) << "vertex " << v;
      const double z = (luminance(r.vertexRadiance[v]) - L) / r.vertexStdError[v];
      beyond += std::fabs(z) > 3, z2 += z * z, ++n;
    }
    std::printf("%d vertices facing the camera: %d beyond 3 standard errors, mean z^2 %.2f\n", n, beyond, z2 / n);
    ASSERT_GT(n, 100);
    EXPECT_LE(beyond, 0.01 * n);
    EXPECT_LT(z2 / n, 1.5);
    EXPECT_GT(z2 / n, 0.4);
  }
}

// A lens that blurs the scene's centre over more than the image is warned
// of (an aperture of 10 focused 0.1 from the eye gave a black picture
// blamed on the camera's place; an outside audit); a narrow one is not.
TEST(RenderPrecision, DepthOfFieldWiderThanTheImageIsWarned) {
  SceneBuilder b;
  b.quad({-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, glm::vec3(0.5f), glm::vec3(0.f), Material::Diffuse, 2);
  const Scene s = b.build();
  for (const auto& [aperture, focus] : {std::pair{10.0, 0.1}, std::pair{0.01, 0.0}, std::pair{0.0, 0.0}}) {
    RenderOptions o;
    o.camera = Camera::lookAt({0, 2, -3}, {0, 0, 0}, {0, 1, 0}, 40, 16, 12);
    o.camera.setLens(aperture, focus);
    o.samplesPerPixel = 1;
    o.skyRadiance = glm::vec3(1.f);
    const RunStats st = run(s, o).stats;
    EXPECT_EQ(warned(st, "depth of field: the scene's centre"), aperture > 1.0) << aperture << ", " << focus;
  }
}
