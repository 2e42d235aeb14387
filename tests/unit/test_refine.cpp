// Adaptive mesh refinement: the red-green subdivision keeps a closed mesh
// closed (no T-junctions), preserves area and attributes; the criterion
// concentrates patches at a shadow boundary; refinement lowers the error
// against an independent reference with fewer patches than uniform
// subdivision; limits and determinism.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <map>
#include <algorithm>
#include <array>

#include "gi/color.h"
#include "gi/form_factor_analytic.h"
#include "gi/radiosity.h"
#include "gi/refine.h"
#include "test_helpers.h"
#include "gi/scenes.h"

using namespace gi;
using gi::test::addGrid;

namespace {

// Floor [-1,1]^2 at z = 0 (rho 0.5, n x n quads), a small light (0.06 x 0.06,
// E = 250, black) at z = 2 facing down, a black occluder x in [0.2, 1.6] at
// z = 1. The floor sees only black surfaces, so B_floor = 0.5 H_direct
// exactly; the shadow edge runs along y at x = 0.4, its penumbra from x = 0.37
// to 0.43: a nearly hard shadow, the staircase of a coarse mesh.
constexpr size_t kFloorFaces(int n) { return size_t(2 * n * n); }
constexpr double kLight = 0.06;  // light edge: the penumbra is as wide
Scene shadowScene(int n) {
  std::vector<glm::dvec3> pts;
  std::vector<glm::uvec3> tris;
  addGrid(pts, tris, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, n, n);
  addGrid(pts, tris, {-kLight / 2, -kLight / 2, 2}, {0, kLight, 0}, {kLight, 0, 0}, 1, 1);  // faces -z
  addGrid(pts, tris, {0.2, -1.6, 1}, {0, 3.2, 0}, {1.4, 0, 0}, 1, 1);       // faces -z
  Scene s = Scene::fromAbsolute(pts, tris);
  s.rho.assign(tris.size(), glm::vec3(0.f));
  s.emission.assign(tris.size(), glm::vec3(0.f));
  for (size_t f = 0; f < kFloorFaces(n); ++f) s.rho[f] = glm::vec3(0.5f);
  s.emission[kFloorFaces(n)] = s.emission[kFloorFaces(n) + 1] = glm::vec3(250.f);
  return s;
}

// Reference: B = 0.5 E sum over a 24 x 24 subdivision of the light of the
// exact point-to-triangle form factor times the visibility of its centre.
struct Reference {
  std::vector<glm::dvec3> pts;
  std::vector<double> B;
};
Reference reference(const Scene& s, int samples) {
  auto caster = makeEmbreeCaster(s);
  const int m = 24;
  std::vector<std::array<glm::dvec3, 3>> sub;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const glm::dvec3 p0(kLight * (double(i) / m - 0.5), kLight * (double(j) / m - 0.5), 2), du(kLight / m, 0, 0),
          dv(0, kLight / m, 0);
      sub.push_back({p0, p0 + du, p0 + du + dv});
      sub.push_back({p0, p0 + du + dv, p0 + dv});
    }
  Reference r;
  for (int j = 0; j < samples; ++j)
    for (int i = 0; i < samples; ++i) {
      const glm::dvec3 x(-0.98 + 1.96 * (i + 0.5) / samples, -0.98 + 1.96 * (j + 0.5) / samples, 0);
      double F = 0;
      for (const auto& t : sub) {
        const glm::dvec3 c = (t[0] + t[1] + t[2]) / 3.0;
        Ray ray;
        ray.o = glm::vec3(x - s.origin) + glm::vec3(0, 0, 1e-5f);
        ray.d = glm::vec3(glm::normalize(c - x));
        ray.tfar = float(glm::length(c - x)) * 0.999f;
        if (caster->occluded(ray)) continue;
        F += pointToTriangleFormFactor(x, {0, 0, 1}, t[0], t[1], t[2]);
      }
      r.pts.push_back(x);
      r.B.push_back(0.5 * 250.0 * F);
    }
  return r;
}

