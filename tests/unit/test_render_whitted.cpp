// Whitted's one shadow ray per area light (render_whitted.cpp) where its aim
// point is hard to place: a closed light (its centre lies inside it) and a
// light partly behind the receiving face. Against the path-traced image
// limited to direct light (max_diffuse_bounces = 0), block means within 4
// combined standard errors (test::expectBlocksAgree). Both came from an
// outside audit (6 December 2026): the floor under a sphere light was black
// in Whitted's image (the ray to the centre met the light's own faces), and
// the face of a closed box that sees a light only past its edge had black
// patches (0.937 of the exact mean; the aim point fell behind the face's
// plane, and the ray started inside the box).
#include <gtest/gtest.h>

#include "gi/render.h"
#include "gi/scene_setup.h"
#include "gi/scenes.h"
#include "render_test_helpers.h"

using namespace gi;
using gi::test::expectBlocksAgree;
using gi::test::SceneBuilder;

namespace {

RenderResult run(const Scene& s, RenderMode mode, const Camera& cam, int spp) {
  RenderOptions o;
  o.mode = mode;
  o.samplesPerPixel = spp;
  o.camera = cam;
  o.maxDiffuseBounces = 0;
  auto caster = makeEmbreeCaster(s);
  return render(s, *caster, o);
}

void expectWhittedIsDirectLight(const Scene& s, const Camera& cam, const char* what) {
  const RenderResult w = run(s, RenderMode::Whitted, cam, 64);
  const RenderResult p = run(s, RenderMode::PathTraced, cam, 256);
  EXPECT_EQ(w.stats.get("area_lights"), 1.0) << what;
  EXPECT_GT(test::meanLuminance(w.image), 0.0) << what;
  expectBlocksAgree(w, p, 4, what);
}

}  // namespace

// A floor under a closed icosphere light (radius 0.3, one light: its faces
// share their vertices), every face emitting.
TEST(Whitted, ClosedLightLightsTheFloor) {
  SceneBuilder b;
  b.quad({-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, glm::vec3(0.5f), glm::vec3(0.f), Material::Diffuse, 8);
  const scenes::SceneFile ball = scenes::sphere(0.3, 2, false);
  const uint32_t base = uint32_t(b.pts.size());
  for (const auto& p : ball.scene.positions) b.pts.push_back(ball.scene.toWorld(p) + glm::dvec3(0, 1, 0));
  for (const auto& t : ball.scene.triangles) {
    b.tris.push_back(t + glm::uvec3(base));
    b.rho.push_back(glm::vec3(0.f));
    b.E.push_back(glm::vec3(3.f));
    b.mat.push_back(Material::Diffuse);
    b.rough.push_back(0.2f);
  }
  const Scene s = b.build();
  expectWhittedIsDirectLight(s, Camera::lookAt({0, 0.6, -3}, {0, 0, 0.3}, {0, 1, 0}, 50, 40, 32),
                             "floor under a sphere light");
}

// The +x face of a closed box (x in [-1, 0], top at z = 0.9) and a light at
// z = 1 facing down over x in [-1.5, 0.5]: the face sees only the strip
// x in [0, 0.5] of it, past the box's edge. The light's faces straddle the
// face's plane, and their centroids' mean lay behind it from some points.
TEST(Whitted, LightPartlyBehindTheFaceOfAClosedBox) {
  SceneBuilder b;
  b.box({-1, -1, 0}, {0, 1, 0.9}, glm::vec3(0.5f), glm::vec3(0.f), Material::Diffuse, false, 4);
  b.quad({-1.5, -1, 1}, {-1.5, 1, 1}, {0.5, 1, 1}, {0.5, -1, 1}, glm::vec3(0.f), glm::vec3(3.f), Material::Diffuse,
         2);
  const Scene s = b.build();
  expectWhittedIsDirectLight(s, Camera::lookAt({3, 0, 0.45}, {0, 0, 0.45}, {0, 0, 1}, 30, 40, 32),
                             "face of a closed box, light partly behind its plane");
}
