// Two-sided surfaces (every face with a reversed copy on the same corners):
// the ray casters report the front of the face turned towards a ray, and
// every lighting filter then loses no energy there; the vertices, which have
// no normal, get the mean of their two sides.
//
// The furnace: a closed box and a sheet inside it, every face with E = 1 and
// rho = 0.5 on both sides, has B = E / (1 - rho) = 2 at every point whatever
// the geometry. Before 4 December 2026 the sheet lost the light that met it
// on the back of the face the caster reported: the box's mean was 1.941 in
// the reference (256 paths), 1.963 in radiosity and 1.966 to 1.970 in photon
// mapping, which also wrote 0 at the sheet's vertices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gi/pathtrace.h"
#include "gi/photon.h"
#include "gi/color.h"
#include "gi/form_factors.h"
#include "gi/radiosity.h"
#include "gi/raycaster.h"
#include "gi/sampling.h"
#include "gi/scenes.h"
#include "test_helpers.h"

using namespace gi;

namespace {

constexpr BatchMode kBatchModes[] = {BatchMode::Single, BatchMode::Packet8, BatchMode::Stream};

struct Furnace {
  Scene scene;
  size_t boxVertices = 0;
};

// A closed box of side 2 (4 x 4 patches a side, facing in) and a two-sided
// unit square sheet (4 x 4 patches) across its middle, tilted so that no
// wall is parallel to it.
Furnace furnaceWithSheet() {
  const Scene box = scenes::closedBox(2.0, 4, true).scene;
  const auto [sheetPts, sheetTris] = test::twoSided(scenes::openPlane(1.0, 4).scene);
  std::vector<glm::dvec3> pts;
  for (const glm::vec3& p : box.positions) pts.push_back(box.toWorld(p));
  std::vector<glm::uvec3> tris = box.triangles;
  const uint32_t off = uint32_t(pts.size());
  const double a = 0.4, c = std::cos(a), s = std::sin(a);
  for (const glm::dvec3& p : sheetPts) pts.push_back({p.x * c, p.y, p.x * s + 0.1});
  for (const glm::uvec3& t : sheetTris) tris.push_back(t + glm::uvec3(off));
  Furnace f;
  f.scene = Scene::fromAbsolute(pts, tris);
  f.scene.rho.assign(f.scene.faceCount(), glm::vec3(0.5f));
  f.scene.emission.assign(f.scene.faceCount(), glm::vec3(1.f));
  f.boxVertices = off;
  return f;
}

// The means of B over the box's and over the sheet's vertices, and the
// standard error of each mean from the vertices' own errors (independent
// estimates per vertex).
struct Means {
  double box = 0, sheet = 0, boxError = 0, sheetError = 0;
};
Means means(const Furnace& f, const std::vector<glm::vec3>& B, const std::vector<float>& err) {
  Means m;
  const size_t n = B.size(), nb = f.boxVertices, ns = n - nb;
  for (size_t i = 0; i < n; ++i) {
    const double e = err.empty() ? 0.0 : double(err[i]) * err[i];
    (i < nb ? m.box : m.sheet) += B[i].g;
    (i < nb ? m.boxError : m.sheetError) += e;
  }
  m.box /= double(nb);
  m.sheet /= double(ns);
  m.boxError = std::sqrt(m.boxError) / double(nb);
  m.sheetError = std::sqrt(m.sheetError) / double(ns);
  return m;
}

}  // namespace

// The reference: each mean within 4 of its standard errors plus 0.2% (as
// the furnace sphere's test); every sheet vertex a mean of its sides.
TEST(TwoSided, FurnaceReference) {
  const Furnace f = furnaceWithSheet();
  const auto caster = makeEmbreeCaster(f.scene);
  PathTraceOptions o;
  o.samplesPerVertex = 256;
  const PathTraceResult r = pathTrace(f.scene, *caster, o);
  const Means m = means(f, r.B, r.stdError);
  std::printf("reference: box %.4f +- %.4f, sheet %.4f +- %.4f\n", m.box, m.boxError, m.sheet, m.sheetError);
  EXPECT_NEAR(m.box, 2.0, 4 * m.boxError + 0.004);
  EXPECT_NEAR(m.sheet, 2.0, 4 * m.sheetError + 0.004);
}

