// The eye pass (gi/render.h) against exact values: a diffuse plane of known
// radiosity, a mirror, a glass slab, total internal reflection, the thin
// lens's circle of confusion, antialiasing of an edge, and its errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gi/color.h"
#include "gi/pathtrace.h"
#include "gi/render.h"
#include "gi/specular.h"
#include "render_test_helpers.h"

using namespace gi;
using gi::test::SceneBuilder;

namespace {

RenderResult run(const Scene& s, const RenderOptions& o) {
  auto caster = makeEmbreeCaster(s);
  return render(s, *caster, o);
}

RenderOptions opts(RenderMode m, const Camera& cam, int spp) {
  RenderOptions o;
  o.mode = m;
  o.camera = cam;
  o.samplesPerPixel = spp;
  return o;
}

const RenderMode kAllModes[] = {RenderMode::Whitted, RenderMode::Distributed, RenderMode::TwoPass,
                                RenderMode::PathTraced};

// A square at depth z, facing the camera at the origin (normal -z), n x n cells.
void frontQuad(SceneBuilder& b, double half, double z, glm::vec3 rho, glm::vec3 E, Material m = Material::Diffuse,
               int n = 1, double cx = 0, double cy = 0) {
  b.quad({cx - half, cy - half, z}, {cx - half, cy + half, z}, {cx + half, cy + half, z}, {cx + half, cy - half, z},
         rho, E, m, n);
}

}  // namespace

// A camera facing a diffuse plane of radiosity B sees B / pi in every pixel,
// exactly, for any sample count: the two-pass mode with the first pass
// alone. And an emitting plane (which cannot light itself) shows E / pi in
// every mode.
TEST(Render, DiffusePlaneShowsBOverPi) {
  SceneBuilder b;
  frontQuad(b, 10, 5, glm::vec3(0.5f), glm::vec3(0.f), Material::Diffuse, 4);
  const Scene s = b.build();
  const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 60, 16, 12);
  const glm::vec3 B(0.3f, 0.5f, 0.7f);
  for (int spp : {1, 3}) {
    RenderOptions o = opts(RenderMode::TwoPass, cam, spp);
    o.twoPass = TwoPassDiffuse::Map;
    o.firstPassB.assign(s.vertexCount(), B);
    const RenderResult r = run(s, o);
    for (const glm::vec3& p : r.image.px)
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(p[k], B[k] / M_PI, 1e-6 * B[k]) << "spp " << spp;
  }
  SceneBuilder e;
  const glm::vec3 E(1.f, 2.f, 3.f);
  frontQuad(e, 10, 5, glm::vec3(0.5f), E, Material::Diffuse, 4);
  const Scene se = e.build();
  for (RenderMode m : kAllModes) {
    RenderOptions o = opts(m, cam, 2);
    o.firstPassB.assign(se.vertexCount(), E);
    o.twoPass = TwoPassDiffuse::DirectIndirect;
    const RenderResult r = run(se, o);
    for (const glm::vec3& p : r.image.px)
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(p[k], E[k] / M_PI, 1e-6 * E[k]) << renderModeName(m);
    EXPECT_EQ(r.seesEmitter[0], 1);
  }
}

// A mirror of reflectance rho_m shows an emitter at exactly rho_m E / pi, in
// every pixel and every mode, and so does each mirror vertex's radiance
// towards the camera; the emitter's own vertices send E / pi.
TEST(Render, MirrorShowsEmitterTimesReflectance) {
  SceneBuilder b;
  const glm::vec3 tint(0.8f, 0.6f, 0.4f), E(3.f, 2.f, 1.f);
  // Mirror z = y + 5 facing (0, 1, -1): camera rays (0, 0, 1) go up to the emitter.
  b.quad({-3, 3, 8}, {3, 3, 8}, {3, -3, 2}, {-3, -3, 2}, tint, glm::vec3(0.f), Material::Mirror, 3);
  b.quad({-50, 10, -50}, {50, 10, -50}, {50, 10, 50}, {-50, 10, 50}, glm::vec3(0.f), E, Material::Diffuse, 2);
  const Scene s = b.build();
  const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 10, 8, 8);
  for (RenderMode m : {RenderMode::Whitted, RenderMode::Distributed, RenderMode::PathTraced}) {
    RenderOptions o = opts(m, cam, 4);
    o.vertexRadiance = true;
    const RenderResult r = run(s, o);
    for (const glm::vec3& p : r.image.px)
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(p[k], tint[k] * E[k] / M_PI, 1e-5) << renderModeName(m);
    for (size_t v = 0; v < s.vertexCount(); ++v) {
      const glm::vec3 expect = v < 16 ? tint * E / float(M_PI) : E / float(M_PI);
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(r.vertexRadiance[v][k], expect[k], 1e-5) << renderModeName(m) << " v " << v;
    }
  }
}

