// The final gather at vertices on the edges of a room (where a wall meets
// the ceiling, the floor or another wall) against the path-traced
// reference. Half of such a vertex's gather rays land within a few ray
// offsets of the edge, on patches whose mean indirect light overstates what
// a point at the edge receives (there the other surface fills half of its
// sky): read from the patch means, the edge vertices of the Cornell box came
// out 3% too bright on average (6% RMS). The multi-level gather at near
// hits (radiosity.cpp, gatherIndirect) removes that bias.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "gi/ao_shared.h"
#include "gi/color.h"
#include "gi/pathtrace.h"
#include "gi/radiosity.h"
#include "gi/raycaster.h"
#include "gi/scene_setup.h"
#include "gi/scenes.h"
#include "render_test_helpers.h"
#include "test_helpers.h"

using namespace gi;

namespace {

// Vertices on two faces of the scene's bounding box: the room's edges.
std::vector<uint8_t> roomEdgeVertices(const Scene& s) {
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : s.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  const glm::vec3 ext = hi - lo;
  const float tol = 1e-4f * std::max(ext.x, std::max(ext.y, ext.z));
  std::vector<uint8_t> edge(s.vertexCount(), 0);
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    int planes = 0;
    for (int a = 0; a < 3; ++a)
      planes += (std::fabs(s.positions[v][a] - lo[a]) < tol) + (std::fabs(s.positions[v][a] - hi[a]) < tol);
    edge[v] = planes == 2;
  }
  return edge;
}

// d = (B - ref) / ref over the edge vertices the reference traced: its
// mean, the mean's standard error (from the spread of d) and its RMS.
struct EdgeError {
  int n = 0;
  double mean = 0, sem = 0, rms = 0;
};

EdgeError edgeError(const std::vector<uint8_t>& edge, const PathTraceResult& ref, const std::vector<glm::vec3>& B) {
  double sum = 0, sum2 = 0;
  EdgeError e;
  for (size_t v = 0; v < edge.size(); ++v) {
    const double q = luminance(ref.B[v]);
    if (!edge[v] || !(q > 0)) continue;
    const double d = luminance(B[v]) / q - 1.0;
    sum += d, sum2 += d * d, ++e.n;
  }
  e.mean = sum / e.n;
  e.rms = std::sqrt(sum2 / e.n);
  e.sem = std::sqrt((sum2 / e.n - e.mean * e.mean) / (e.n - 1));
  return e;
}

// The reference at the edge vertices alone: 16,384 paths each.
PathTraceResult edgeReference(const Scene& s, const RayCaster& caster, std::shared_ptr<std::vector<uint8_t>> edge,
                              int maxDepth) {
  PathTraceOptions po;
  po.samplesPerVertex = 16384;
  po.maxDepth = maxDepth;
  po.tracedSelected = true;
  po.selectedVertices = std::move(edge);
  return pathTrace(s, caster, po);
}

// The converged solution of `solver` gathered with `rays` rays a vertex,
// against the reference at the marked vertices; printed as `what`.
EdgeError convergedAgainst(const Scene& s, const RayCaster& caster, const std::vector<uint8_t>& marked,
                           const PathTraceResult& ref, RadiositySolver solver, int rays, const char* what) {
  RadiosityOptions o;
  o.solver = solver;
  o.gatherRays = rays;
  const EdgeError e = edgeError(marked, ref, solveRadiosity(s, caster, o).Bvertex);
  std::printf("%s: %d %s vertices, mean %+.4f (standard error %.4f), RMS %.4f\n",
              solver == RadiositySolver::GaussSeidel ? "flat" : "hierarchical", e.n, what, e.mean, e.sem, e.rms);
  return e;
}

void expectWithinTheReference(const EdgeError& e, double bias = 0) {
  EXPECT_GT(e.n, 150);
  EXPECT_LT(std::fabs(e.mean), 4 * e.sem + bias);
  EXPECT_LT(std::fabs(e.mean), 0.01);
  EXPECT_LT(e.rms, 0.025);
}

}  // namespace

