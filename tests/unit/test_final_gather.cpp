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
#include <vector>

#include "gi/color.h"
#include "gi/pathtrace.h"
#include "gi/radiosity.h"
#include "gi/raycaster.h"
#include "gi/scenes.h"

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

}  // namespace

// The Cornell box (1.5k patches) at its 165 edge vertices: the flat solver
// (Gauss-Seidel) and the hierarchical one, 2048 gather rays per vertex so
// that the gather's own noise is small; the reference traces 16,384 paths
// at each edge vertex (about 1.2% standard error each). d = (B - ref) / ref
// per vertex; its mean must lie within 4 standard errors of the mean (from
// the spread of d itself, which holds both noises) of 0 and below 1%, and
// its RMS below 2.5%. Measured: flat mean -0.03% (standard error 0.13%),
// RMS 1.7%; hierarchical -0.30% (0.14%), RMS 1.8%. Reading the patch means
// at near hits, as before: flat +3.1% (7.8 standard errors), RMS 6.0%;
// hierarchical +3.4%, RMS 6.8%: the test fails.
TEST(FinalGather, RoomEdgeVerticesMatchTheReference) {
  auto sf = scenes::cornellBox(50.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  auto edge = std::make_shared<std::vector<uint8_t>>(roomEdgeVertices(s));
  PathTraceOptions po;
  po.samplesPerVertex = 16384;
  po.tracedSelected = true;
  po.selectedVertices = edge;
  const PathTraceResult ref = pathTrace(s, *caster, po);
  for (RadiositySolver solver : {RadiositySolver::GaussSeidel, RadiositySolver::Hierarchical}) {
    RadiosityOptions o;
    o.solver = solver;
    o.gatherRays = 2048;
    const RadiosityResult r = solveRadiosity(s, *caster, o);
    double sum = 0, sum2 = 0;
    int n = 0;
    for (size_t v = 0; v < s.vertexCount(); ++v) {
      const double q = luminance(ref.B[v]);
      if (!(*edge)[v] || !(q > 0)) continue;
      const double d = luminance(r.Bvertex[v]) / q - 1.0;
      sum += d, sum2 += d * d, ++n;
    }
    const double mean = sum / n, rms = std::sqrt(sum2 / n), sem = std::sqrt((sum2 / n - mean * mean) / (n - 1));
    std::printf("%s: %d edge vertices, mean %+.4f (standard error %.4f), RMS %.4f\n",
                solver == RadiositySolver::GaussSeidel ? "flat" : "hierarchical", n, mean, sem, rms);
    EXPECT_GT(n, 150);
    EXPECT_LT(std::fabs(mean), 4 * sem);
    EXPECT_LT(std::fabs(mean), 0.01);
    EXPECT_LT(rms, 0.025);
  }
}
