// Photon mapping where another surface lies inside the gather sphere, on
// the Cornell box as shipped (test_meshes/cornell_box.ply): its lamp hangs
// 0.1 mm below the ceiling, and its blocks stand on a floor that goes on
// under them. Until 5 December 2026 the k-nearest estimate read the ceiling
// vertices on the lamp's border 1.6 to 2.7 times their reference (the
// lamp's photons counted as the ceiling's, and the sphere averages away the
// lamp's shadow on the point 0.1 mm above it), and the floor vertices along
// the blocks' feet up to 40% low (the floor under the block counted as area
// no photon reaches); the final gather read those foot vertices 33-42% low
// (half of their rays land within a few centimetres, on floor whose
// estimate has the same fault). Now the k-nearest mode hands such vertices
// to the final gather, and the gather relights its near hits. Progressive
// photon mapping read the lamp's border +57% (worst +124%) until 5 December
// 2026; it now hands over the same vertices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "gi/color.h"
#include "gi/filters.h"
#include "gi/pathtrace.h"
#include "gi/photon.h"
#include "gi/scene_setup.h"
#include "mesh_io.h"

using namespace gi;

namespace {

double segmentDistance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
  const glm::dvec3 d = b - a;
  const double t = glm::clamp(glm::dot(p - a, d) / glm::dot(d, d), 0.0, 1.0);
  return glm::length(p - (a + t * d));
}

struct Group {
  const char* name;
  std::vector<size_t> vertices;
};

}  // namespace

// Reference: the path tracer at the chosen vertices (16,384 paths each,
// about 1% standard error). Errors are weighted by the reference (the
// blocks' backs at the floor are 20 times darker than the lit floor, and
// their reference noise alone would dominate relative errors): the group's
// mean, sum (photon map - reference) / sum reference, within 6%, and every
// vertex's difference within 40% of the group's mean value (the gathered
// vertices, 64 rays each, scatter by 10-20% of it). Measured at the code
// before the change (the default seed, against a cached reference of the
// same tracer): the lamp's border +62.6% (worst 111%), the blocks' sides at
// the floor -21.1% with the final gather and a worst of 74% at k nearest;
// after: -0.3%, +2.1%, the worst 23%. Progressive (8 passes of 200,000
// paths) with its hand-over switched off: the lamp's border +59.2% (worst
// 133%); with it, as the k-nearest mode (the same first pass's photons).
TEST(PhotonContact, LampBorderAndBlockFeetMatchTheReference) {
  io::LoadedMesh mesh = io::loadMesh(std::string(GI_TEST_MESHES) + "/cornell_box.ply");
  Scene s = mesh.scene;
  const auto specs = filterSpecs(FilterKind::PhotonMapping);
  ParamValues v = defaultValues(specs, 1.0);
  ASSERT_FALSE(applySceneConventions(s, mesh.attrs, v, true).has_value());
  auto caster = makeEmbreeCaster(s);

  // The blocks' bottom edges: both ends on the floor, inside the room.
  std::vector<std::pair<glm::dvec3, glm::dvec3>> feet;
  const auto world = [&](uint32_t i) { return s.toWorld(s.positions[i]); };
  const auto inRoom = [](const glm::dvec3& p) { return p.x > 5 && p.x < 545 && p.z > 5 && p.z < 550; };
  for (const auto& t : s.triangles) {
    const glm::dvec3 n = glm::normalize(glm::cross(world(t.y) - world(t.x), world(t.z) - world(t.x)));
    if (std::abs(n.y) > 0.5) continue;
    const uint32_t c[3] = {t.x, t.y, t.z};
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 a = world(c[k]), b = world(c[(k + 1) % 3]);
      if (a.y < 0.5 && b.y < 0.5 && inRoom(a) && inRoom(b)) feet.push_back({a, b});
    }
  }
  ASSERT_GE(feet.size(), 8u);
  // Which vertices are the floor's and the ceiling's (their faces' normals).
  std::vector<int> up(s.vertexCount(), 0);
  for (const auto& t : s.triangles) {
    const glm::dvec3 n = glm::normalize(glm::cross(world(t.y) - world(t.x), world(t.z) - world(t.x)));
    for (uint32_t i : {t.x, t.y, t.z}) up[i] = n.y > 0.99 ? 1 : n.y < -0.99 ? -1 : up[i];
  }
  Group lamp{"ceiling on the lamp's border", {}}, foot{"the blocks' sides at the floor", {}},
      floor{"floor within 30 mm of a block", {}};
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    const glm::dvec3 p = world(uint32_t(i));
    if (up[i] == -1 && std::abs(p.y - 548.8) < 0.01) {
      const bool onX = (std::abs(p.x - 213) < 0.01 || std::abs(p.x - 343) < 0.01) && p.z > 226.9 && p.z < 332.1;
      const bool onZ = (std::abs(p.z - 227) < 0.01 || std::abs(p.z - 332) < 0.01) && p.x > 212.9 && p.x < 343.1;
      if (onX || onZ) lamp.vertices.push_back(i);
    }
    if (p.y > 0.01 || !inRoom(p)) continue;
    double d = 1e9;
    for (const auto& [a, b] : feet) d = std::min(d, segmentDistance(p, a, b));
    if (up[i] == 0 && d < 0.01) foot.vertices.push_back(i);
    if (up[i] == 1 && d < 30) floor.vertices.push_back(i);
  }
  ASSERT_GE(lamp.vertices.size(), 16u);
  ASSERT_GE(foot.vertices.size(), 16u);
  ASSERT_GE(floor.vertices.size(), 8u);

  auto chosen = std::make_shared<std::vector<uint8_t>>(s.vertexCount(), 0);
  for (const Group* g : {&lamp, &foot, &floor})
    for (size_t i : g->vertices) (*chosen)[i] = 1;
  // At max_depth 1 as well: the gather's map then holds no photon on the
  // ceiling (the lamp faces down), and a relit near hit's ray that reached
  // it read an estimate left unset, uninitialised memory: floor vertices
  // beside the blocks read up to 2,300 instead of about 0.07 in a CLI run,
  // the blocks' sides at the floor +74% here (found 5 December 2026).
  for (const int maxDepth : {32, 1}) {
    PathTraceOptions po;
    po.samplesPerVertex = 16384;
    po.tracedSelected = true;
    po.selectedVertices = chosen;
    po.maxDepth = maxDepth;
    const PathTraceResult ref = pathTrace(s, *caster, po);
    for (const char* mode : {"k nearest", "final gather", "progressive"}) {
      PhotonOptions o;
      o.finalGather = std::string(mode) == "final gather";
      o.progressive = std::string(mode) == "progressive";
      o.maxDepth = maxDepth;
      if (o.progressive && maxDepth == 1) continue;  // the same gather as the k-nearest mode's
      if (o.progressive) o.passes = 8;                // of the default 200,000 paths
      const VertexRadiometry r = computePhotonMap(s, *caster, o);
      if (!o.finalGather) {
        EXPECT_GT(r.stats.get("vertices_gathered_beside_other_surfaces", 0.0), 0.0);
        EXPECT_GT(r.stats.get("gather_near_hits_relit", 0.0), 0.0);
      }
      for (const Group* g : {&lamp, &foot, &floor}) {
        // Weighted by the reference: the blocks' backs at the floor are 20
        // times darker than the lit floor, and their 1% reference noise alone
        // would dominate relative errors.
        double diff = 0, sumRef = 0, worst = 0;
        size_t n = 0;
        for (size_t i : g->vertices) {
          if (!(luminance(ref.B[i]) > 0.f)) continue;  // under a block
          diff += double(luminance(r.B[i])) - double(luminance(ref.B[i]));
          sumRef += double(luminance(ref.B[i]));
          ++n;
        }
        for (size_t i : g->vertices)
          if (luminance(ref.B[i]) > 0.f)
            worst = std::max(worst, std::abs(double(luminance(r.B[i])) - double(luminance(ref.B[i]))) * double(n) /
                                        sumRef);
        std::printf("max_depth %d, %s, %s: %zu vertices, (photon map - reference) / reference: mean %+.4f, worst "
                    "%.4f of the mean\n",
                    maxDepth, mode, g->name, n, diff / sumRef, worst);
        EXPECT_LT(std::abs(diff / sumRef), 0.06) << g->name << ", max_depth " << maxDepth << ", " << mode;
        EXPECT_LT(worst, 0.4) << g->name << ", max_depth " << maxDepth << ", " << mode;
      }
    }
  }
}

