// gi/scene.h: analyzeScene (every kind of defect, the ray offset at any
// scale and offset), fromAbsolute, append and vertex normals. All inputs
// are exact and small: every check is deterministic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "gi/scene.h"

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// ---------------------------------------------------------------- scene ----

// One face of every kind (see SceneReport):
//   f0 usable, emitter E = (2, 1, 0.5), area 0.5   f1 on a NaN vertex
//   f2 on an Inf vertex                             f3 repeated index (invalid)
//   f4 index out of range (invalid)                 f5 collinear (degenerate), emitter
//   f6 usable, zero emission                        f7 collinear on far vertices (degenerate)
//   f8 sliver of height 1e-13 (degenerate)          f9 NaN vertex and bad index (invalid first)
//   f10 edges of 1e-12 (degenerate: its normal underflows in float; Monte
//       Carlo form factors cast a ray without a direction from it)
gi::Scene defectScene() {
  gi::Scene s;
  s.positions = {
      {0, 0, 0}, {1, 0, 0}, {0, 1, 0},  // 0-2
      {kNaN, 0, 0},                     // 3
      {kInf, 0, 0},                     // 4
      {2, 0, 0},                        // 5: only in the collinear f5 -> isolated
      {0, 0, 1},                        // 6
      {2, 2, 2}, {3, 3, 3}, {4, 4, 4},  // 7-9: only in the collinear f7 -> isolated
      {0.5f, 1e-13f, 0},                // 10: only in the sliver -> isolated
      {-1, -1, -1},                     // 11: in no face -> isolated
      {0, -kInf, 0},                    // 12: in no face, not finite
      {0, 0, 0}, {1e-12f, 0, 0}, {0, 1e-12f, 1e-13f},  // 13-15: only in the tiny f10 -> isolated
  };
  s.triangles = {{0, 1, 2}, {0, 1, 3}, {0, 4, 2}, {0, 0, 1}, {0, 1, 99},
                 {0, 1, 5}, {0, 1, 6}, {7, 8, 9}, {0, 1, 10}, {3, 3, 1000}, {13, 14, 15}};
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  s.emission[0] = {2.f, 1.f, 0.5f};
  s.emission[5] = {5.f, 5.f, 5.f};  // on a degenerate face: does not count
  s.emission[1] = {7.f, 7.f, 7.f};  // on a NaN face: does not count
  return s;
}

TEST(AnalyzeScene, CountsEveryDefect) {
  const gi::Scene s = defectScene();
  const gi::SceneReport r = gi::analyzeScene(s);
  EXPECT_EQ(r.vertices, 16u);
  EXPECT_EQ(r.faces, 11u);
  EXPECT_EQ(r.nonFiniteVertices, 3u);   // 3, 4, 12
  EXPECT_EQ(r.facesOnNonFinite, 2u);    // f1, f2
  EXPECT_EQ(r.invalidFaces, 3u);        // f3 (repeated), f4 (range), f9 (both)
  EXPECT_EQ(r.degenerateFaces, 4u);     // f5, f7, f8, f10
  EXPECT_EQ(r.usableFaces(), 2u);       // f0, f6
  EXPECT_EQ(r.isolatedVertices, 9u);    // 5, 7, 8, 9, 10, 11, 13-15 (finite, in no usable face)
  EXPECT_EQ(r.emitterFaces, 1u);
  // luminance(2, 1, 0.5) * 0.5 = (0.4252 + 0.7152 + 0.0361) * 0.5; tolerance 1e-6.
  EXPECT_NEAR(r.emittedPower, (0.2126 * 2 + 0.7152 + 0.0722 * 0.5) * 0.5, 1e-6);
  // bbox over the finite vertices: (-1,-1,-1) .. (4,4,4); tolerance 1e-12.
  EXPECT_NEAR(r.bboxMin.x, -1.0, 1e-12);
  EXPECT_NEAR(r.bboxMax.z, 4.0, 1e-12);
  // The scale (diagonal, ray offsets) over the finite vertices some face
  // uses: (0,0,0) .. (4,4,4), vertex 11 in no face left out.
  EXPECT_NEAR(r.diagonal, std::sqrt(48.0), 1e-9);
  EXPECT_GT(r.rayEpsilon, 0.0);
  // The mask used by the casters agrees with the counts.
  const auto ok = gi::usableFaceMask(s);
  EXPECT_EQ(ok, (std::vector<uint8_t>{1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0}));
  EXPECT_NE(r.summary().find("2 usable"), std::string::npos) << r.summary();
}