// RMS of (linear interpolation of Bvertex on the floor faces - reference) / mean reference.
double floorError(const RefinedMesh& m, const std::vector<glm::vec3>& Bvertex, const Reference& ref, int n) {
  const Scene& s = m.scene;
  std::vector<double> val(ref.pts.size(), std::nan(""));
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (m.sourceFace[f] >= kFloorFaces(n)) continue;
    const glm::dvec3 a = s.toWorld(s.positions[s.triangles[f].x]), b = s.toWorld(s.positions[s.triangles[f].y]),
                     c = s.toWorld(s.positions[s.triangles[f].z]);
    const double det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    for (size_t k = 0; k < ref.pts.size(); ++k) {
      const glm::dvec3& p = ref.pts[k];
      const double w1 = ((p.x - a.x) * (c.y - a.y) - (c.x - a.x) * (p.y - a.y)) / det;
      const double w2 = ((b.x - a.x) * (p.y - a.y) - (p.x - a.x) * (b.y - a.y)) / det;
      if (w1 < -1e-9 || w2 < -1e-9 || w1 + w2 > 1 + 1e-9) continue;
      val[k] = (1 - w1 - w2) * luminance(Bvertex[s.triangles[f].x]) + w1 * luminance(Bvertex[s.triangles[f].y]) +
               w2 * luminance(Bvertex[s.triangles[f].z]);
    }
  }
  double e2 = 0, mean = 0;
  for (size_t k = 0; k < val.size(); ++k) {
    EXPECT_TRUE(std::isfinite(val[k])) << "sample point " << k << " not covered by the floor";
    e2 += (val[k] - ref.B[k]) * (val[k] - ref.B[k]);
    mean += ref.B[k];
  }
  mean /= double(val.size());
  return std::sqrt(e2 / double(val.size())) / mean;
}

RadiosityOptions cheapOptions() {
  RadiosityOptions o;
  o.formFactors.raysPerPatch = 64;     // nothing to gather: every surface the floor sees is black
  o.lightSamples = 1024;   // direct light at the vertices: noise below 1% in the penumbra
  o.gatherRays = 16;
  o.refine = true;
  return o;
}

// Every edge used exactly twice, once in each direction: closed, consistently
// oriented, and no T-junction (a hanging vertex leaves an edge used once).
void expectClosed(const Scene& s) {
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) directed[{t[k], t[(k + 1) % 3]}]++;
  size_t bad = 0;
  for (const auto& [e, c] : directed)
    if (c != 1 || directed.count({e.second, e.first}) == 0 || directed.at({e.second, e.first}) != 1) ++bad;
  EXPECT_EQ(bad, 0u) << "edges not shared by exactly two faces";
}

double minAngle(const Scene& s) {
  double lo = 180;
  for (size_t f = 0; f < s.faceCount(); ++f)
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 a(s.positions[s.triangles[f][k]]), b(s.positions[s.triangles[f][(k + 1) % 3]]),
          c(s.positions[s.triangles[f][(k + 2) % 3]]);
      lo = std::min(lo, std::acos(glm::dot(glm::normalize(b - a), glm::normalize(c - a))) * 180 / M_PI);
    }
  return lo;
}

// The smallest angle red-green refinement can create from `s`: every face is
// similar to an input face or to a half of one bisected at an edge midpoint.
double angleBound(const Scene& s) {
  double lo = minAngle(s);
  for (size_t f = 0; f < s.faceCount(); ++f)
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 a = s.positions[s.triangles[f][k]], b = s.positions[s.triangles[f][(k + 1) % 3]],
                      c = s.positions[s.triangles[f][(k + 2) % 3]], m = 0.5f * (a + b);
      Scene h;
      h.positions = {a, m, c, b};
      h.triangles = {{0, 1, 2}, {1, 3, 2}};
      lo = std::min(lo, minAngle(h));
    }
  return lo;
}

}  // namespace

