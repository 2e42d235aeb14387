// The two-pass mode's caustic map at a mesh border and beside a crease. A
// floor patch (1 x 1, reflectance 0.2) is lit only through a mirror: a lamp
// (1 x 1, radiance 1) faces up at z = 1 under a mirror at z = 2, so the
// floor sees the lamp's image at z = 3 and nothing else. A pixel whose ray
// meets the floor at p shows rho F(p -> image) (Lambert's contour integral),
// plus a second-order term of about 0.4% (floor -> mirror -> floor: allowed
// for below). The density estimate at a hit near the patch's border, or
// beside a black wall standing on its edge, must divide by the surface
// inside the gather sphere, not the whole disk: an outside audit (6
// December 2026) found the final gather's caustics 18 to 22% low within
// 0.03 of the border and the default mode (the first pass's caustics taken
// out at the vertices, the map's added at the hits) 22 to 28% high.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "gi/color.h"
#include "gi/form_factor_analytic.h"
#include "gi/photon.h"
#include "gi/render.h"
#include "gi/scene_setup.h"
#include "render_test_helpers.h"

using namespace gi;
using gi::test::SceneBuilder;

namespace {

// rho F(p -> the lamp's image), the image's two triangles.
double exactRadiance(const glm::dvec3& p, double rho) {
  const glm::dvec3 a(-.5, -.5, 3), b(.5, -.5, 3), c(.5, .5, 3), d(-.5, .5, 3), n(0, 0, 1);
  return rho * (pointToTriangleFormFactor(p, n, a, b, c) + pointToTriangleFormFactor(p, n, a, c, d));
}

struct Band {
  double ratio = 0;  // mean image / mean exact over the band's pixels
  int pixels = 0;
};

// Two-pass images of the scene (first pass photon mapping), and per image
// the band of pixels whose centre ray meets the floor within `width` of the
// edges `near(p)` measures the distance to.
template <class Near>
void expectBandsMatch(const Scene& s, const Camera& cam, Near near, const char* what) {
  constexpr double rho = 0.2, width = 0.06;
  auto caster = makeEmbreeCaster(s);
  PhotonOptions po;
  po.photons = 200000;
  const VertexRadiometry first = computePhotonMap(s, *caster, po);
  for (TwoPassDiffuse mode : {TwoPassDiffuse::Caustics, TwoPassDiffuse::FinalGather}) {
    RenderOptions o;
    o.camera = cam;
    o.mode = RenderMode::TwoPass;
    o.twoPass = mode;
    o.samplesPerPixel = 4;
    o.causticPhotons = 1000000;
    o.firstPassB = first.B;
    const RenderResult r = render(s, *caster, o);
    Band band, inner;
    double sumBand = 0, sumBandExact = 0, sumInner = 0, sumInnerExact = 0;
    // Where the film point (u, v) sees the floor's plane, and whether on the floor.
    auto onFloor = [&](float u, float v, glm::dvec3& p) {
      const Ray ray = cam.ray({u, v}, {0.5f, 0.5f}, {0, 0, 0});
      if (ray.d.z >= 0.f) return false;
      p = glm::dvec3(ray.o) + glm::dvec3(ray.d) * (-double(ray.o.z) / ray.d.z);
      return p.x > 1.5 && p.x < 2.5 && std::fabs(p.y) < 0.5;
    };
    for (int j = 0; j < cam.height(); ++j)
      for (int i = 0; i < cam.width(); ++i) {
        glm::dvec3 p, corner;
        // Pixels wholly on the floor (their samples spread over the pixel).
        if (!onFloor(float(i), float(j), corner) || !onFloor(i + 1.f, float(j), corner) ||
            !onFloor(float(i), j + 1.f, corner) || !onFloor(i + 1.f, j + 1.f, corner) || !onFloor(i + .5f, j + .5f, p))
          continue;
        const double d = near(p);
        if (d < 0) continue;
        const double L = luminance(r.image.px[size_t(j) * size_t(cam.width()) + size_t(i)]);
        (d < width ? sumBand : sumInner) += L;
        (d < width ? sumBandExact : sumInnerExact) += exactRadiance(p, rho);
        ++(d < width ? band : inner).pixels;
      }
    band.ratio = sumBand / sumBandExact;
    inner.ratio = sumInner / sumInnerExact;
    std::printf("%s, %s: within %.2f of the edge %.4f (%d pixels), further in %.4f (%d pixels)\n", what,
                mode == TwoPassDiffuse::Caustics ? "caustic map + stored indirect" : "caustic map + final gather",
                width, band.ratio, band.pixels, inner.ratio, inner.pixels);
    ASSERT_GT(band.pixels, 40) << what;
    ASSERT_GT(inner.pixels, 100) << what;
    // Measured (pixels wholly on the floor): at the border 1.031 (default
    // mode) and 0.991 (final gather), further in 1.035 and 1.007; at the
    // crease 0.980 and 1.024, further in 1.038 and 1.012. With the whole
    // disk: 1.283 and 0.868 at the border, 1.233 and 0.926 at the crease.
    // 6% allows the estimates' noise and small bias (k-nearest estimates
    // are consistent, not unbiased).
    EXPECT_NEAR(band.ratio, 1.0, 0.06) << what;
    EXPECT_NEAR(inner.ratio, 1.0, 0.06) << what;
  }
}

SceneBuilder mirrorAndLamp() {
  SceneBuilder b;
  b.quad({1.5, -.5, 0}, {2.5, -.5, 0}, {2.5, .5, 0}, {1.5, .5, 0}, glm::vec3(0.2f), glm::vec3(0.f), Material::Diffuse, 8);
  b.quad({-5, -5, 2}, {-5, 5, 2}, {5, 5, 2}, {5, -5, 2}, glm::vec3(1.f), glm::vec3(0.f), Material::Mirror, 4);
  b.quad({-.5, -.5, 1}, {.5, -.5, 1}, {.5, .5, 1}, {-.5, .5, 1}, glm::vec3(0.f), glm::vec3(float(M_PI)),
         Material::Diffuse, 2);
  return b;
}

}  // namespace

TEST(TwoPassCaustics, MatchTheExactValueAtAMeshBorder) {
  const Scene s = mirrorAndLamp().build();
  expectBandsMatch(s, Camera::lookAt({2, -1.2, 0.9}, {2, 0, 0}, {0, 0, 1}, 50, 48, 48),
                   [](const glm::dvec3& p) { return std::min({p.x - 1.5, 2.5 - p.x, p.y + .5, .5 - p.y}); },
                   "mesh border");
}

// A black wall 0.2 high on the floor's edge x = 2.5: the band is along it,
// away from the other edges.
TEST(TwoPassCaustics, MatchTheExactValueBesideACrease) {
  SceneBuilder b = mirrorAndLamp();
  b.quad({2.5, -.5, 0}, {2.5, -.5, .2}, {2.5, .5, .2}, {2.5, .5, 0}, glm::vec3(0.f), glm::vec3(0.f), Material::Diffuse,
         2);
  const Scene s = b.build();
  expectBandsMatch(s, Camera::lookAt({2.1, 0, 1.0}, {2.1, 0, 0}, {0, 1, 0}, 60, 48, 48),
                   [](const glm::dvec3& p) {
                     return std::min({p.x - 1.5, p.y + .5, .5 - p.y}) > 0.15 ? 2.5 - p.x : -1.0;
                   },
                   "crease");
}