TEST(AnalyzeScene, EmptyAndAllBad) {
  const gi::SceneReport e = gi::analyzeScene(gi::Scene{});
  EXPECT_EQ(e.faces, 0u);
  EXPECT_EQ(e.usableFaces(), 0u);
  EXPECT_EQ(e.diagonal, 0.0);
  EXPECT_GT(e.rayEpsilon, 0.0);  // never zero (it offsets ray origins)
  gi::Scene n;
  n.positions = {{kNaN, kNaN, kNaN}, {kNaN, 0, 0}, {0, 0, kInf}};
  n.triangles = {{0, 1, 2}};
  const gi::SceneReport r = gi::analyzeScene(n);
  EXPECT_EQ(r.nonFiniteVertices, 3u);
  EXPECT_EQ(r.facesOnNonFinite, 1u);
  EXPECT_EQ(r.isolatedVertices, 0u);
  EXPECT_TRUE(std::isfinite(r.rayEpsilon) && r.rayEpsilon > 0.0);
  EXPECT_TRUE(std::isfinite(r.diagonal));
}

// The unit cube [0,1]^3 as 12 triangles, counter-clockwise seen from outside.
std::vector<glm::dvec3> cubePoints(double scale, glm::dvec3 offset) {
  std::vector<glm::dvec3> p;
  for (int i = 0; i < 8; ++i) p.push_back(offset + scale * glm::dvec3(i & 1, (i >> 1) & 1, (i >> 2) & 1));
  return p;
}
std::vector<glm::uvec3> cubeFaces() {
  // Quads (a, b, c, d) counter-clockwise from outside, split along a-c.
  const unsigned q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<glm::uvec3> t;
  for (const auto& f : q) {
    t.push_back({f[0], f[1], f[2]});
    t.push_back({f[0], f[2], f[3]});
  }
  return t;
}

TEST(AnalyzeScene, RayEpsilonGrowsWithScaleAndOffset) {
  const double e1 = gi::analyzeScene(gi::Scene::fromAbsolute(cubePoints(1, {}), cubeFaces())).rayEpsilon;
  const double e1000 = gi::analyzeScene(gi::Scene::fromAbsolute(cubePoints(1000, {}), cubeFaces())).rayEpsilon;
  // Scale: proportional (within 1%) to the size.
  EXPECT_NEAR(e1000 / e1, 1000.0, 10.0);
  // Offset kept in local float coordinates (no re-centring): the epsilon must
  // exceed the float spacing at 1e6 (2^-4 = 0.0625) by a margin (x 8).
  gi::Scene raw;
  for (const auto& p : cubePoints(1, glm::dvec3(1e6))) raw.positions.push_back(glm::vec3(p));
  raw.triangles = cubeFaces();
  const double eRaw = gi::analyzeScene(raw).rayEpsilon;
  EXPECT_GT(eRaw, 8 * 0.0625);
  EXPECT_GT(eRaw, 100 * e1);
  // fromAbsolute re-centres: local coordinates stay within the cube's half
  // size (+1e-6), the epsilon matches the unit cube's (within 1%), and the
  // absolute bbox and positions are exact to 1e-6.
  const gi::Scene far = gi::Scene::fromAbsolute(cubePoints(1, glm::dvec3(1e6, -2e6, 3e6)), cubeFaces());
  for (const auto& p : far.positions)
    EXPECT_LE(std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}), 0.5f + 1e-6f);
  const gi::SceneReport rf = gi::analyzeScene(far);
  EXPECT_NEAR(rf.rayEpsilon / e1, 1.0, 0.01);
  EXPECT_NEAR(rf.bboxMin.x, 1e6, 1e-6);
  EXPECT_NEAR(rf.bboxMin.y, -2e6, 1e-6);
  EXPECT_NEAR(rf.bboxMax.z, 3e6 + 1, 1e-6);
  EXPECT_NEAR(rf.diagonal, std::sqrt(3.0), 1e-9);
  const auto w = far.toWorld(far.positions[7]);
  EXPECT_NEAR(w.x, 1e6 + 1, 1e-6);
  EXPECT_NEAR(w.y, -2e6 + 1, 1e-6);
  EXPECT_NEAR(w.z, 3e6 + 1, 1e-6);
  EXPECT_EQ(rf.usableFaces(), 12u);
  // A NaN point does not move the origin.
  auto pts = cubePoints(1, glm::dvec3(1e6));
  pts.push_back(glm::dvec3(std::nan("")));
  const gi::Scene withNaN = gi::Scene::fromAbsolute(pts, cubeFaces());
  EXPECT_NEAR(withNaN.origin.x, 1e6 + 0.5, 1e-9);
}