// Through a glass slab at normal incidence the emitter behind it appears
// with the slab's transmittance, the internal reflections summed:
//   T = (1 - R)^2 (1 + R^2 + R^4 + ...) = (1 - R)^2 / (1 - R^2),  R = ((n - 1) / (n + 1))^2
// (fov 1 degree: R changes by < 1e-5 over the image). Whitted splits every
// glass hit: within 1e-4 (the branches below whitted_min_weight = 1e-3
// carry R^4 ~ 3e-6). The sampled modes choose reflection with probability
// R, each sample giving 0 or E / pi: the image mean lies within 4 binomial
// standard errors sqrt(T (1 - T) / n) E / pi of T E / pi.
TEST(Render, GlassSlabTransmittance) {
  SceneBuilder b;
  b.box({-5, -5, 2}, {5, 5, 2.5}, glm::vec3(1.f), glm::vec3(0.f), Material::Glass, false);
  const glm::vec3 E(2.f);
  frontQuad(b, 20, 6, glm::vec3(0.f), E);
  const float n = 1.5f;
  const Scene s = b.build(n);
  const double R = std::pow((n - 1.0) / (n + 1.0), 2), T = (1 - R) * (1 - R) / (1 - R * R);
  const double L = T * E.g / M_PI;
  const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 1, 16, 16);
  {
    const RenderResult r = run(s, opts(RenderMode::Whitted, cam, 1));
    for (const glm::vec3& p : r.image.px) ASSERT_NEAR(p.g, L, 1e-4 * L);
  }
  for (RenderMode m : {RenderMode::Distributed, RenderMode::PathTraced}) {
    const int spp = 64;
    const RenderResult r = run(s, opts(m, cam, spp));
    const double samples = double(r.image.px.size()) * spp;
    const double mean = gi::test::meanLuminance(r.image) / luminance(glm::vec3(1.f));
    EXPECT_NEAR(mean, L, 4 * std::sqrt(T * (1 - T) / samples) * E.g / M_PI) << renderModeName(m);
  }
}

