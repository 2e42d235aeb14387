// The camera (gi/camera.h) against its definition and against vcglib's
// Shot/Camera conventions (MeshLab's view), and the image files (gi/image.h).
#include <gtest/gtest.h>

#include <cmath>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "gi/camera.h"
#include "gi/color.h"
#include "gi/image.h"
#include "gi/sampling.h"

using namespace gi;

namespace {
std::string tempPath(const std::string& name) {
  const char* d = std::getenv("TMPDIR");
  return std::string(d ? d : "/tmp") + "/gi_test_" + std::to_string(::getpid()) + "_" + name;
}
}  // namespace

// Rays through film points come back to the same film points (pinhole), and
// the image centre looks at the target.
TEST(Camera, RayAndProjectRoundTrip) {
  const glm::dvec3 eye(1, 2, 3), target(4, -1, 10);
  const Camera c = Camera::lookAt(eye, target, {0, 1, 0}, 50.0, 320, 200);
  const glm::dvec3 origin(0.5, 0.25, -7);  // a scene's local origin
  const Ray centre = c.ray({160.f, 100.f}, {0.5f, 0.5f}, origin);
  EXPECT_NEAR(glm::dot(glm::dvec3(centre.d), glm::normalize(target - eye)), 1.0, 1e-6);
  Rng rng(3);
  for (int i = 0; i < 100; ++i) {
    const glm::vec2 film(rng.next() * 320.f, rng.next() * 200.f);
    const Ray r = c.ray(film, {0.5f, 0.5f}, origin);
    const glm::dvec3 p = glm::dvec3(r.o) + origin + 7.0 * glm::dvec3(r.d);
    const auto q = c.project(p);
    ASSERT_TRUE(q.has_value());
    EXPECT_NEAR(q->x, film.x, 1e-3);
    EXPECT_NEAR(q->y, film.y, 1e-3);
  }
  // The top edge of the image is fov/2 above the axis.
  const Ray top = c.ray({160.f, 0.f}, {0.5f, 0.5f}, origin);
  EXPECT_NEAR(std::acos(glm::dot(glm::dvec3(top.d), c.forward())), glm::radians(25.0), 1e-5);
  EXPECT_GT(glm::dot(glm::dvec3(top.d), c.up()), 0.0);
}

// The shot stored with a rendered raster layer gives the same camera back:
// every film point projects identically.
TEST(Camera, ShotRoundTrip) {
  const Camera c = Camera::lookAt({1, 2, 3}, {4, -1, 10}, {0, 1, 0}, 50.0, 320, 200);
  const Camera d = Camera::fromShot(c.toShot(), 320, 200);
  EXPECT_NEAR(glm::length(d.eye() - c.eye()), 0.0, 1e-12);
  EXPECT_NEAR(glm::dot(d.forward(), c.forward()), 1.0, 1e-12);
  EXPECT_NEAR(d.pixelsPerTangent(), c.pixelsPerTangent(), 1e-9);
  Rng rng(5);
  for (int i = 0; i < 50; ++i) {
    const glm::dvec3 p(rng.next() * 10.0, rng.next() * 10.0 - 5.0, 10.0 + rng.next() * 10.0);
    const auto a = c.project(p), b = d.project(p);
    ASSERT_TRUE(a && b);
    EXPECT_NEAR(a->x, b->x, 1e-7);
    EXPECT_NEAR(a->y, b->y, 1e-7);
  }
}