TEST(Scene, AppendKeepsPerFaceArraysAligned) {
  gi::Scene a = gi::Scene::fromAbsolute({{10, 0, 0}, {11, 0, 0}, {10, 1, 0}, {11, 1, 0}}, {{0, 1, 2}, {1, 3, 2}});
  gi::Scene b = gi::Scene::fromAbsolute({{0, 5, 0}, {1, 5, 0}, {0, 6, 0}, {0, 5, 1}}, {{0, 1, 2}, {0, 2, 3}, {0, 3, 1}});
  b.rho = {{0.1f, 0.2f, 0.3f}, {0.4f, 0.5f, 0.6f}, {0.7f, 0.8f, 0.9f}};
  b.emission = {{0, 0, 0}, {3, 3, 3}, {0, 0, 0}};
  b.material = {gi::Material::Mirror, gi::Material::Glass, gi::Material::Diffuse};
  b.vertexNormals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {1, 0, 0}};
  const auto worldB = b.toWorld(b.positions[3]);
  EXPECT_EQ(a.append(b), 4u);
  ASSERT_EQ(a.faceCount(), 5u);
  ASSERT_EQ(a.rho.size(), 5u);
  ASSERT_EQ(a.emission.size(), 5u);
  ASSERT_EQ(a.material.size(), 5u);
  EXPECT_TRUE(a.ior.empty());  // neither part had one
  ASSERT_EQ(a.vertexNormals.size(), a.vertexCount());
  EXPECT_EQ(a.rho[0], glm::vec3(0.5f));
  EXPECT_EQ(a.emission[1], glm::vec3(0.f));
  EXPECT_EQ(a.material[1], gi::Material::Diffuse);
  EXPECT_EQ(a.rho[3], glm::vec3(0.4f, 0.5f, 0.6f));
  EXPECT_EQ(a.emission[3], glm::vec3(3.f));
  EXPECT_EQ(a.material[2], gi::Material::Mirror);
  EXPECT_EQ(a.vertexNormals[0], glm::vec3(0.f));
  EXPECT_EQ(a.vertexNormals[7], glm::vec3(1, 0, 0));
  EXPECT_EQ(a.triangles[4], glm::uvec3(4, 7, 5));
  // World positions are kept (origins differ); tolerance 1e-5.
  const auto w = a.toWorld(a.positions[7]);
  EXPECT_LT(glm::length(w - worldB), 1e-5);
  EXPECT_TRUE(a.hasEmitters());
  // A third part with only ior: ior becomes explicit for all 6 faces, the
  // others get the part's defaults.
  gi::Scene c = gi::Scene::fromAbsolute({{0, 0, 9}, {1, 0, 9}, {0, 1, 9}}, {{0, 1, 2}});
  c.ior = {1.33f};
  EXPECT_EQ(a.append(c), 8u);
  ASSERT_EQ(a.faceCount(), 6u);
  for (size_t n : {a.rho.size(), a.emission.size(), a.material.size(), a.ior.size()}) EXPECT_EQ(n, 6u);
  ASSERT_EQ(a.vertexNormals.size(), a.vertexCount());
  EXPECT_EQ(a.ior[0], 1.5f);
  EXPECT_EQ(a.ior[5], 1.33f);
  EXPECT_EQ(a.rho[5], glm::vec3(0.5f));
  EXPECT_EQ(a.material[5], gi::Material::Diffuse);
  // Appending plain scenes keeps optional arrays empty.
  gi::Scene p = gi::Scene::fromAbsolute({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
  p.append(gi::Scene::fromAbsolute({{0, 0, 1}, {1, 0, 1}, {0, 1, 1}}, {{0, 1, 2}}));
  EXPECT_TRUE(p.rho.empty() && p.emission.empty() && p.material.empty() && p.ior.empty() && p.vertexNormals.empty());
  EXPECT_EQ(p.triangles[1], glm::uvec3(3, 4, 5));
}

// Duplicated faces are the same three corner positions in the same turn,
// whether the copy reuses the vertices or has its own (a triangle soup);
// sharing two corners, or a corner that differs in the last bit, is not a
// duplicate. A copy in the other turn makes a two-sided pair, counted apart
// (the ray casters meet such a surface on the side facing the ray).
TEST(Scene, DuplicateFacesByPositionNotIndex) {
  const float nudged = std::nextafter(1.f, 2.f);
  const gi::Scene s = gi::Scene::fromAbsolute(
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},        // 0-3: two triangles of a square
       {0, 1, 0}, {0, 0, 0}, {1, 0, 0},                   // 4-6: own copies of 2, 0, 1
       {0, 0, 0}, {1, 0, 0}, {0, double(nudged), 0},      // 7-9: 0, 1 and a corner one ulp off 2
       {-0.0, 0, 0}, {1, 0, 0}, {0, 1, 0}},               // 10-12: a third copy, its own vertices
      {{0, 1, 2}, {1, 3, 2},
       {2, 1, 0},     // same vertices, reversed: a two-sided pair with face 0
       {4, 5, 6},     // own vertices, rotated: duplicate
       {7, 8, 9},     // one corner differs: not
       {0, 1, 3},     // shares two corners: not
       {10, 11, 12},  // duplicate
       {1, 2, 3}}     // face 1 reversed (its vertices rotated): a two-sided pair
  );
  const gi::SceneReport r = gi::analyzeScene(s);
  EXPECT_EQ(r.duplicateFaces, 2u);
  EXPECT_EQ(r.twoSidedPairs, 2u);
  EXPECT_NE(r.summary().find("2 two-sided pairs"), std::string::npos) << r.summary();
  EXPECT_EQ(r.usableFaces(), 8u);
  EXPECT_NEAR(gi::sceneDiagonal(s), r.diagonal, 1e-12);
}