// Whitted's shadow rays cross glass on a straight line, losing the Fresnel
// reflectance at each interface: a pane between a point light (beside the
// camera) and a backdrop covers half of it, and the camera sees that half
// through the pane too. Each pixel against the same pixel without the pane
// (the same samples): within 5e-4 for glass of index 1, which is no glass
// at all (the pane's shadow was black); for 1.5, (1 - R)^2 on the eye ray
// and again on the shadow ray, R = 0.04 at normal incidence (0.0401 at the
// image's 10 degrees), plus the pane's internal reflections on the eye ray
// (R^2 of it) and its sideways shift of the eye ray (0.03 at 10 degrees,
// where the light changes by 0.1%): (1 - R)^4 = 0.8493 within 0.005. The
// other half is untouched.
TEST(Render, WhittedShadowsCrossGlass) {
  const int W = 16, H = 16;
  const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 20, W, H);
  auto image = [&](bool pane, float n) {
    SceneBuilder b;
    frontQuad(b, 20, 10, glm::vec3(0.8f), glm::vec3(0.f), Material::Diffuse, 4);
    if (pane) b.box({-20, -20, 6}, {0, 20, 6.5}, glm::vec3(1.f), glm::vec3(0.f), Material::Glass, false);
    const Scene s = b.build(n);
    RenderOptions o = opts(RenderMode::Whitted, cam, 1);
    o.point.intensity = glm::vec3(100.f);
    o.point.position = glm::vec3(glm::dvec3(0, 0, 0.5) - s.origin);
    return run(s, o).image;
  };
  const Image bare = image(false, 1.5f);
  const double R = std::pow((1.5 - 1.0) / 2.5, 2);
  for (float n : {1.0f, 1.5f}) {
    const Image glass = image(true, n);
    size_t behind = 0;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const double a = glass.at(x, y).g, c = bare.at(x, y).g;
        ASSERT_GT(c, 0.0);
        if (n == 1.0f || a == c) {  // (index 1: the eye ray lifted off each face it crosses: 1e-4 apart)
          EXPECT_NEAR(a, c, 5e-4 * c) << "index " << n << ", pixel " << x << ", " << y;
          continue;
        }
        ++behind;
        if (x == W / 2 || x == W / 2 - 1) continue;  // the pane's edge
        EXPECT_NEAR(a / c, std::pow(1.0 - R, 4), 0.005) << "index " << n << ", pixel " << x << ", " << y;
      }
    if (n == 1.5f) {
      EXPECT_EQ(behind, size_t(W * H / 2));
    }
  }
  // The sun 50 degrees off the pane's normal, past glass's critical angle
  // (41.8): every shadow ray crosses the pane, those of the half the camera
  // sees directly lose (1 - F(50))^2 = 0.888 exactly (Fresnel's equations
  // written out here), where evaluating the second face inside at the unbent
  // angle had turned it total and the shadow black.
  const double ci = std::cos(50.0 * M_PI / 180.0), st = std::sin(50.0 * M_PI / 180.0) / 1.5;
  const double ct = std::sqrt(1.0 - st * st);
  const double rs = std::pow((ci - 1.5 * ct) / (ci + 1.5 * ct), 2), rp = std::pow((ct - 1.5 * ci) / (ct + 1.5 * ci), 2);
  const double sunT = std::pow(1.0 - 0.5 * (rs + rp), 2);
  auto sunImage = [&](bool pane) {
    SceneBuilder b;
    frontQuad(b, 20, 10, glm::vec3(0.8f), glm::vec3(0.f), Material::Diffuse, 4);
    if (pane) b.box({-40, -20, 6}, {0, 20, 6.5}, glm::vec3(1.f), glm::vec3(0.f), Material::Glass, false);
    const Scene s = b.build(1.5f);
    RenderOptions o = opts(RenderMode::Whitted, cam, 1);
    o.sunIrradiance = glm::vec3(10.f);
    o.sunDirection = glm::vec3(-std::sin(50.0 * M_PI / 180.0), 0.0, -ci);
    return run(s, o).image;
  };
  const Image sunBare = sunImage(false), sunGlass = sunImage(true);
  size_t direct = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double a = sunGlass.at(x, y).g, c = sunBare.at(x, y).g;
      ASSERT_GT(c, 0.0);
      if (a < 0.85 * c) continue;  // seen through the pane as well (0.92 of this)
      ++direct;
      EXPECT_NEAR(a / c, sunT, 1e-4) << "sun, pixel " << x << ", " << y;
    }
  EXPECT_GE(direct, size_t(W * H / 2 - W));
}

// A camera inside a glass cube (n = 1.5) looking at an emitter beyond its
// +z face: rays leave through that face only below the critical angle
// asin(1/n) = 41.8 degrees. In an axis-aligned cube reflections keep the
// direction's |z| component, so a ray beyond the critical angle is totally
// reflected at the z faces forever: pixels whose every direction lies
// beyond it are exactly black (Whitted and path traced). Pixels within
// it show at least the once-transmitted light n^2 (1 - F(theta_max)) E / pi
// (radiance is n^2 larger inside the glass; the emitter, 0.01 beyond the
// face, catches every ray refracted out below theta_c - 0.5 degrees).
TEST(Render, TotalInternalReflectionAtTheCriticalAngle) {
  SceneBuilder b;
  b.box({-1, -1, -1}, {1, 1, 1}, glm::vec3(1.f), glm::vec3(0.f), Material::Glass, false);
  const glm::vec3 E(1.f);
  // Just beyond the +z face and no wider: light leaving through a side face
  // (possible beyond the critical angle of the z faces) cannot reach it.
  frontQuad(b, 1, 1.01, glm::vec3(0.f), E);
  const float n = 1.5f;
  const Scene s = b.build(n);
  const int W = 48;
  const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 120, W, W);
  const double k = cam.pixelsPerTangent(), thetaC = std::asin(1.0 / n);
  auto theta = [&](double fx, double fy) {
    const double x = (fx - W / 2.0) / k, y = (W / 2.0 - fy) / k;
    return std::atan(std::sqrt(x * x + y * y));
  };
  int below = 0, beyond = 0;
  for (RenderMode m : {RenderMode::Whitted, RenderMode::PathTraced}) {
    const RenderResult r = run(s, opts(m, cam, 4));
    for (int j = 0; j < W; ++j)
      for (int i = 0; i < W; ++i) {
        double lo = 10, hi = 0;
        for (int c = 0; c < 4; ++c) {
          const double t = theta(i + (c & 1), j + (c >> 1));
          lo = std::min(lo, t);
          hi = std::max(hi, t);
        }
        const float v = r.image.at(i, j).g;
        if (lo > thetaC + glm::radians(0.5)) {
          ASSERT_EQ(v, 0.f) << renderModeName(m) << " pixel " << i << "," << j;
          ++beyond;
        } else if (hi < thetaC - glm::radians(0.5) && m == RenderMode::Whitted) {
          const double F = fresnelDielectric(float(std::cos(hi)), n);
          ASSERT_GE(v, n * n * (1 - F) * E.g / M_PI * 0.999) << "pixel " << i << "," << j;
          ++below;
        }
      }
  }
  EXPECT_GT(below, 100);
  EXPECT_GT(beyond, 200);
}