// Radiosity (patches, then the vertices' direct light and final gather):
// the patches' form factors in a closed box sum to 1 row by row, so the
// means hold to 0.1% (measured 2.0001 for both), and every vertex to 1%
// (the final gather's noise: at most 0.3% here). Then every form factor
// method with the flat and the hierarchical solver, the patches' own
// values: means within 0.5% (measured 0.26% off at most, the analytic
// factors' sheet), every patch within 2%. Before 4 December 2026 the
// hemicube drew the reversed copy's back in some cells (box 1.963), and
// the hierarchical solver linked each face to its copy with a factor near
// 1 when rounding put the copy's corners a hair in front (sheet 2.30).
TEST(TwoSided, FurnaceRadiosity) {
  const Furnace f = furnaceWithSheet();
  const auto caster = makeEmbreeCaster(f.scene);
  const RadiosityResult r = solveRadiosity(f.scene, *caster, RadiosityOptions{});
  const Means m = means(f, r.Bvertex, {});
  std::printf("radiosity: box %.5f, sheet %.5f\n", m.box, m.sheet);
  EXPECT_NEAR(m.box, 2.0, 0.002);
  EXPECT_NEAR(m.sheet, 2.0, 0.002);
  for (size_t i = 0; i < r.Bvertex.size(); ++i) EXPECT_NEAR(r.Bvertex[i].g, 2.0, 0.02) << i;
  const size_t boxFaces = scenes::closedBox(2.0, 4, true).scene.faceCount();
  for (auto method : {FormFactorMethod::MonteCarlo, FormFactorMethod::Analytic, FormFactorMethod::Hemicube})
    for (auto solver : {RadiositySolver::Auto, RadiositySolver::Hierarchical}) {
      RadiosityOptions o;
      o.formFactors.method = method;
      o.solver = solver;
      o.vertexOutput = RadiosityVertexOutput::PatchAverage;
      const RadiosityResult p = solveRadiosity(f.scene, *caster, o);
      double box = 0, sheet = 0, worst = 0;
      for (size_t k = 0; k < p.B.size(); ++k) {
        (k < boxFaces ? box : sheet) += p.B[k].g;
        worst = std::max(worst, std::abs(p.B[k].g - 2.0));
      }
      box /= double(boxFaces);
      sheet /= double(p.B.size() - boxFaces);
      std::printf("method %d solver %d: box %.4f, sheet %.4f, worst patch off by %.4f\n", int(method), int(solver), box,
                  sheet, worst);
      EXPECT_NEAR(box, 2.0, 0.01) << int(method) << " " << int(solver);
      EXPECT_NEAR(sheet, 2.0, 0.01) << int(method) << " " << int(solver);
      EXPECT_LT(worst, 0.04) << int(method) << " " << int(solver);
    }
}

// Photon mapping in its three k-nearest modes and progressive: the sheet's
// vertices are estimated on each side (they were 0) and the means hold to
// 1% (the photons' density estimates: without the sheet the box's mean is
// 2.0013 in the default mode), every vertex within the furnace sphere's
// tolerances.
TEST(TwoSided, FurnacePhotonMap) {
  const Furnace f = furnaceWithSheet();
  const auto caster = makeEmbreeCaster(f.scene);
  for (int mode = 0; mode < 4; ++mode) {
    PhotonOptions o;
    o.photons = mode == 3 ? 100000 : 400000;
    o.kNearest = mode == 2 ? 50 : 200;
    o.directLight = mode > 0;
    o.finalGather = mode == 2;
    o.gatherRays = 32;
    o.progressive = mode == 3;
    o.passes = 4;
    const VertexRadiometry r = computePhotonMap(f.scene, *caster, o);
    const Means m = means(f, r.B, {});
    std::printf("photon mode %d: box %.4f, sheet %.4f\n", mode, m.box, m.sheet);
    // The log's mean is over the scene's vertices (not each side apart).
    double all = 0;
    for (const glm::vec3& b : r.B) all += luminance(b);
    EXPECT_NEAR(r.stats.get("mean_luminance_B"), all / double(r.B.size()), 1e-6) << "mode " << mode;
    EXPECT_NEAR(m.box, 2.0, 0.02) << "mode " << mode;
    EXPECT_NEAR(m.sheet, 2.0, 0.02) << "mode " << mode;
    const double tol = mode == 0 ? 0.3 : mode == 1 ? 0.2 : 0.16;
    for (size_t i = f.boxVertices; i < r.B.size(); ++i) EXPECT_NEAR(r.B[i].g, 2.0, tol) << "mode " << mode << " " << i;
    bool noted = false;
    for (const auto& note : r.stats.notes) noted |= note.find("25 vertices on a two-sided surface") != std::string::npos;
    EXPECT_TRUE(noted) << r.stats.line("photon mapping");
  }
}