// The same surface with coincident vertices merged (closedBox builds six sheets).
Scene welded(const Scene& s) {
  std::map<std::array<float, 3>, uint32_t> id;
  std::vector<glm::dvec3> pts;
  std::vector<uint32_t> remap;
  for (const auto& p : s.positions) {
    const auto [it, added] = id.try_emplace({p.x, p.y, p.z}, uint32_t(pts.size()));
    if (added) pts.push_back(s.toWorld(p));
    remap.push_back(it->second);
  }
  std::vector<glm::uvec3> tris;
  for (const auto& t : s.triangles) tris.push_back({remap[t.x], remap[t.y], remap[t.z]});
  Scene w = Scene::fromAbsolute(pts, tris);
  w.rho = s.rho;
  return w;
}

TEST(Refine, ClosedMeshStaysClosedAreaAndAttributesKept) {
  Scene in = welded(scenes::closedBox(2.0, 3, false).scene);
  expectClosed(in);
  for (size_t f = 0; f < in.faceCount(); ++f) in.rho[f] = glm::vec3(0.01f * float(f % 50), 0.2f, 0.3f);
  in.emission.assign(in.faceCount(), glm::vec3(0.f));
  in.emission[5] = glm::vec3(7.f);
  in.vertexNormals = computeVertexNormals(in);
  MeshRefiner r(in);
  // Scattered marks, three levels: greens get undone and red closure spreads.
  for (int level = 0; level < 3; ++level) {
    std::vector<uint32_t> marks;
    for (uint32_t f = 0; f < r.mesh().scene.faceCount(); f += 7 + level) marks.push_back(f);
    const size_t predicted = r.faceCountAfter(marks);
    r.refine(marks);
    EXPECT_EQ(r.mesh().scene.faceCount(), predicted);
    expectClosed(r.mesh().scene);
  }
  const RefinedMesh& m = r.mesh();
  EXPECT_GT(m.scene.faceCount(), 4 * in.faceCount());
  // Area per source face preserved, each face inside its source triangle, attributes inherited.
  std::vector<double> area(in.faceCount(), 0.0);
  for (size_t f = 0; f < m.scene.faceCount(); ++f) {
    const uint32_t src = m.sourceFace[f];
    ASSERT_LT(src, in.faceCount());
    area[src] += faceArea(m.scene, f);
    EXPECT_EQ(m.scene.rho[f], in.rho[src]);
    EXPECT_EQ(m.scene.emission[f], in.emission[src]);
    const glm::vec3 n = glm::normalize(faceNormalUnnormalized(m.scene, f)),
                    n0 = glm::normalize(faceNormalUnnormalized(in, src));
    EXPECT_GT(glm::dot(n, n0), 0.9999f) << "face " << f << " flipped or off its source plane";
    const glm::vec3 c = (m.scene.positions[m.scene.triangles[f].x] + m.scene.positions[m.scene.triangles[f].y] +
                         m.scene.positions[m.scene.triangles[f].z]) / 3.f;
    const auto& t = in.triangles[src];
    for (int k = 0; k < 3; ++k) {  // the centroid is on the inner side of each source edge
      const glm::vec3 e = in.positions[t[(k + 1) % 3]] - in.positions[t[k]];
      EXPECT_GE(glm::dot(glm::cross(e, c - in.positions[t[k]]), n0), -1e-6f);
    }
  }
  for (size_t f = 0; f < in.faceCount(); ++f) EXPECT_NEAR(area[f], faceArea(in, f), 1e-6 * faceArea(in, f));
  // Input vertices unchanged and first; new ones at their parents' midpoint with unit normals.
  ASSERT_EQ(m.inputVertices, in.vertexCount());
  for (size_t v = 0; v < in.vertexCount(); ++v) EXPECT_EQ(m.scene.positions[v], in.positions[v]);
  ASSERT_EQ(m.scene.vertexNormals.size(), m.scene.vertexCount());
  for (size_t v = m.inputVertices; v < m.scene.vertexCount(); ++v) {
    const glm::uvec2 p = m.vertexParents[v];
    EXPECT_LT(p.y, v);
    EXPECT_LT(glm::length(m.scene.positions[v] - 0.5f * (m.scene.positions[p.x] + m.scene.positions[p.y])), 1e-6f);
    EXPECT_NEAR(glm::length(m.scene.vertexNormals[v]), 1.f, 1e-5f);
  }
  // No slivers: red children are similar to their parent; greens are halves of those.
  EXPECT_GE(minAngle(m.scene), angleBound(in) - 1e-3);
  // Mesh attributes follow the source faces; vertex colours interpolate.
  MeshAttributes a;
  for (size_t f = 0; f < in.faceCount(); ++f) {
    a.faceColor.push_back(glm::u8vec3(uint8_t(f), 1, 2));
    a.faceQuality.push_back(float(f));
    a.faceSelected.push_back(f == 5 ? 1 : 0);
  }
  a.vertexColor.assign(in.vertexCount(), glm::u8vec3(200, 100, 50));
  for (size_t v = 0; v < in.vertexCount(); ++v) a.vertexSelected.push_back(v % 3 ? 1 : 0);
  const MeshAttributes ra = refineAttributes(a, m);
  // A new vertex is selected where both its parents are; file normals carried
  // over as the refiner carries the scene's (the CLI writes them back).
  ASSERT_EQ(ra.vertexSelected.size(), m.scene.vertexCount());
  for (size_t v = 0; v < m.scene.vertexCount(); ++v)
    EXPECT_EQ(ra.vertexSelected[v], v < m.inputVertices ? a.vertexSelected[v]
                                                         : uint8_t(ra.vertexSelected[m.vertexParents[v].x] &&
                                                                   ra.vertexSelected[m.vertexParents[v].y]));
  const std::vector<glm::vec3> carried = refineVertexNormals(in.vertexNormals, m);
  ASSERT_EQ(carried.size(), m.scene.vertexCount());
  for (size_t v = 0; v < carried.size(); ++v) EXPECT_LT(glm::length(carried[v] - m.scene.vertexNormals[v]), 1e-5f);
  EXPECT_TRUE(refineVertexNormals({}, m).empty());
  ASSERT_EQ(ra.faceColor.size(), m.scene.faceCount());
  for (size_t f = 0; f < m.scene.faceCount(); ++f) {
    EXPECT_EQ(ra.faceQuality[f], float(m.sourceFace[f]));
    EXPECT_EQ(ra.faceSelected[f], m.sourceFace[f] == 5 ? 1 : 0);
    EXPECT_EQ(ra.faceColor[f].x, uint8_t(m.sourceFace[f]));
  }
  ASSERT_EQ(ra.vertexColor.size(), m.scene.vertexCount());
  for (const auto& c : ra.vertexColor) EXPECT_LE(std::abs(int(c.x) - 200) + std::abs(int(c.y) - 100), 2);
}