// Depth of field with a thin lens of radius A focused at F: a small emitter
// at depth z spreads into a uniform disk of radius R = A |1/F - 1/z| k pixels
// (k = pixels per unit tangent) around its sharp image. Checked by
//   - the light it sends into the image: the same as through a pinhole
//     (every lens point sees it with the same projected area), within 3%;
//   - the second moment of the spread, <r^2> = R^2 / 2 + s^2 / 6 + 1 / 6
//     (disk, the emitter's square image of side s, and Sheppard's
//     correction for pixel centres): R within 3% (random sampling of the
//     ~4000 sample hits would give a 4-sigma error of 2%; QMC does better);
//   - nothing beyond R + s / sqrt(2) + 1 pixel.
// Focused on the emitter (z = F) the same lens keeps it sharp: pixels fully
// inside its image are exactly E / pi, pixels fully outside exactly 0.
TEST(Render, ThinLensCircleOfConfusion) {
  const int W = 64;
  const double fov = 20, F = 2, z = 4;
  Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, fov, W, W);
  const double k = cam.pixelsPerTangent(), Rpx = 12, A = Rpx / (std::fabs(1 / F - 1 / z) * k);
  const double side = 4 * z / k;  // a 4-pixel square image
  const glm::vec3 E(1.f);
  SceneBuilder b;
  frontQuad(b, side / 2, z, glm::vec3(0.f), E);
  const Scene s = b.build();
  const RenderResult pin = run(s, opts(RenderMode::Distributed, cam, 64));
  cam.setLens(A, F);
  const RenderResult dof = run(s, opts(RenderMode::Distributed, cam, 256));
  double sumPin = 0, sum = 0, m2 = 0;
  for (int j = 0; j < W; ++j)
    for (int i = 0; i < W; ++i) {
      sumPin += pin.image.at(i, j).g;
      const double v = dof.image.at(i, j).g, dx = i + 0.5 - W / 2.0, dy = j + 0.5 - W / 2.0;
      sum += v;
      m2 += v * (dx * dx + dy * dy);
      if (std::hypot(dx, dy) > Rpx + 4 / std::sqrt(2.0) + 1) {
        ASSERT_EQ(v, 0.0) << i << "," << j;
      }
    }
  EXPECT_NEAR(sumPin * M_PI / E.g, 16.0, 0.05);  // the 4 x 4 pixel image, edges on pixel borders
  EXPECT_NEAR(sum / sumPin, 1.0, 0.03);
  const double Rest = std::sqrt(2 * (m2 / sum - 16.0 / 6 - 1.0 / 6));
  EXPECT_NEAR(Rest, Rpx, 0.03 * Rpx);

  // In focus: a 20-pixel square at z = F, its edges mid-pixel (the image's
  // right is -x, its top +y).
  SceneBuilder f;
  const double half = 10 * F / k, off = 0.5 * F / k;
  frontQuad(f, half, F, glm::vec3(0.f), E, Material::Diffuse, 1, -off, off);
  const Scene sf = f.build();
  const RenderResult sharp = run(sf, opts(RenderMode::Distributed, cam, 16));
  int inside = 0, outside = 0;
  for (int j = 0; j < W; ++j)
    for (int i = 0; i < W; ++i) {
      // The square covers film x in [W/2 - 9.5, W/2 + 10.5], y in [W/2 - 10.5, W/2 + 9.5].
      const double x0 = W / 2.0 - 9.5, x1 = W / 2.0 + 10.5, y0 = W / 2.0 - 10.5, y1 = W / 2.0 + 9.5;
      const float v = sharp.image.at(i, j).g;
      if (i >= x0 && i + 1 <= x1 && j >= y0 && j + 1 <= y1) {
        ASSERT_NEAR(v, E.g / M_PI, 1e-6) << i << "," << j;
        ++inside;
      } else if (i + 1 <= x0 || i >= x1 || j + 1 <= y0 || j >= y1) {
        ASSERT_EQ(v, 0.f) << i << "," << j;
        ++outside;
      }
    }
  EXPECT_EQ(inside, 19 * 19);
  EXPECT_EQ(outside, W * W - 21 * 21);
}