// Photon mapping on an open two-sided plane under a sky (H = 1 on either
// side) and a sun of 2 straight above: the top (rho 0.5) has H = 3, the
// bottom (rho 0.2) H = 1, nothing reflects back, so B = (0.5 x 3 + 0.2 x 1)
// / 2 = 0.85 and H = 2 at every vertex (the reference's test of the same
// plane), light path parts included.
TEST(TwoSided, PhotonMapTakesTheMeanOfTheSides) {
  const auto [pts, tris] = test::twoSided(scenes::openPlane(2.0, 4).scene);
  const size_t n = tris.size() / 2;
  Scene s = Scene::fromAbsolute(pts, tris);
  s.rho.assign(s.faceCount(), glm::vec3(0.2f));
  for (size_t f = 0; f < n; ++f) s.rho[f] = glm::vec3(0.5f);
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  const auto caster = makeEmbreeCaster(s);
  PhotonOptions o;
  o.photons = 20000;
  o.outside.skyRadiance = glm::vec3(float(1.0 / M_PI));
  o.outside.sunIrradiance = glm::vec3(2.f);
  o.outside.sunAngularRadiusDeg = 0.f;
  o.outside.sunDirection = glm::vec3(0.f, 0.f, 1.f);
  o.lightPathSplit = true;
  const VertexRadiometry r = computePhotonMap(s, *caster, o);
  ASSERT_EQ(r.B.size(), s.vertexCount());
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    EXPECT_NEAR(r.B[i].g, 0.85, 1e-4) << i;
    EXPECT_NEAR(r.H[i].g, 2.0, 1e-4) << i;
    const glm::vec3 sum = r.split.emitted[i] + r.split.direct[i] + r.split.caustic[i] + r.split.indirect[i];
    EXPECT_NEAR(sum.g, r.B[i].g, 1e-5) << i;
  }
}