// Framing: every corner of the box is inside the image, and the box touches
// the border (within the 2% margin): no wasted pixels.
// Also for a box 1e30 across (framing took its orientation from a point one
// unit in front of the centre, which coordinates of 1e30 cannot tell from
// the centre: "the camera's eye and target must differ") and one far from
// the origin.
TEST(Camera, FrameFitsTheBox) {
  for (const double s : {1.0, 1e30, 1e-20})
  for (const glm::dvec3 dir : {glm::dvec3(0, 0, 1), glm::dvec3(1, -0.5, 0.3)}) {
    const glm::dvec3 lo = glm::dvec3(-3, 0, 10) * s, hi = glm::dvec3(5, 2, 13) * s;
    const Camera c = Camera::frame(lo, hi, dir, {0, 1, 0}, 40.0, 300, 200);
    double margin = 1e9;
    for (int k = 0; k < 8; ++k) {
      const glm::dvec3 q((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
      const auto p = c.project(q);
      ASSERT_TRUE(p.has_value());
      EXPECT_GE(p->x, 0.0);
      EXPECT_LE(p->x, 300.0);
      EXPECT_GE(p->y, 0.0);
      EXPECT_LE(p->y, 200.0);
      margin = std::min({margin, p->x, 300.0 - p->x, p->y, 200.0 - p->y});
    }
    EXPECT_LT(margin, 0.03 * 200.0);
  }
}

// vcglib's conventions (vcg/math/shot.h, camera.h), written out: the shot of
// LookTowards(z_dir, up) has rotation rows x = up ^ -z, y = -z ^ x, -z
// (normalised); a world point p maps to camera coordinates R (p - viewpoint)
// with z negated, then to the image plane (f x / z, f y / z) mm, then to
// viewport pixels (local / pixel size + centre), y up. Camera::fromShot must
// project every point to the same pixel (viewport y flipped to image rows),
// also with an off-centre principal point and an image of other size.
// (Checked once against vcglib's own Shot::Project and UnProject, to 1e-13
// pixels; the engine tests do not depend on the MeshLab SDK.)
TEST(Camera, FromShotMatchesVcgProjection) {
  const glm::dvec3 eye(10, 20, -30), target(12, 18, 5), up(0.1, 1, 0);
  const glm::dvec3 z = target - eye, x = glm::cross(up, -z), y = glm::cross(-z, x);
  ShotData s;
  const glm::dvec3 rows[3] = {glm::normalize(x), glm::normalize(y), -glm::normalize(z)};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s.rotation[i][j] = rows[i][j];
  s.viewpoint[0] = eye.x;
  s.viewpoint[1] = eye.y;
  s.viewpoint[2] = eye.z;
  s.focalMm = 35.0;
  s.pixelSizeMm[0] = s.pixelSizeMm[1] = 0.02;
  s.viewportPx[0] = 640;
  s.viewportPx[1] = 480;
  s.centerPx[0] = 330;  // off centre
  s.centerPx[1] = 235;
  auto vcgProject = [&](const glm::dvec3& p) {
    glm::dvec3 cp(glm::dot(rows[0], p - eye), glm::dot(rows[1], p - eye), glm::dot(rows[2], p - eye));
    cp.z = -cp.z;
    const glm::dvec2 local(cp.x * s.focalMm / cp.z, cp.y * s.focalMm / cp.z);
    return glm::dvec2(local.x / s.pixelSizeMm[0] + s.centerPx[0], local.y / s.pixelSizeMm[1] + s.centerPx[1]);
  };
  Rng rng(9);
  for (const int scale : {1, 2}) {
    const Camera c = Camera::fromShot(s, 640 / scale, 480 / scale);
    for (int i = 0; i < 50; ++i) {
      const glm::dvec3 p = target + glm::dvec3(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5) * 10.0;
      const glm::dvec2 v = vcgProject(p);
      const auto q = c.project(p);
      ASSERT_TRUE(q.has_value());
      EXPECT_NEAR(q->x, v.x / scale, 1e-6 * 640);
      EXPECT_NEAR(q->y, (480.0 - v.y) / scale, 1e-6 * 480);
    }
  }
  // Orthographic (vcg's SetOrtho: "mm" are scene units on the film plane).
  s.orthographic = true;
  s.pixelSizeMm[0] = s.pixelSizeMm[1] = 0.05;
  const Camera o = Camera::fromShot(s, 640, 480);
  const glm::dvec3 p = target + glm::dvec3(1, 2, 3);
  const glm::dvec3 rel = p - eye;
  const auto q = o.project(p);
  ASSERT_TRUE(q.has_value());
  EXPECT_NEAR(q->x, glm::dot(rows[0], rel) / 0.05 + 330, 1e-6 * 640);
  EXPECT_NEAR(q->y, 480 - (glm::dot(rows[1], rel) / 0.05 + 235), 1e-6 * 480);
}

TEST(Camera, RejectsDegenerateViews) {
  EXPECT_THROW(Camera::lookAt({0, 0, 0}, {0, 0, 0}, {0, 1, 0}, 40, 10, 10), std::invalid_argument);
  EXPECT_THROW(Camera::lookAt({0, 0, 0}, {0, 1, 0}, {0, 1, 0}, 40, 10, 10), std::invalid_argument);
  EXPECT_THROW(Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 180, 10, 10), std::invalid_argument);
  EXPECT_THROW(Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 40, 0, 10), std::invalid_argument);
  // Only the up vector's direction counts: a tiny one gives the same view
  // (it was called parallel to the view); a zero one is said as such.
  const Camera tiny = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1e-30, 0}, 40, 10, 10);
  const Camera unit = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 40, 10, 10);
  EXPECT_EQ(tiny.up(), unit.up());
  try {
    Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 0, 0}, 40, 10, 10);
    ADD_FAILURE() << "a zero up vector was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("non-zero"), std::string::npos) << e.what();
  }
  ShotData s;
  EXPECT_THROW(Camera::fromShot(s, 10, 10), std::invalid_argument);  // no intrinsics
  Camera c = Camera::lookAt({0, 0, 0}, {0, 0, 3}, {0, 1, 0}, 40, 10, 10);
  EXPECT_THROW(c.setLens(-1, 1), std::invalid_argument);
  EXPECT_THROW(c.setLens(0.1, -1), std::invalid_argument);
  EXPECT_THROW(c.setLens(0.1, std::nan("")), std::invalid_argument);
  // Focus distance 0 (the table's default) keeps the target's distance: a
  // lens with the default focus was refused until 3 December 2026.
  c.setLens(0.1, 0);
  EXPECT_EQ(c.focusDistance(), 3.0);
  c.setLens(0.1, 2);
  EXPECT_EQ(c.focusDistance(), 2.0);
}