// Antialiasing: pixels cut in half by an emitter's edge converge to half
// its radiance. A diagonal edge through the pixel centres (by symmetry each
// diagonal pixel is half covered): every such pixel within 3 binomial
// standard errors 0.5 / sqrt(N) of 1/2, and their mean within 3 standard
// errors of the mean (QMC points do better than these random-sampling
// bounds); pixels off the diagonal are exactly 0 or E / pi.
TEST(Render, HalfCoveredPixelConvergesToHalf) {
  const int W = 32, N = 256;
  const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 40, W, W);
  SceneBuilder b;
  const glm::vec3 E(1.f);
  // The half-plane y >= x at z = 1, facing -z. Looking along +z with y up,
  // the image's right is -x: film (i, j) sees x = -(i + 1/2 - W/2) / k,
  // y = -(j + 1/2 - W/2) / k, so the edge x = y is the diagonal i = j and
  // y > x is i > j.
  b.tri({-10, -10, 1}, {-10, 10, 1}, {10, 10, 1}, glm::vec3(0.f), E, Material::Diffuse);
  const Scene s = b.build();
  for (RenderMode m : {RenderMode::Distributed, RenderMode::PathTraced}) {
    const RenderResult r = run(s, opts(m, cam, N));
    const double Lfull = E.g / M_PI, sigma = 0.5 / std::sqrt(double(N));
    double mean = 0;
    for (int j = 0; j < W; ++j)
      for (int i = 0; i < W; ++i) {
        const double v = r.image.at(i, j).g / Lfull;
        if (i == j) {
          EXPECT_NEAR(v, 0.5, 3 * sigma) << renderModeName(m) << " pixel " << i;
          mean += v / W;
        } else {  // whole pixels
          ASSERT_NEAR(v, i > j ? 1.0 : 0.0, 1e-6) << renderModeName(m) << " pixel " << i << "," << j;
        }
      }
    EXPECT_NEAR(mean, 0.5, 3 * sigma / std::sqrt(double(W))) << renderModeName(m);
  }
}

// A path between two parallel mirrors never ends: the loop (no recursion)
// runs to max_depth without exhausting the stack, and says so in the log.
TEST(Render, DeepMirrorBoxDoesNotRecurse) {
  SceneBuilder b;
  // Eye rays within 0.005 degrees of the normal drift < 10 units in 50000 bounces.
  b.quad({-100, -100, 1}, {-100, 100, 1}, {100, 100, 1}, {100, -100, 1}, glm::vec3(1.f), glm::vec3(0.f), Material::Mirror);
  b.quad({-100, -100, -1}, {100, -100, -1}, {100, 100, -1}, {-100, 100, -1}, glm::vec3(1.f), glm::vec3(0.f), Material::Mirror);
  const Scene s = b.build();
  const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0.01, 2, 2);
  for (RenderMode m : {RenderMode::Whitted, RenderMode::Distributed}) {
    RenderOptions o = opts(m, cam, 1);
    o.maxDepth = 50000;
    o.point.intensity = glm::vec3(1.f);
    o.point.position = glm::vec3(0.f, 3.f, 0.f) - glm::vec3(s.origin);
    const RenderResult r = run(s, o);
    EXPECT_EQ(r.image.at(0, 0), glm::vec3(0.f));
    EXPECT_GE(r.stats.get("specular_rays"), 4 * 49999.0) << renderModeName(m);
    EXPECT_NE(r.stats.line("render").find("cut at max_depth"), std::string::npos);
  }
}