TEST(Refine, GreenFacesAreNeverBisectedTwice) {
  // One marked face in a flat grid: its neighbours go green; marking a green
  // face next must undo the pair and red-split its parent instead.
  scenes::SceneFile plane = scenes::openPlane(1.0, 4);
  MeshRefiner r(plane.scene);
  r.refine({10});
  const RefinedMesh& m1 = r.mesh();
  // 1 red (4) + 3 green pairs (6) + the rest.
  EXPECT_EQ(m1.scene.faceCount(), plane.scene.faceCount() - 4 + 4 + 6);
  uint32_t green = 0;
  while (m1.depth[green] != 0 || m1.sourceFace[green] == 10 ||
         std::count(m1.sourceFace.begin(), m1.sourceFace.end(), m1.sourceFace[green]) != 2)
    ++green;
  const uint32_t parent = m1.sourceFace[green];
  r.refine({green});
  const RefinedMesh& m2 = r.mesh();
  // The parent of the undone green pair is now four depth-1 faces.
  EXPECT_EQ(std::count(m2.sourceFace.begin(), m2.sourceFace.end(), parent), 4);
  for (size_t f = 0; f < m2.scene.faceCount(); ++f) {
    if (m2.sourceFace[f] == parent) {
      EXPECT_EQ(m2.depth[f], 1);
    }
  }
  EXPECT_GE(minAngle(m2.scene), angleBound(plane.scene) - 1e-3);
}