// A point light on the box's surfaces: at its corner (the default
// position, world (0, 0, 0)) and on the left wall's plane. Its photons were
// traced from the light itself, where every direction hits the faces it
// lies on at t ~ 0: on their back (absorbed: all light lost) or their front
// (stored at the light: the vertex there read 1.9e33, the mean 1.9e30; an
// outside sweep, 5 December 2026). Now its light towards those faces'
// backs is absorbed and the rest leaves from past them. Against the path
// tracer (256 paths a vertex, whose next-event estimation to the point
// light never traces from it): the mean over the vertices within 3% (seen:
// 1.540 against 1.528, 3.941 against 3.947 at 1,024 paths), and no vertex
// above twice the brightest reference vertex (the lamp's emission).
TEST(PhotonContact, PointLightOnTheBoxsSurfaces) {
  io::LoadedMesh mesh = io::loadMesh(std::string(GI_TEST_MESHES) + "/cornell_box.ply");
  Scene s = mesh.scene;
  ParamValues v = defaultValues(filterSpecs(FilterKind::PhotonMapping), 1.0);
  ASSERT_FALSE(applySceneConventions(s, mesh.attrs, v, true).has_value());
  auto caster = makeEmbreeCaster(s);
  for (const glm::dvec3 world : {glm::dvec3(0, 0, 0), glm::dvec3(0, 274, 280)}) {
    PointLight L;
    L.position = glm::vec3(world - s.origin);
    L.intensity = glm::vec3(1e6f);
    PathTraceOptions po;
    po.samplesPerVertex = 256;
    po.point = L;
    const PathTraceResult ref = pathTrace(s, *caster, po);
    PhotonOptions o;
    o.point = L;
    const VertexRadiometry r = computePhotonMap(s, *caster, o);
    double mean = 0, refMean = 0, refMax = 0, most = 0;
    for (size_t i = 0; i < s.vertexCount(); ++i) {
      mean += luminance(r.B[i]) / double(s.vertexCount());
      refMean += luminance(ref.B[i]) / double(s.vertexCount());
      refMax = std::max(refMax, double(luminance(ref.B[i])));
      most = std::max(most, double(luminance(r.B[i])));
    }
    std::printf("point light at (%g, %g, %g): mean B %.4f (reference %.4f), largest %.2f (reference %.2f)\n", world.x,
                world.y, world.z, mean, refMean, most, refMax);
    EXPECT_NEAR(mean, refMean, 0.03 * refMean);
    EXPECT_LT(most, 2.0 * refMax);
  }
}