// PFM keeps the linear floats bit for bit (negative, tiny, huge values too).
TEST(Image, PfmRoundTrip) {
  Image img(5, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) img.at(x, y) = {x * 1.25f - 2.f, y * 1e-20f, 3e30f * float(x + y)};
  const std::string path = tempPath("round.pfm");
  writePfm(path, img);
  const Image back = readPfm(path);
  std::remove(path.c_str());
  ASSERT_EQ(back.width, 5);
  ASSERT_EQ(back.height, 3);
  for (size_t i = 0; i < img.px.size(); ++i) EXPECT_EQ(back.px[i], img.px[i]) << i;
  EXPECT_THROW(readPfm(tempPath("missing.pfm")), std::runtime_error);
}

// PNG: the file's signature and header carry the size; the bytes follow
// the filters' display convention (value x exposure, sRGB); auto exposure
// maps the 99th percentile of the unmasked pixels to white.
TEST(Image, PngAndExposure) {
  Image img(10, 10);
  for (size_t i = 0; i < img.px.size(); ++i) img.px[i] = glm::vec3(float(i + 1) / 100.f);
  std::vector<uint8_t> mask(img.px.size(), 0);
  mask[99] = 1;                          // the brightest pixel shows an emitter
  img.px[99] = glm::vec3(1000.f);
  const float e = imageExposure(img, 0.0, mask);
  EXPECT_NEAR(1.f / e, 0.98f, 0.011f);  // percentile of 0.01 .. 0.99
  EXPECT_EQ(imageExposure(img, 2.5), 2.5f);
  // Every pixel an emitter (inside a furnace): their own percentile, not 1
  // (which an outside audit found: an exposure left at 1 whatever the light).
  Image furnace(4, 4);
  for (glm::vec3& p : furnace.px) p = glm::vec3(50.f);
  EXPECT_FLOAT_EQ(imageExposure(furnace, 0.0, std::vector<uint8_t>(furnace.px.size(), 1)), 1.f / 50.f);
  const auto bytes = toSrgb8(img, 1.f);
  EXPECT_EQ(bytes[3 * 99], 255);         // clamped
  EXPECT_EQ(bytes[3 * 49], uint8_t(std::lround(linearToSrgb(0.5f) * 255.f)));
  const std::string path = tempPath("img.png");
  writePng(path, img, e);
  std::ifstream f(path, std::ios::binary);
  std::vector<unsigned char> head(24);
  f.read(reinterpret_cast<char*>(head.data()), 24);
  std::remove(path.c_str());
  const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  for (int k = 0; k < 8; ++k) EXPECT_EQ(head[size_t(k)], sig[k]);
  EXPECT_EQ(head[19], 10);  // IHDR width (big-endian, low byte)
  EXPECT_EQ(head[23], 10);  // IHDR height
  EXPECT_THROW(writePng("/nonexistent-dir/x.png", img, 1.f), std::runtime_error);
}