namespace {

// The refined floor faces of shadowScene(n)'s refinement: how many, and the
// farthest of their centroids from the line x = x0.
std::pair<size_t, double> refinedFloor(const RefinedMesh& m, int n, double x0) {
  size_t refined = 0;
  double far = 0;
  for (size_t f = 0; f < m.scene.faceCount(); ++f) {
    if (m.sourceFace[f] >= kFloorFaces(n) || m.depth[f] == 0) continue;
    ++refined;
    const glm::dvec3 c = m.scene.toWorld((m.scene.positions[m.scene.triangles[f].x] +
                                          m.scene.positions[m.scene.triangles[f].y] +
                                          m.scene.positions[m.scene.triangles[f].z]) / 3.f);
    far = std::max(far, std::fabs(c.x - x0));
  }
  return {refined, far};
}

}  // namespace

TEST(Refine, ConcentratesAtTheShadowBoundary) {
  const int n = 8;
  const Scene s = shadowScene(n);
  RadiosityOptions o = cheapOptions();
  o.refinement.threshold = 100;  // shadow test only
  o.refinement.maxDepth = 3;
  const AdaptiveRadiosity r = solveRadiosityAdaptive(s, o);
  const RefinedMesh& m = r.mesh;
  const auto [refined, far] = refinedFloor(m, n, 0.4);
  EXPECT_GT(refined, 100u);
  // The penumbra is 0.03 either side of x = 0.4; a coarse cell is 0.25 wide:
  // refined faces stay within the penumbra plus two coarse cells.
  EXPECT_LT(far, 0.03 + 2 * 0.25) << r.result.stats.line("refine");
  EXPECT_EQ(m.scene.faceCount(), size_t(r.result.stats.get("refined_patches")));
}

// The same floor and occluder lit by a sun straight overhead (the light
// square dark): the occluder's shadow edge runs along y at x = 0.2, its
// penumbra 1 tan(0.27 deg) = 0.005 either side. With the B jump test off,
// the sun's visibility alone must refine there (the shadow test counted
// only emitting faces: nothing was refined).
TEST(Refine, ConcentratesAtTheSunsShadowBoundary) {
  const int n = 8;
  Scene s = shadowScene(n);
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  RadiosityOptions o = cheapOptions();
  o.outside.sunDirection = glm::vec3(0.f, 0.f, 1.f);
  o.outside.sunIrradiance = glm::vec3(100.f);
  o.refinement.threshold = 100;  // shadow test only
  o.refinement.maxDepth = 3;
  const AdaptiveRadiosity r = solveRadiosityAdaptive(s, o);
  const auto [refined, far] = refinedFloor(r.mesh, n, 0.2);
  EXPECT_GT(refined, 100u) << r.result.stats.line("refine");
  EXPECT_LT(far, 0.005 + 2 * 0.25) << r.result.stats.line("refine");
  // The emitters' test alone sees no light and refines nothing.
  const std::vector<float> none = emitterVisibility(s, *makeEmbreeCaster(s), 64, 0);
  EXPECT_TRUE(std::all_of(none.begin(), none.end(), [](float v) { return v == -1.f; }));
  // Per vertex: 0 under the occluder and under the dark light square (the
  // floor's centre), 1 in the open, -1 for faces turned from the sun (the
  // occluder's and the light's, facing down).
  const std::vector<float> sun = sunVisibility(s, *makeEmbreeCaster(s), o.outside, 64, 0);
  for (size_t v = 0; v < size_t((n + 1) * (n + 1)); ++v) {
    const glm::dvec3 p = s.toWorld(s.positions[v]);
    const bool underLight = std::fabs(p.x) < kLight && std::fabs(p.y) < kLight;
    if ((p.x > 0.21 && p.x < 0.99) || underLight) EXPECT_EQ(sun[v], 0.f) << p.x << " " << p.y;
    else if (p.x < 0.19) EXPECT_EQ(sun[v], 1.f) << p.x << " " << p.y;
  }
  for (size_t v = size_t((n + 1) * (n + 1)); v < s.vertexCount(); ++v) EXPECT_EQ(sun[v], -1.f);
}