// A two-sided surface: every face with a reversed copy on the same corners
// (shared vertices, or copies of them), so that a ray meets both at the same
// distance. Whichever a caster tests first, the hit must be the front of the
// face that turns towards the ray: the original from above, the copy from
// below (before 4 December 2026 Embree reported the original from below for
// some rays, whose light every estimator then took as black: a furnace with
// one such sheet lost 3%). The point, the distance and the barycentrics
// still describe the same place on the reported face. A degenerate face
// first makes the primitives' indices differ from the faces'. Without the
// copies, a back is still reported as a back.
TEST(RayCaster, TwoSidedSurfaceIsMetOnTheFrontFacingTheRay) {
  for (int variant = 0; variant < 3; ++variant) {
    const bool copiesOwnVertices = variant == 1, oneSided = variant == 2;
    Scene s;
    const int n = 4;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const float x = float(i) / n, y = float(j) / n;
        s.positions.push_back({x, y, 0.1f * std::sin(3.f * x) * std::cos(2.f * y)});  // curved: no common plane
      }
    s.positions.push_back({0.5f, 0.5f, 0.5f});
    s.triangles.push_back({0, 1, 0});  // unusable
    std::vector<glm::uvec3> up;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
        up.push_back({a, b, d});
        up.push_back({a, d, c});
      }
    const uint32_t firstUp = uint32_t(s.triangles.size());
    for (const auto& t : up) s.triangles.push_back(t);
    const uint32_t firstDown = uint32_t(s.triangles.size());
    const uint32_t shift = copiesOwnVertices ? uint32_t((n + 1) * (n + 1) + 1) : 0u;
    if (copiesOwnVertices) {
      const auto original = s.positions;
      for (const auto& p : original) s.positions.push_back(p);
    }
    if (!oneSided)
      for (size_t k = 0; k < up.size(); ++k) {
        const glm::uvec3 t = up[k] + glm::uvec3(shift);
        // The three turns of the reversed order, so that every corner mapping is used.
        s.triangles.push_back(k % 3 == 0 ? glm::uvec3(t.x, t.z, t.y) : k % 3 == 1 ? glm::uvec3(t.z, t.y, t.x)
                                                                                  : glm::uvec3(t.y, t.x, t.z));
      }
    std::vector<std::unique_ptr<RayCaster>> casters;
    casters.push_back(makeBruteForceCaster(s));
    for (BatchMode m : kBatchModes) casters.push_back(makeEmbreeCaster(s, m));
    Rng rng(17u + uint32_t(variant));
    std::vector<Ray> rays;
    for (int k = 0; k < 400; ++k) {
      Ray r;
      const bool fromBelow = k % 2 == 1;
      const glm::vec3 target(0.05f + 0.9f * rng.next(), 0.05f + 0.9f * rng.next(), 0.f);
      r.o = target + glm::vec3(0.3f * (rng.next() - 0.5f), 0.3f * (rng.next() - 0.5f), fromBelow ? -2.f : 2.f);
      r.d = glm::normalize(target - r.o);
      rays.push_back(r);
    }
    for (size_t c = 0; c < casters.size(); ++c) {
      std::vector<Hit> batch(rays.size());
      casters[c]->intersectBatch(rays.data(), rays.size(), batch.data());
      int backs = 0;
      for (size_t k = 0; k < rays.size(); ++k) {
        const Ray& r = rays[k];
        for (const Hit& h : {casters[c]->intersect(r), batch[k]}) {
          ASSERT_TRUE(h.valid()) << "caster " << c << " variant " << variant << " ray " << k;
          const bool fromBelow = r.o.z < 0.f;
          const bool front = glm::dot(r.d, h.ng) < 0.f;
          backs += front ? 0 : 1;
          if (oneSided) {
            EXPECT_EQ(front, !fromBelow) << "caster " << c << " ray " << k;
          } else {
            EXPECT_TRUE(front) << "caster " << c << " variant " << variant << " ray " << k;
            EXPECT_EQ(h.face >= firstDown, fromBelow) << "caster " << c << " ray " << k << " face " << h.face;
          }
          EXPECT_GE(h.face, firstUp);
          // The reported face, its barycentrics and its winding describe the hit.
          const glm::uvec3 t = s.triangles[h.face];
          const glm::vec3 q = (1.f - h.u - h.v) * s.positions[t.x] + h.u * s.positions[t.y] + h.v * s.positions[t.z];
          const glm::vec3 p = r.o + h.t * r.d;
          EXPECT_LT(glm::length(q - p), 1e-5f) << "caster " << c << " variant " << variant << " ray " << k;
          const glm::vec3 ng = faceNormalUnnormalized(s, h.face);
          EXPECT_GT(glm::dot(glm::normalize(ng), glm::normalize(h.ng)), 0.9999f) << "caster " << c << " ray " << k;
        }
      }
      if (oneSided) {
        EXPECT_EQ(backs, int(rays.size()));  // every ray from below, both queries
      }
    }
  }
}

// A hostile mesh: 100,000 copies of one triangle, half of them reversed.
// Finding the copies sorts each set of equal corners once (it compared every
// pair: 10^10 comparisons here), and the hit is still the front facing the ray.
TEST(RayCaster, ManyCopiesOfOneTriangle) {
  Scene s;
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (int k = 0; k < 100000; ++k) s.triangles.push_back(k % 2 ? glm::uvec3(0, 2, 1) : glm::uvec3(0, 1, 2));
  const auto embree = makeEmbreeCaster(s);
  const auto brute = makeBruteForceCaster(s);
  for (const RayCaster* c : {embree.get(), brute.get()})
    for (float dz : {-1.f, 1.f}) {
      Ray r;
      r.o = {0.25f, 0.25f, -2.f * dz};
      r.d = {0.f, 0.f, dz};
      const Hit h = c->intersect(r);
      ASSERT_TRUE(h.valid());
      EXPECT_LT(glm::dot(r.d, h.ng), 0.f);
      EXPECT_EQ(h.face % 2, dz > 0 ? 1u : 0u);  // from below, a reversed copy (facing down)
    }
}