// The Cornell box (1.5k patches) at its 165 edge vertices: the flat solver
// (Gauss-Seidel) and the hierarchical one, 2048 gather rays per vertex so
// that the gather's own noise is small; the reference traces 16,384 paths
// at each edge vertex (about 1.2% standard error each). d = (B - ref) / ref
// per vertex; its mean must lie within 4 standard errors of the mean (from
// the spread of d itself, which holds both noises) of 0 and below 1%, and
// its RMS below 2.5%. Measured: flat mean +0.08% (standard error 0.11%),
// RMS 1.4%; hierarchical -0.34% (0.11%), RMS 1.5%, which is allowed 0.5%
// besides (README, Limitations); on 6 December 2026 flat -0.09%, RMS 1.4%,
// hierarchical -0.51%, RMS 1.5%. Before the solvers worked with the seen
// parts of the floor's patches under the blocks (test_patch_seen.cpp):
// flat -0.42%, hierarchical -0.79%. Reading the patch means at every near hit: flat +3.1% (7.8
// standard errors), RMS 6.0%; hierarchical +3.4%, RMS 6.8%: the test fails.
TEST(FinalGather, RoomEdgeVerticesMatchTheReference) {
  auto sf = scenes::cornellBox(50.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  auto edge = std::make_shared<std::vector<uint8_t>>(roomEdgeVertices(s));
  const PathTraceResult ref = edgeReference(s, *caster, edge, -1);
  for (RadiositySolver solver : {RadiositySolver::GaussSeidel, RadiositySolver::Hierarchical})
    expectWithinTheReference(convergedAgainst(s, *caster, *edge, ref, solver, 2048, "edge"),
                             solver == RadiositySolver::Hierarchical ? 0.005 : 0.0);
}

// A fixed bounce count (the course's images, one bounce the classic one):
// with K bounces a near hit must reflect its direct light and its own
// indirect light one bounce short, R^(K)(y) = rho (H_direct(y) +
// H^(K-1)(y)), gathered again at the hit from the patch values of K - 1
// bounces (and so on down the near hits). Reading the patch's mean instead
// made an outside check's sealed room's ceiling-edge vertices 25% bright at
// one bounce and 6.6% at two. Against the reference cut at K bounces
// (max_depth K), the same measures as above, K = 1, 2, 3 (the flat solver)
// and 2 (the hierarchical one, which keeps its own bounce values).
// Measured: mean +0.10%, +0.10%, +0.10% (standard errors 0.12 to 0.16%;
// hierarchical at 2: -0.01%), RMS 2.1%, 1.6%, 1.6% (-0.05%, -0.12%, -0.19%
// before the seen parts of the floor's patches under the blocks); reading the patch means at near hits instead
// (one bounce as before its fix, two and three as before this one): +5.3%,
// +7.0%, +6.8%, RMS 12%, 11%, 11%.
TEST(FinalGather, RoomEdgeVerticesMatchTheReferenceAtFixedBounces) {
  auto sf = scenes::cornellBox(50.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  auto edge = std::make_shared<std::vector<uint8_t>>(roomEdgeVertices(s));
  for (int K : {1, 2, 3}) {
    const PathTraceResult ref = edgeReference(s, *caster, edge, K);
    for (RadiositySolver solver : {RadiositySolver::GaussSeidel, RadiositySolver::Hierarchical}) {
      if (solver == RadiositySolver::Hierarchical && K != 2) continue;
      RadiosityOptions o;
      o.solver = solver;
      o.bounces = K;
      o.gatherRays = 2048;
      const EdgeError e = edgeError(*edge, ref, solveRadiosity(s, *caster, o).Bvertex);
      std::printf("%d bounces, %s: %d edge vertices, mean %+.4f (standard error %.4f), RMS %.4f\n", K,
                  solver == RadiositySolver::GaussSeidel ? "flat" : "hierarchical", e.n, e.mean, e.sem, e.rms);
      expectWithinTheReference(e);
    }
  }
}

// Where three surfaces meet: a sealed room of two triangles a wall (each
// wall its own vertices, all of them at the room's 8 corners), a small light
// below the ceiling. A corner vertex's near hits land near the corner again
// at every level; reading the patch's mean after the last level (the mean
// of a whole wall, far above what the corner receives) made them 8-10%
// bright at the ceiling and 2-3% at the floor (an outside check). The
// converged solution goes on past the levels by Russian roulette. The 24
// corner vertices against the reference (16,384 paths each, about 1%
// standard error): the mean of d within 4 of its standard errors (from its
// spread) of 0 and below 1.5%. Measured: mean +0.5% (standard error 0.2%;
// with form-factor seeds 1 to 3 +0.1%, +0.1%, +0.7%, standard errors 0.3%);
// reading the mean: +6.4% (flat), +3.1% (hierarchical): the test fails.
TEST(FinalGather, RoomCornerVerticesMatchTheReference) {
  test::SceneBuilder b;
  b.box({0, 0, 0}, {1, 1, 1}, glm::vec3(0.7f), glm::vec3(0.f), Material::Diffuse, true);
  b.quad({0.4, 0.99, 0.4}, {0.6, 0.99, 0.4}, {0.6, 0.99, 0.6}, {0.4, 0.99, 0.6}, glm::vec3(0.f), glm::vec3(10.f));
  const Scene s = b.build();
  auto caster = makeEmbreeCaster(s);
  auto corners = std::make_shared<std::vector<uint8_t>>(s.vertexCount(), 0);
  std::fill(corners->begin(), corners->begin() + 24, 1);  // the walls' vertices
  const PathTraceResult ref = edgeReference(s, *caster, corners, -1);
  for (RadiositySolver solver : {RadiositySolver::GaussSeidel, RadiositySolver::Hierarchical}) {
    const EdgeError e = convergedAgainst(s, *caster, *corners, ref, solver, 4096, "corner");
    EXPECT_EQ(e.n, 24);
    EXPECT_LT(std::fabs(e.mean), 4 * e.sem);
    EXPECT_LT(std::fabs(e.mean), 0.015);
  }
}

// Sharing the gather between neighbours (gather_share_rings) on the Cornell
// box at 10k patches (5,233 vertices, 2 cm apart): 256 gather rays per
// vertex, pooled up to 2 rings or not, against the same patch solution
// gathered with 4,096 rays per vertex without pooling (the solution is the
// same bits whatever the gather; the 4,096-ray gather's own noise is about
// a quarter of the 256-ray one's). Errors relative to max(value, a tenth of
// the mean). Pooling must cut the RMS error over all vertices, and must not
// raise it where the gathered light is not smooth: at the vertices whose
// value differs from the mean of their neighbours' by more than 3% in the
// 4,096-ray gather (the blocks' feet, the room's edges, around the light).
// Measured: all vertices 1.70% -> 1.43%; the 1,140 rough ones 2.50% ->
// 2.45%, though single vertices lose: 11 are more than 5 points worse (at
// most 6.9, on the ceiling next to a wall and by the light; asserted below
// 10). The 1.5k box (vertices 5 cm apart) gains nothing: its light changes
// too much across a pool.
TEST(FinalGather, SharingWithNeighboursCutsTheNoiseNotTheDetail) {
  auto sf = scenes::cornellBox(20.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  auto run = [&](int rays, int rings) {
    RadiosityOptions o;
    o.solver = RadiositySolver::GaussSeidel;
    o.gatherRays = rays;
    o.gatherShareRings = rings;
    return solveRadiosity(s, *caster, o);
  };
  const RadiosityResult truth = run(4096, 0), own = run(256, 0), shared = run(256, 2);
  const VertexGraph g = VertexGraph::build(s);
  double meanB = 0;
  int counted = 0;
  for (size_t v = 0; v < s.vertexCount(); ++v)
    if (g.degree(uint32_t(v)) > 0) meanB += luminance(truth.Bvertex[v]), ++counted;
  meanB /= counted;
  double eOwn = 0, eShared = 0, rOwn = 0, rShared = 0;
  int n = 0, rough = 0, worse = 0;
  double worst = 0;  // the most a vertex's error grew by pooling
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    const double t = luminance(truth.Bvertex[v]);
    if (!(t > 0) || g.degree(uint32_t(v)) == 0) continue;
    double nb = 0;
    for (uint32_t k = g.offset[v]; k < g.offset[v + 1]; ++k) nb += luminance(truth.Bvertex[g.nbr[k]]);
    nb /= double(g.degree(uint32_t(v)));
    const double scale = std::max(t, 0.1 * meanB);
    const double dOwn = (luminance(own.Bvertex[v]) - t) / scale, dShared = (luminance(shared.Bvertex[v]) - t) / scale;
    eOwn += dOwn * dOwn, eShared += dShared * dShared, ++n;
    const double grew = std::fabs(dShared) - std::fabs(dOwn);
    worse += grew > 0.05, worst = std::max(worst, grew);
    if (std::fabs(nb / t - 1) > 0.03) rOwn += dOwn * dOwn, rShared += dShared * dShared, ++rough;
  }
  eOwn = std::sqrt(eOwn / n), eShared = std::sqrt(eShared / n);
  rOwn = std::sqrt(rOwn / rough), rShared = std::sqrt(rShared / rough);
  std::printf("%d vertices: own rays %.4f, shared %.4f; %d rough: own %.4f, shared %.4f; pools of %.1f vertices; "
              "%d vertices more than 5 points worse, at most %.3f\n",
              n, eOwn, eShared, rough, rOwn, rShared, shared.stats.get("gather_pool_vertices"), worse, worst);
  EXPECT_LT(eShared, 0.9 * eOwn);
  EXPECT_GT(rough, 30);
  EXPECT_LT(rShared, rOwn);
  EXPECT_LT(worst, 0.1);
}

// A two-sided floor (every face with a reversed copy on the same vertices,
// as some exporters write double-sided geometry) under a light: the
// vertices' normals cancel, so there is no side to gather on. They wrote 0
// (9 of 25 vertices in a reviewer's run); they now take the patch average
// of their faces, both sides, in every vertex mode, and the log says how
// many. Border vertices keep no normal either (their faces cancel too).
TEST(FinalGather, TwoSidedSurfaceTakesThePatchAverage) {
  auto [pts, tris] = test::twoSided(scenes::openPlane(2.0, 4).scene);
  const uint32_t l = uint32_t(pts.size());  // a light 0.5 wide at height 1, facing down
  for (glm::dvec3 p : {glm::dvec3(-0.25, -0.25, 1), glm::dvec3(0.25, -0.25, 1), glm::dvec3(0.25, 0.25, 1),
                       glm::dvec3(-0.25, 0.25, 1)})
    pts.push_back(p);
  tris.push_back({l, l + 2, l + 1});
  tris.push_back({l, l + 3, l + 2});
  Scene s = Scene::fromAbsolute(pts, tris);
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  s.emission[s.faceCount() - 1] = s.emission[s.faceCount() - 2] = glm::vec3(10.f);
  auto caster = makeEmbreeCaster(s);
  for (auto mode : {RadiosityVertexOutput::FinalGather, RadiosityVertexOutput::InterpolatedIndirect}) {
    RadiosityOptions o;
    o.vertexOutput = mode;
    o.gatherRays = 16;
    const RadiosityResult r = solveRadiosity(s, *caster, o);
    const std::vector<glm::vec3> average = faceToVertex(s, r.B);
    size_t lit = 0;
    for (uint32_t v = 0; v < l; ++v) {
      EXPECT_GT(r.Bvertex[v].g, 0.f) << "vertex " << v;
      EXPECT_EQ(r.Bvertex[v], average[v]) << "vertex " << v;
      lit += r.Bvertex[v].g > 0.f;
    }
    EXPECT_EQ(lit, size_t(l));
    bool noted = false;
    for (const auto& n : r.stats.notes) noted |= n.find("25 vertices without a normal") != std::string::npos;
    EXPECT_TRUE(noted) << r.stats.line("radiosity");
  }
}