TEST(Refine, ErrorFallsWithFewerPatchesThanUniform) {
  const int n = 8;
  const Scene s = shadowScene(n);
  const Reference ref = reference(s, 60);  // 3,600 points, 1,152 light triangles each
  RadiosityOptions o = cheapOptions();
  o.refinement.maxDepth = 3;
  const AdaptiveRadiosity adaptive = solveRadiosityAdaptive(s, o);
  const double eAdaptive = floorError(adaptive.mesh, adaptive.result.Bvertex, ref, n);
  const MeshRefiner coarse(s);
  auto caster0 = makeEmbreeCaster(s);
  const double eCoarse = floorError(coarse.mesh(), solveRadiosity(s, *caster0, o).Bvertex, ref, n);
  // Uniform subdivision, two and three levels (every face red-split).
  double eUniform[2];
  size_t nUniform[2];
  MeshRefiner uniform(s);
  for (int level = 1; level <= 3; ++level) {
    std::vector<uint32_t> all(uniform.mesh().scene.faceCount());
    for (uint32_t f = 0; f < all.size(); ++f) all[f] = f;
    uniform.refine(all);
    if (level < 2) continue;
    auto caster = makeEmbreeCaster(uniform.mesh().scene);
    eUniform[level - 2] = floorError(uniform.mesh(), solveRadiosity(uniform.mesh().scene, *caster, o).Bvertex, ref, n);
    nUniform[level - 2] = uniform.mesh().scene.faceCount();
  }
  const size_t nAdaptive = adaptive.mesh.scene.faceCount();
  std::printf("[refine] coarse %zu patches %.4f; adaptive %zu patches %.4f; uniform %zu %.4f, %zu %.4f\n",
              s.faceCount(), eCoarse, nAdaptive, eAdaptive, nUniform[0], eUniform[0], nUniform[1], eUniform[1]);
  // Measured: coarse 132 patches 12.6%; adaptive 1,313 patches 0.76%;
  // uniform 2,112 patches 1.75%, 8,448 patches 0.37%.
  EXPECT_LT(eAdaptive, 0.1 * eCoarse);
  EXPECT_LT(nAdaptive, nUniform[0]);
  EXPECT_LT(eAdaptive, 0.6 * eUniform[0]);
}