// Edges along which two faces run the same way: one of them is turned over.
// A closed cube of 12 triangles has none; one triangle turned over gives its
// three edges; the cube as a soup (every face its own vertices) is judged
// by positions, the same; the duplicates found are listed as (copy,
// original) pairs, the original the first face of its corners.
TEST(Scene, MisorientedEdgesAndDuplicatePairs) {
  gi::Scene s = gi::Scene::fromAbsolute(cubePoints(2, glm::dvec3(0.0)), cubeFaces());
  EXPECT_EQ(gi::analyzeScene(s).misorientedEdges, 0u);
  std::swap(s.triangles[5].y, s.triangles[5].z);
  EXPECT_EQ(gi::analyzeScene(s).misorientedEdges, 3u);
  EXPECT_NE(gi::analyzeScene(s).summary().find("3 edges between faces turned opposite ways"), std::string::npos);
  std::vector<glm::dvec3> soup;
  std::vector<glm::uvec3> tris;
  for (const glm::uvec3& t : s.triangles) {
    for (int k = 0; k < 3; ++k) soup.push_back(s.toWorld(s.positions[t[k]]));
    tris.push_back({uint32_t(soup.size() - 3), uint32_t(soup.size() - 2), uint32_t(soup.size() - 1)});
  }
  gi::Scene loose = gi::Scene::fromAbsolute(soup, tris);
  EXPECT_EQ(gi::analyzeScene(loose).misorientedEdges, 3u);
  loose.triangles.push_back(loose.triangles[7]);
  loose.triangles.push_back(loose.triangles[2]);
  loose.triangles.push_back(loose.triangles[7]);
  auto pairs = gi::duplicatedFaces(loose);
  std::sort(pairs.begin(), pairs.end());
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0], (std::pair<uint32_t, uint32_t>{12, 7}));
  EXPECT_EQ(pairs[1], (std::pair<uint32_t, uint32_t>{13, 2}));
  EXPECT_EQ(pairs[2], (std::pair<uint32_t, uint32_t>{14, 7}));
  loose.leftOut.assign(loose.faceCount(), 0);
  for (const auto& [copy, original] : pairs) loose.leftOut[copy] = 1;
  const gi::SceneReport r = gi::analyzeScene(loose);
  EXPECT_EQ(r.leftOutFaces, 3u);
  EXPECT_EQ(r.duplicateFaces, 0u);
  EXPECT_EQ(r.degenerateFaces, 0u);
  EXPECT_EQ(r.usableFaces(), 12u);
  EXPECT_EQ(gi::usableFaceMask(loose)[13], 0);
}