TEST(Render, ClearErrors) {
  SceneBuilder b;
  frontQuad(b, 1, 2, glm::vec3(0.5f), glm::vec3(0.f));
  const Scene s = b.build();
  const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 40, 4, 4);
  RenderOptions o = opts(RenderMode::TwoPass, cam, 1);
  o.point.intensity = glm::vec3(1.f);
  try {
    run(s, o);
    FAIL() << "two-pass without a first pass must throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("GI: Radiosity"), std::string::npos) << e.what();
  }
  o.firstPassB.assign(3, glm::vec3(1.f));
  EXPECT_THROW(run(s, o), std::invalid_argument);  // wrong size
  o.firstPassB.assign(s.vertexCount(), glm::vec3(-1.f));
  EXPECT_THROW(run(s, o), std::invalid_argument);  // negative
  o = opts(RenderMode::Distributed, cam, 1);
  try {
    run(s, o);
    FAIL() << "no light must throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no light"), std::string::npos) << e.what();
  }
  o.point.intensity = glm::vec3(1.f);
  o.samplesPerPixel = 0;
  EXPECT_THROW(run(s, o), std::invalid_argument);
  o.samplesPerPixel = 1;
  auto caster = makeEmbreeCaster(s);
  EXPECT_THROW(render(s, *caster, o, Progress([](int, const std::string&) { return false; })), Cancelled);
}

namespace {

// The form factor from a point (normal n) to a planar polygon, by its
// contour integral (Lambert's formula, as in Cohen and Wallace 1993,
// "Radiosity and Realistic Image Synthesis", eq. 4.6): independent of the
// engine's own point-to-triangle code.
double pointToPolygon(const glm::dvec3& x, const glm::dvec3& n, const std::vector<glm::dvec3>& poly) {
  double sum = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3 a = poly[i] - x, b = poly[(i + 1) % poly.size()] - x, c = glm::cross(a, b);
    sum += std::atan2(glm::length(c), glm::dot(a, b)) * glm::dot(n, c) / glm::length(c);
  }
  return std::fabs(sum) / (2 * M_PI);
}

}  // namespace

// A ramp tilted 40 degrees whose upper part sees a light just above it at a
// grazing angle. The shadow rays are lifted off the ramp by the ray offset;
// aimed from the unlifted point, a lifted ray met the light's own plane
// before the light point (Whitted read 0 there, the sampled modes 42% low).
// Each vertex's radiance towards the camera (direct light only) against
// rho E F / pi with F in closed form: Whitted exactly (its area-light
// factor is F, with one shadow ray), the sampled modes by the mean of
// their ratios to it over the band, within 4 of its standard errors (the
// spread of the ratios over the vertices, each an independent estimate of 1).
TEST(Render, LightAtAGrazingAngleIsNotShadowedByItsOwnPlane) {
  const double a = 40 * M_PI / 180;
  const glm::dvec3 n(std::sin(a), std::cos(a), 0), t(std::cos(a), -std::sin(a), 0), z(0, 0, 1);
  const float rho = 0.5f;
  const glm::vec3 E(float(M_PI));
  SceneBuilder b;
  b.quad(-2.0 * t - 2.0 * z, -2.0 * t + 2.0 * z, 2.0 * t + 2.0 * z, 2.0 * t - 2.0 * z, glm::vec3(rho), glm::vec3(0.f),
         Material::Diffuse, 16);
  const std::vector<glm::dvec3> light = {{-1, 1.5, -1}, {1, 1.5, -1}, {1, 1.5, 1}, {-1, 1.5, 1}};
  b.quad(light[0], light[1], light[2], light[3], glm::vec3(0.f), E);
  const Scene s = b.build();
  const size_t rampVertices = 17 * 17;
  std::vector<size_t> band;  // the upper part, off the ramp's sides: 1.29 to 0.96 high, the light at 1.5
  for (size_t v = 0; v < rampVertices; ++v) {
    const glm::dvec3 p = s.toWorld(s.positions[v]);
    if (glm::dot(p, t) < -1.49 && std::fabs(p.z) < 1.9) band.push_back(v);
  }
  ASSERT_EQ(band.size(), 3u * 15u);
  for (RenderMode m : {RenderMode::Whitted, RenderMode::Distributed, RenderMode::PathTraced}) {
    RenderOptions o = opts(m, Camera::lookAt(3.0 * n, {0, 0, 0}, {0, 1, 0}, 60, 4, 4), m == RenderMode::Whitted ? 1 : 64);
    o.maxDepth = 0;
    o.renderImage = false;
    o.vertexRadiance = true;
    const RenderResult r = run(s, o);
    double sum = 0, sum2 = 0;
    for (size_t v : band) {
      const double F = pointToPolygon(s.toWorld(s.positions[v]), n, light);
      const double expected = rho * E.x * F / M_PI;
      ASSERT_GT(F, 0.01);
      const double ratio = r.vertexRadiance[v].x / expected;
      if (m == RenderMode::Whitted) {
        EXPECT_NEAR(ratio, 1.0, 1e-3) << "vertex " << v;
      }
      sum += ratio;
      sum2 += ratio * ratio;
    }
    const double k = double(band.size()), mean = sum / k, se = std::sqrt((sum2 / k - mean * mean) / (k - 1));
    EXPECT_NEAR(mean, 1.0, 4 * se + 1e-4) << renderModeName(m) << ": mean ratio over " << k << " vertices";
  }
}