TEST(Refine, BudgetAndDepthRespectedAndDeterministic) {
  const int n = 8;
  const Scene s = shadowScene(n);
  RadiosityOptions o = cheapOptions();
  o.refinement.maxDepth = 2;
  const AdaptiveRadiosity deep = solveRadiosityAdaptive(s, o);
  for (uint8_t d : deep.mesh.depth) EXPECT_LE(int(d), 2);
  o.refinement.maxDepth = 5;
  o.refinement.maxPatches = 400;
  const AdaptiveRadiosity capped = solveRadiosityAdaptive(s, o);
  EXPECT_LE(capped.mesh.scene.faceCount(), 400u);
  EXPECT_GT(capped.mesh.scene.faceCount(), 250u);
  bool saysBudget = false;
  for (const auto& note : capped.result.stats.notes) saysBudget |= note.find("patch budget") != std::string::npos;
  EXPECT_TRUE(saysBudget) << capped.result.stats.line("refine");
  // The level the budget cut says how many of the faces marked it refined
  // (it gave the marks' reasons as if all were refined; an outside audit).
  bool saysMarked = false;
  for (const auto& note : capped.result.stats.notes) saysMarked |= note.find(" faces marked refined (") != std::string::npos;
  EXPECT_TRUE(saysMarked) << capped.result.stats.line("refine");
  EXPECT_TRUE(capped.result.stats.warnings.empty()) << capped.result.stats.line("refine");
  // A budget below the input's patch count refines nothing, and says so.
  o.refinement.maxPatches = int(s.faceCount()) - 1;
  const AdaptiveRadiosity none = solveRadiosityAdaptive(s, o);
  EXPECT_EQ(none.mesh.scene.faceCount(), s.faceCount());
  ASSERT_EQ(none.result.stats.warnings.size(), 1u);
  EXPECT_NE(none.result.stats.warnings[0].find("below the mesh's"), std::string::npos);
  // Determinism: one thread against two.
  o.refinement.maxDepth = 2;
  o.refinement.maxPatches = 200000;
  AdaptiveRadiosity one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = solveRadiosityAdaptive(s, o);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = solveRadiosityAdaptive(s, o);
  }
  ASSERT_EQ(one.mesh.scene.triangles, two.mesh.scene.triangles);
  EXPECT_EQ(one.mesh.scene.positions, two.mesh.scene.positions);
  EXPECT_EQ(one.result.Bvertex, two.result.Bvertex);
  EXPECT_EQ(one.result.B, two.result.B);
}

TEST(Refine, BadFacesDoNotBreakIt) {
  // A face with an index out of range and a degenerate one beside marked faces:
  // left alone, no crash; the rest refines as usual.
  scenes::SceneFile plane = scenes::openPlane(1.0, 2);
  Scene s = plane.scene;
  const uint32_t nv = uint32_t(s.vertexCount());
  s.triangles.push_back({0, 1, nv + 5});
  s.triangles.push_back({0, 1, 1});
  s.rho.resize(s.triangles.size(), glm::vec3(0.5f));
  s.emission.resize(s.triangles.size(), glm::vec3(0.f));
  MeshRefiner r(s);
  std::vector<uint32_t> all(s.faceCount());
  for (uint32_t f = 0; f < all.size(); ++f) all[f] = f;
  r.refine(all);
  r.refine(all);
  const RefinedMesh& m = r.mesh();
  EXPECT_EQ(std::count(m.sourceFace.begin(), m.sourceFace.end(), uint32_t(s.faceCount() - 2)), 1);
  for (size_t f = 0; f < m.scene.faceCount(); ++f) {
    if (m.sourceFace[f] == s.faceCount() - 2) continue;
    for (int k = 0; k < 3; ++k) EXPECT_LT(m.scene.triangles[f][k], m.scene.vertexCount());
  }
  EXPECT_GT(m.scene.faceCount(), 4 * plane.scene.faceCount());
}

// Per-face arrays shorter (or longer) than the face list: one clear error
// naming the array, before anything is read past its end.
TEST(Refine, PerFaceArraysOfTheWrongSizeAreAClearError) {
  const Scene plane = scenes::openPlane(1.0, 2).scene;
  for (int which = 0; which < 4; ++which) {
    Scene s = plane;
    s.material.assign(s.faceCount(), Material::Diffuse);
    s.ior.assign(s.faceCount(), 1.5f);
    s.triangles.push_back(s.triangles.front());  // one face more than the arrays
    if (which != 0) s.rho.push_back(glm::vec3(0.5f));
    if (which != 1) s.emission.push_back(glm::vec3(0.f));
    if (which != 2) s.material.push_back(Material::Diffuse);
    if (which != 3) s.ior.push_back(1.5f);
    const char* names[] = {"reflectance", "emission", "material", "index of refraction"};
    try {
      MeshRefiner r(s);
      ADD_FAILURE() << "no error for a short " << names[which] << " array";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(names[which]), std::string::npos) << e.what();
    }
  }
}
