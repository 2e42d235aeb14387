// The spatial order of a mesh's vertices (gi/vertex_order.h): a permutation
// that brings neighbours together in memory, a reordered copy with the same
// geometry, and filters that give every vertex the same value in either
// order (its rays are keyed by its index in the mesh), whole or split into
// parts. Also: the face loops made parallel (normals, ray origins) add in
// face order, so their bits do not depend on the number of threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>

#include <tbb/global_control.h>

#include "gi/ambient.h"
#include "gi/filter_run.h"
#include "gi/raycaster.h"
#include "gi/scan.h"
#include "gi/vertex_order.h"
#include "mesh_io.h"

using namespace gi;

namespace {

const Scene& bunny() {
  static const Scene s = io::loadMesh(std::string(GI_TEST_MESHES) + "/bunny.ply").scene;
  return s;
}

// A generated scan of `levels` Loop steps (29k vertices at 2, 118k at 3) in
// the order subdivision writes it: each level's new vertices after the old.
Scene scan(int levels) {
  scenes::ScanOptions o;
  o.levels = levels;
  return scenes::displacedScan(bunny(), o);
}

// The median index distance across the mesh's edges.
double medianEdgeSpan(const Scene& s) {
  std::vector<double> d;
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) d.push_back(std::fabs(double(t[k]) - double(t[(k + 1) % 3])));
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

template <class T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

FilterInput inputOf(const Scene& s, FilterKind kind, const std::map<std::string, std::string>& params) {
  FilterInput in;
  in.scene = s;
  in.layers.push_back({"mesh", 0, s.faceCount()});
  const auto specs = filterSpecs(kind);
  const double diag = analyzeScene(in.scene).diagonal;
  in.values = defaultValues(specs, diag);
  for (const auto& [k, v] : params) in.values.set(k, parseValue(*findSpec(specs, k), v, diag));
  return in;
}

}  // namespace

TEST(VertexOrder, APermutationThatBringsNeighboursTogether) {
  Scene s = scan(2);
  s.positions[17] = glm::vec3(NAN, 0.f, 0.f);  // a broken vertex goes last
  const size_t nv = s.vertexCount();
  EXPECT_TRUE(spatialVertexOrder(s, nv + 1).identity());  // below the threshold: nothing to do
  const VertexOrder o = spatialVertexOrder(s);
  ASSERT_FALSE(o.identity());
  std::vector<uint32_t> sorted = *o.meshIndex;
  std::sort(sorted.begin(), sorted.end());
  std::vector<uint32_t> all(nv);
  std::iota(all.begin(), all.end(), 0u);
  ASSERT_EQ(sorted, all);
  EXPECT_EQ(o.meshIndex->back(), 17u);

  const Scene r = reorderVertices(s, o);
  ASSERT_EQ(r.faceCount(), s.faceCount());
  for (size_t f = 0; f < s.faceCount(); ++f)
    for (int k = 0; k < 3; ++k)
      ASSERT_TRUE(sameBits(std::vector<glm::vec3>{r.positions[r.triangles[f][k]]},
                           std::vector<glm::vec3>{s.positions[s.triangles[f][k]]}))
          << "face " << f << " corner " << k;
  EXPECT_TRUE(sameBits(toMeshOrder(r.positions, o), s.positions));
  // Subdivision's order: half the edges span more than a tenth of the mesh.
  // Along the curve the median edge spans a few places.
  const double before = medianEdgeSpan(s), after = medianEdgeSpan(r);
  EXPECT_GT(before, 0.05 * double(nv));
  EXPECT_LT(after, 1e-3 * double(nv)) << "before " << before;
}

// Out-of-range indices stay out of range (the filters' checks still see them).
TEST(VertexOrder, KeepsBadIndicesBad) {
  Scene s = scan(1);
  s.triangles[3][1] = uint32_t(s.vertexCount() + 5);
  const Scene r = reorderVertices(s, spatialVertexOrder(s));
  EXPECT_EQ(r.triangles[3][1], uint32_t(s.vertexCount() + 5));
}

// The face loops run in parallel blocks but add in face order: the same bits
// on one thread as on several.
TEST(VertexOrder, NormalsAndRayOriginsDoNotDependOnThreads) {
  const Scene s = scan(2);
  std::vector<glm::vec3> n1, o1;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    n1 = computeVertexNormals(s);
    o1 = vertexRayOrigins(s, n1, 1e-4f);
  }
  const std::vector<glm::vec3> n2 = computeVertexNormals(s);
  EXPECT_TRUE(sameBits(n1, n2));
  EXPECT_TRUE(sameBits(o1, vertexRayOrigins(s, n2, 1e-4f)));
}

// A mesh above the threshold is computed in the spatial order; each vertex
// keeps its rays, so the per-vertex estimator gives the bits of a run in the
// mesh's order, and the shared one (whose pools add their neighbours in
// another order) the same values up to rounding.
TEST(VertexOrder, AmbientOcclusionGivesEachVertexTheSameValue) {
  const Scene s = scan(3);
  ASSERT_GE(s.vertexCount(), kSpatialOrderFrom);
  const auto caster = makeEmbreeCaster(s, BatchMode::Single);
  {
    FilterInput in = inputOf(s, FilterKind::AmbientOcclusion, {{"rays_per_vertex", "4"}});
    const FilterResult r = runFilter(FilterKind::AmbientOcclusion, in);
    EXPECT_GT(r.stats.get("vertex_order_seconds", -1.0), 0.0);  // it was reordered
    AmbientOptions o;
    o.raysPerVertex = 4;
    EXPECT_TRUE(sameBits(r.vertexQuality, computeAmbient(s, *caster, o).value));
  }
  {
    FilterInput in = inputOf(s, FilterKind::AmbientOcclusion,
                             {{"estimator", "1"}, {"target_error", "0.05"}, {"min_rays", "4"}, {"max_rays", "64"}});
    const FilterResult r = runFilter(FilterKind::AmbientOcclusion, in);
    AmbientOptions o;
    o.estimator = AOEstimator::Shared;
    o.targetError = 0.05;
    o.minRays = 4;
    o.maxRays = 64;
    const AmbientResult whole = computeAmbient(s, *caster, o);
    size_t differ = 0;
    double worst = 0;
    for (size_t i = 0; i < s.vertexCount(); ++i) {
      const double d = std::fabs(double(r.vertexQuality[i]) - whole.value[i]);
      differ += d > 1e-5 ? 1 : 0;
      worst = std::max(worst, d);
    }
    // A pool's sums in another order may, rarely, tip Lepski's rule at one vertex.
    EXPECT_LE(differ, s.vertexCount() / 1000) << "largest difference " << worst;
  }
}