// A floor and a wall that meet at a seam without sharing vertices (as the
// Cornell box's walls do), lit from above: each vertex's path-traced
// radiance towards the camera is the per-vertex reference's B / pi there,
// seam vertices included (the eye rays arrived exactly on the seam, and
// rays along the wall slipped through it or struck it at t = 0: a fifth of
// the reference at the seam's floor vertices). z-scores with the reference's
// error bars, the same for the view's estimate (the same paths and counts).
TEST(Render, VertexRadianceAtASeamMatchesTheReference) {
  SceneBuilder b;
  b.quad({0, 0, -1}, {0, 0, 1}, {2, 0, 1}, {2, 0, -1}, glm::vec3(0.6f, 0.5f, 0.4f), glm::vec3(0.f), Material::Diffuse, 6);
  b.quad({0, 0, -1}, {0, 2, -1}, {0, 2, 1}, {0, 0, 1}, glm::vec3(0.7f), glm::vec3(0.f), Material::Diffuse, 6);
  b.quad({0.5, 1.9, -0.5}, {1.5, 1.9, -0.5}, {1.5, 1.9, 0.5}, {0.5, 1.9, 0.5}, glm::vec3(0.f), glm::vec3(5.f));
  const Scene s = b.build();
  auto caster = makeEmbreeCaster(s);
  PathTraceOptions po;
  po.samplesPerVertex = 1024;
  po.maxDepth = 3;
  const PathTraceResult ref = pathTrace(s, *caster, po);
  RenderOptions o = opts(RenderMode::PathTraced, Camera::lookAt({2.5, 2.5, 0}, {0.5, 0, 0}, {0, 1, 0}, 60, 4, 4), 1024);
  o.maxDepth = 3;
  o.renderImage = false;
  o.vertexRadiance = true;
  const RenderResult r = render(s, *caster, o);
  double z2 = 0, seamZ2 = 0;
  int count = 0, seam = 0;
  for (size_t v = 0; v < 49; ++v) {  // the floor's vertices
    const double B = luminance(ref.B[v]), L = M_PI * luminance(r.vertexRadiance[v]);
    const double z = (L - B) / (std::sqrt(2.0) * ref.stdError[v]);
    z2 += z * z;
    ++count;
    if (s.toWorld(s.positions[v]).x < 1e-9) {
      seamZ2 += z * z;
      ++seam;
      EXPECT_LT(std::fabs(z), 4.5) << "seam vertex " << v << ": " << L << " against " << B;
    }
  }
  EXPECT_EQ(seam, 7);
  EXPECT_LT(z2 / count, 1.6) << "mean z^2 over the floor";
  EXPECT_LT(seamZ2 / seam, 2.5) << "mean z^2 at the seam";
}