TEST(Scene, VertexNormalsOfClosedCubePointOutwards) {
  // Near and far (1e6 offset) cubes; one extra isolated vertex gets zero.
  for (double off : {0.0, 1e6}) {
    gi::Scene s = gi::Scene::fromAbsolute(cubePoints(2, glm::dvec3(off)), cubeFaces());
    s.positions.push_back({9, 9, 9});
    const glm::dvec3 centre = glm::dvec3(off + 1.0);
    for (size_t f = 0; f < s.faceCount(); ++f) {  // fixture check: faces face outwards
      const auto& t = s.triangles[f];
      const glm::dvec3 c = (s.toWorld(s.positions[t.x]) + s.toWorld(s.positions[t.y]) + s.toWorld(s.positions[t.z])) / 3.0;
      ASSERT_GT(glm::dot(glm::dvec3(gi::faceNormalUnnormalized(s, f)), c - centre), 0.0) << f;
      EXPECT_NEAR(gi::faceArea(s, f), 2.0, 1e-9);
    }
    const auto n = gi::computeVertexNormals(s);
    ASSERT_EQ(n.size(), 9u);
    for (size_t i = 0; i < 8; ++i) {
      // Angle weighting makes every corner normal exactly the diagonal; 1e-5.
      const glm::dvec3 want = glm::normalize(s.toWorld(s.positions[i]) - centre);
      EXPECT_NEAR(glm::length(n[i]), 1.f, 1e-5f);
      EXPECT_GT(glm::dot(glm::dvec3(n[i]), want), 1.0 - 1e-5) << "vertex " << i << " offset " << off;
    }
    EXPECT_EQ(n[8], glm::vec3(0.f));
  }
}

}  // namespace

// A caller's vertex normals reach the ray estimators at unit length (scaled
// in double; unit ones keep their bits), as the faces' normal where they are
// zero or not finite (an exporter's 0 0 0 read 0 with an error of 0), or as
// zero where the vertex is on no usable face (it is then invalid); without
// them, the computed ones.
TEST(Scene, VertexNormalsForRaysAreUnitOrZero) {
  gi::Scene s;
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}, {1, 2, 0}, {5, 5, 5}};
  s.triangles = {{0, 1, 2}, {3, 4, 5}};
  EXPECT_EQ(gi::vertexNormalsForRays(s), gi::computeVertexNormals(s));
  const glm::vec3 unit = glm::normalize(glm::vec3(0.3f, -0.2f, 0.9f));
  s.vertexNormals = {{0, 0, 2}, {3, 4, 0}, unit, {kInf, 0, 0}, {kNaN, 0, 1}, {0, 0, 0}, {0, 0, 1}};
  const std::vector<glm::vec3> n = gi::vertexNormalsForRays(s);
  ASSERT_EQ(n.size(), 7u);
  EXPECT_EQ(n[0], glm::vec3(0, 0, 1));
  EXPECT_NEAR(n[1].x, 0.6f, 1e-7f);
  EXPECT_NEAR(n[1].y, 0.8f, 1e-7f);
  EXPECT_EQ(n[1].z, 0.f);
  EXPECT_EQ(n[2], unit);  // the same bits
  s.vertexNormals.clear();
  const std::vector<glm::vec3> faces = gi::computeVertexNormals(s);
  EXPECT_EQ(n[3], faces[3]);  // inf, NaN and 0: the faces' normal
  EXPECT_EQ(n[4], faces[4]);
  EXPECT_EQ(n[5], faces[5]);
  EXPECT_NEAR(glm::length(n[5]), 1.f, 1e-6f);
  EXPECT_EQ(n[6], glm::vec3(0.f));  // isolated
}
