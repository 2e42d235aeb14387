// gi/scene.h (analyzeScene, fromAbsolute, append, vertex normals),
// gi/params.h (defaults, validation, CLI parsing), gi/color.h (sRGB, display
// mapping, auto exposure) and gi/filters.h (complete .mlx scripts).
// All inputs are exact and small: every check is deterministic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "gi/ambient.h"
#include "gi/color.h"
#include "gi/pathtrace.h"
#include "gi/filters.h"
#include "gi/params.h"
#include "gi/run.h"
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
  };
  s.triangles = {{0, 1, 2}, {0, 1, 3}, {0, 4, 2}, {0, 0, 1}, {0, 1, 99},
                 {0, 1, 5}, {0, 1, 6}, {7, 8, 9}, {0, 1, 10}, {3, 3, 1000}};
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  s.emission[0] = {2.f, 1.f, 0.5f};
  s.emission[5] = {5.f, 5.f, 5.f};  // on a degenerate face: does not count
  s.emission[1] = {7.f, 7.f, 7.f};  // on a NaN face: does not count
  return s;
}

TEST(AnalyzeScene, CountsEveryDefect) {
  const gi::Scene s = defectScene();
  const gi::SceneReport r = gi::analyzeScene(s);
  EXPECT_EQ(r.vertices, 13u);
  EXPECT_EQ(r.faces, 10u);
  EXPECT_EQ(r.nonFiniteVertices, 3u);   // 3, 4, 12
  EXPECT_EQ(r.facesOnNonFinite, 2u);    // f1, f2
  EXPECT_EQ(r.invalidFaces, 3u);        // f3 (repeated), f4 (range), f9 (both)
  EXPECT_EQ(r.degenerateFaces, 3u);     // f5, f7, f8
  EXPECT_EQ(r.usableFaces(), 2u);       // f0, f6
  EXPECT_EQ(r.isolatedVertices, 6u);    // 5, 7, 8, 9, 10, 11 (finite, in no usable face)
  EXPECT_EQ(r.emitterFaces, 1u);
  // luminance(2, 1, 0.5) * 0.5 = (0.4252 + 0.7152 + 0.0361) * 0.5; tolerance 1e-6.
  EXPECT_NEAR(r.emittedPower, (0.2126 * 2 + 0.7152 + 0.0722 * 0.5) * 0.5, 1e-6);
  // bbox over the finite vertices: (-1,-1,-1) .. (4,4,4); tolerance 1e-12.
  EXPECT_NEAR(r.bboxMin.x, -1.0, 1e-12);
  EXPECT_NEAR(r.bboxMax.z, 4.0, 1e-12);
  EXPECT_NEAR(r.diagonal, std::sqrt(75.0), 1e-9);
  EXPECT_GT(r.rayEpsilon, 0.0);
  // The mask used by the casters agrees with the counts.
  const auto ok = gi::usableFaceMask(s);
  EXPECT_EQ(ok, (std::vector<uint8_t>{1, 0, 0, 0, 0, 0, 1, 0, 0, 0}));
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

// Duplicated faces are the same three corner positions in any order, whether
// the copy reuses the vertices or has its own (a triangle soup); sharing two
// corners, or a corner that differs in the last bit, is not a duplicate.
TEST(Scene, DuplicateFacesByPositionNotIndex) {
  const float nudged = std::nextafter(1.f, 2.f);
  const gi::Scene s = gi::Scene::fromAbsolute(
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},        // 0-3: two triangles of a square
       {0, 1, 0}, {0, 0, 0}, {1, 0, 0},                   // 4-6: own copies of 2, 0, 1
       {0, 0, 0}, {1, 0, 0}, {0, double(nudged), 0},      // 7-9: 0, 1 and a corner one ulp off 2
       {-0.0, 0, 0}, {1, 0, 0}, {0, 1, 0}},               // 10-12: a third copy, its own vertices
      {{0, 1, 2}, {1, 3, 2},
       {2, 1, 0},     // same vertices, other order: duplicate
       {4, 5, 6},     // own vertices, rotated: duplicate
       {7, 8, 9},     // one corner differs: not
       {0, 1, 3},     // shares two corners: not
       {10, 11, 12}}  // duplicate
  );
  const gi::SceneReport r = gi::analyzeScene(s);
  EXPECT_EQ(r.duplicateFaces, 3u);
  EXPECT_EQ(r.usableFaces(), 7u);
  EXPECT_NEAR(gi::sceneDiagonal(s), r.diagonal, 1e-12);
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

// --------------------------------------------------------------- params ----

std::vector<gi::ParamSpec> testSpecs() {
  return {
      {"flag", "Flag", "A switch.", gi::ParamType::Bool, 1},
      {"count", "Count", "An integer.", gi::ParamType::Int, 8, 1, 100},
      {"ratio", "Ratio", "A float.", gi::ParamType::Float, 0.5, 0.0, 1.0},
      {"radius", "Radius", "A distance.", gi::ParamType::Distance, 0.1, 0.0, 2.0},
      {"mode", "Mode", "An enum.", gi::ParamType::Enum, 1, 0, 0, {"Alpha", "Beta", "Gamma"}},
      {"tint", "Tint", "A colour.", gi::ParamType::Color, 0, 0, 0, {}, glm::vec3(1.f, 0.5f, 0.f)},
      {"dir", "Direction", "A direction.", gi::ParamType::Direction, 0, 0, 0, {}, glm::vec3(0.f, 1.f, 0.f)},
  };
}
constexpr double kDiag = 10.0;

TEST(Params, DefaultValues) {
  const auto specs = testSpecs();
  const gi::ParamValues v = gi::defaultValues(specs, kDiag);
  EXPECT_EQ(v.all().size(), specs.size());
  EXPECT_TRUE(v.getBool("flag"));
  EXPECT_EQ(v.getInt("count"), 8);
  EXPECT_DOUBLE_EQ(v.getFloat("ratio"), 0.5);
  EXPECT_DOUBLE_EQ(v.getFloat("radius"), 1.0);  // 0.1 x diagonal 10
  EXPECT_EQ(v.getInt("mode"), 1);
  EXPECT_EQ(v.getVec("tint"), glm::vec3(1.f, 0.5f, 0.f));
  EXPECT_EQ(v.getVec("dir"), glm::vec3(0.f, 1.f, 0.f));
  EXPECT_FALSE(gi::validate(specs, v, kDiag).has_value());
  EXPECT_EQ(gi::describe(specs, v), "flag=true, count=8, ratio=0.5, radius=1, mode=Beta, tint=1,0.5,0, dir=0,1,0");
  EXPECT_THROW(v.getInt("nope"), std::invalid_argument);
  EXPECT_THROW(v.getFloat("count"), std::bad_variant_access);
  EXPECT_EQ(gi::findSpec(specs, "mode"), &specs[4]);
  EXPECT_EQ(gi::findSpec(specs, "nope"), nullptr);
}

// validate() with one parameter changed: an error naming it, or none.
std::optional<std::string> validateWith(const std::string& name, gi::ParamValue x) {
  const auto specs = testSpecs();
  gi::ParamValues v = gi::defaultValues(specs, kDiag);
  v.set(name, x);
  return gi::validate(specs, v, kDiag);
}
void expectRejected(const std::string& name, gi::ParamValue x, const char* why) {
  const auto err = validateWith(name, x);
  ASSERT_TRUE(err.has_value()) << name << ": " << why;
  EXPECT_NE(err->find("'" + name + "'"), std::string::npos) << *err;
}

// Directions of any magnitude keep their direction: 1e20 (whose square
// overflows a float: glm::normalize gave 0, a sun below every horizon) and
// 1e-30 (whose square underflows: it was rejected as zero); zero, NaN and
// infinite ones are rejected with the parameter's name, by validate() and by
// getDirection().
TEST(Params, DirectionsOfAnyMagnitude) {
  const auto specs = testSpecs();
  for (const float m : {1e20f, 3e38f, 1e-30f, 1e-45f, 1.f}) {
    for (const glm::vec3 d : {glm::vec3(m, 0.f, 0.f), glm::vec3(-m, m, 0.f), glm::vec3(0.f, 0.f, -m)}) {
      EXPECT_FALSE(validateWith("dir", d)) << m;
      gi::ParamValues v = gi::defaultValues(specs, kDiag);
      v.set("dir", d);
      const glm::vec3 u = v.getDirection("dir");
      const glm::vec3 expect = glm::normalize(glm::vec3(d.x != 0.f ? (d.x > 0 ? 1.f : -1.f) : 0.f,
                                                        d.y != 0.f ? (d.y > 0 ? 1.f : -1.f) : 0.f,
                                                        d.z != 0.f ? (d.z > 0 ? 1.f : -1.f) : 0.f));
      EXPECT_NEAR(glm::length(u - expect), 0.f, 1e-6f) << m;
    }
  }
  // The CLI's path: parse "1e20,0,0", validate, read as a unit vector.
  const gi::ParamValue parsed = gi::parseValue(specs[6], "1e20,0,0", kDiag);
  gi::ParamValues v = gi::defaultValues(specs, kDiag);
  v.set("dir", parsed);
  EXPECT_FALSE(gi::validate(specs, v, kDiag));
  EXPECT_EQ(v.getDirection("dir"), glm::vec3(1.f, 0.f, 0.f));
  // "1e39" is infinite as a float: rejected, not normalised to garbage.
  v.set("dir", gi::parseValue(specs[6], "1e39,0,0", kDiag));
  ASSERT_TRUE(gi::validate(specs, v, kDiag).has_value());
  EXPECT_THROW(v.getDirection("dir"), std::invalid_argument);
  for (const glm::vec3 bad : {glm::vec3(0.f), glm::vec3(-0.f, 0.f, -0.f), glm::vec3(kNaN, 1.f, 0.f),
                              glm::vec3(kInf, 0.f, 0.f), glm::vec3(1.f, -kInf, 0.f)}) {
    expectRejected("dir", bad, "zero or non-finite direction");
    v.set("dir", bad);
    EXPECT_THROW(v.getDirection("dir"), std::invalid_argument);
  }
}

// The filters read their direction parameters through getDirection: a sun
// given as 1e20,0,0 is the sun along +x, not a zero vector.
TEST(Params, DirectionParametersReachTheAlgorithmsAsUnitVectors) {
  const glm::vec3 huge(1e20f, 0.f, 0.f), tiny(0.f, -1e-30f, 0.f);
  {
    const auto specs = gi::filterSpecs(gi::FilterKind::SkyLighting);
    gi::ParamValues v = gi::defaultValues(specs, 1.0);
    v.set("sun_direction", huge);
    ASSERT_FALSE(gi::validate(specs, v, 1.0));
    EXPECT_EQ(gi::AmbientOptions::fromParams(gi::AmbientMode::Sky, v).sunDirection, glm::vec3(1.f, 0.f, 0.f));
  }
  {
    const auto specs = gi::filterSpecs(gi::FilterKind::PathTracedReference);
    gi::ParamValues v = gi::defaultValues(specs, 1.0);
    v.set("sun_direction", huge);
    v.set("spot_direction", tiny);
    ASSERT_FALSE(gi::validate(specs, v, 1.0));
    const gi::PathTraceOptions o = gi::PathTraceOptions::fromParams(v, glm::dvec3(0.0));
    EXPECT_EQ(o.sunDirection, glm::vec3(1.f, 0.f, 0.f));
    EXPECT_EQ(o.point.spotDirection, glm::vec3(0.f, -1.f, 0.f));
  }
}

TEST(Params, ValidateEveryErrorPath) {
  expectRejected("count", 0, "int below min");
  expectRejected("count", 101, "int above max");
  expectRejected("ratio", -0.01, "float below min");
  expectRejected("ratio", 1.01, "float above max");
  expectRejected("ratio", std::nan(""), "NaN float");
  expectRejected("ratio", HUGE_VAL, "infinite float");
  expectRejected("radius", -0.5, "negative distance");
  expectRejected("radius", std::nan(""), "NaN distance");
  expectRejected("radius", 2.0 * kDiag * 1.001, "distance > max x diagonal");
  expectRejected("mode", 3, "enum past the choices");
  expectRejected("mode", -1, "negative enum");
  expectRejected("tint", glm::vec3(1.01f, 0.f, 0.f), "colour channel > 1");
  expectRejected("tint", glm::vec3(0.f, -0.01f, 0.f), "colour channel < 0");
  expectRejected("tint", glm::vec3(0.f, 0.f, kNaN), "NaN colour channel");
  expectRejected("dir", glm::vec3(0.f), "zero direction");
  expectRejected("dir", glm::vec3(kNaN, 1.f, 0.f), "NaN direction");
  expectRejected("count", 2.5, "wrong type");
  expectRejected("flag", 1, "wrong type");
  // Missing parameter.
  const auto specs = testSpecs();
  gi::ParamValues partial;
  partial.set("flag", true);
  auto err = gi::validate(specs, partial, kDiag);
  ASSERT_TRUE(err.has_value());
  EXPECT_NE(err->find("'count'"), std::string::npos) << *err;
  // Boundary values pass.
  EXPECT_FALSE(validateWith("count", 1));
  EXPECT_FALSE(validateWith("count", 100));
  EXPECT_FALSE(validateWith("ratio", 0.0));
  EXPECT_FALSE(validateWith("ratio", 1.0));
  EXPECT_FALSE(validateWith("radius", 0.0));
  EXPECT_FALSE(validateWith("radius", 2.0 * kDiag));
  EXPECT_FALSE(validateWith("mode", 2));
  EXPECT_FALSE(validateWith("tint", glm::vec3(0.f, 1.f, 1.f)));
  EXPECT_FALSE(validateWith("dir", glm::vec3(0.f, 0.f, -1e-3f)));
}

gi::ParamValue parse(const std::string& name, const std::string& text) {
  const auto specs = testSpecs();
  return gi::parseValue(*gi::findSpec(specs, name), text, 50.0);
}
void expectParseError(const std::string& name, const std::string& text) {
  try {
    (void)parse(name, text);
    ADD_FAILURE() << name << " accepted '" << text << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << "message does not name " << name << ": " << e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << name << " '" << text << "' threw a non-invalid_argument: " << e.what();
  }
}

TEST(Params, ParseValueEveryType) {
  for (const char* t : {"1", "true", "on", "yes"}) EXPECT_EQ(std::get<bool>(parse("flag", t)), true) << t;
  for (const char* t : {"0", "false", "off", "no"}) EXPECT_EQ(std::get<bool>(parse("flag", t)), false) << t;
  for (const char* t : {"maybe", "", "2", "True "}) expectParseError("flag", t);

  EXPECT_EQ(std::get<int>(parse("count", "42")), 42);
  EXPECT_EQ(std::get<int>(parse("count", "-7")), -7);  // parsed; validate rejects the range
  for (const char* t : {"4.2", "abc", "", "12x", "99999999999999999999999"}) expectParseError("count", t);

  EXPECT_DOUBLE_EQ(std::get<double>(parse("ratio", "0.25")), 0.25);
  EXPECT_DOUBLE_EQ(std::get<double>(parse("ratio", "1e-3")), 1e-3);
  for (const char* t : {"0.5x", "x", "", "1e999"}) expectParseError("ratio", t);

  // Distances: absolute, or % of the diagonal (50): 10% = 5. Tolerance 1e-12.
  EXPECT_NEAR(std::get<double>(parse("radius", "10%")), 5.0, 1e-12);
  EXPECT_NEAR(std::get<double>(parse("radius", "0.5%")), 0.25, 1e-12);
  EXPECT_NEAR(std::get<double>(parse("radius", "2.5")), 2.5, 1e-12);
  for (const char* t : {"10%%", "%", "10 %x", "abc", ""}) expectParseError("radius", t);

  EXPECT_EQ(std::get<int>(parse("mode", "Gamma")), 2);
  EXPECT_EQ(std::get<int>(parse("mode", "Alpha")), 0);
  EXPECT_EQ(std::get<int>(parse("mode", "1")), 1);
  for (const char* t : {"Delta", "gamma", "", "1.5"}) expectParseError("mode", t);
  // An index past the choices is either refused here or by validate.
  {
    bool refused = false;
    try {
      const gi::ParamValue x = parse("mode", "7");
      refused = validateWith("mode", x).has_value();
    } catch (const std::invalid_argument&) {
      refused = true;
    }
    EXPECT_TRUE(refused);
  }
  try {
    (void)parse("mode", "Delta");
  } catch (const std::invalid_argument& e) {  // lists the choices
    EXPECT_NE(std::string(e.what()).find("Alpha, Beta, Gamma"), std::string::npos) << e.what();
  }

  // Colours: #rrggbb and r,g,b (0-255) both give sRGB in [0,1]; exact / 255.
  const glm::vec3 orange(1.f, 128.f / 255.f, 0.f);
  EXPECT_EQ(std::get<glm::vec3>(parse("tint", "#ff8000")), orange);
  EXPECT_EQ(std::get<glm::vec3>(parse("tint", "#FF8000")), orange);
  EXPECT_EQ(std::get<glm::vec3>(parse("tint", "255,128,0")), orange);
  EXPECT_EQ(std::get<glm::vec3>(parse("tint", "255, 128, 0")), orange);
  for (const char* t : {"#ff80", "#ff80zz", "#gg8000", "255,128", "255,128,0,1", "a,b,c", "", "orange", "#12345g"})
    expectParseError("tint", t);

  EXPECT_EQ(std::get<glm::vec3>(parse("dir", "0,-1,0.5")), glm::vec3(0.f, -1.f, 0.5f));
  for (const char* t : {"0,1", "0,1,x", "", "1,2,3,4"}) expectParseError("dir", t);
}

TEST(Params, ParseIntOutsideIntRangeIsRefused) {
  // 2^32 + 1 fits a 64-bit long but not an int: it must not wrap to 1
  // (engine bug found by this test, fixed in params.cpp).
  expectParseError("count", "4294967297");
  expectParseError("count", "2147483648");
  EXPECT_EQ(std::get<int>(parse("count", "2147483647")), 2147483647);
  EXPECT_EQ(std::get<int>(parse("count", "-2147483648")), -2147483647 - 1);
  // Enum indices too: 2^32 + 1 must not wrap to "Beta".
  bool refused = false;
  try {
    refused = validateWith("mode", parse("mode", "4294967297")).has_value();
  } catch (const std::invalid_argument& e) {
    refused = std::string(e.what()).find("mode") != std::string::npos;
  }
  EXPECT_TRUE(refused);
}

// ---------------------------------------------------------------- color ----

TEST(Color, SrgbRoundTripAllBytes) {
  // All 256 byte values decode and re-encode to themselves (lround); linear
  // values increase strictly; srgb8ToLinear is the per-channel decode.
  float prev = -1.f;
  for (int b = 0; b < 256; ++b) {
    const float lin = gi::srgbToLinear(b / 255.f);
    EXPECT_GT(lin, prev) << b;
    prev = lin;
    EXPECT_EQ(std::lround(gi::linearToSrgb(lin) * 255.f), b);
    const glm::vec3 c = gi::srgb8ToLinear(uint8_t(b), 0, 255);
    EXPECT_EQ(c.r, lin);
    EXPECT_EQ(c.g, 0.f);
    EXPECT_FLOAT_EQ(c.b, 1.f);
  }
  // Reference points of IEC 61966-2-1; tolerance 1e-5.
  EXPECT_NEAR(gi::srgbToLinear(0.5f), 0.214041f, 1e-5f);
  EXPECT_NEAR(gi::linearToSrgb(0.18f), 0.461356f, 1e-5f);
  EXPECT_NEAR(gi::linearToSrgb(0.0031308f), 0.04045f, 1e-5f);  // both branches meet
  EXPECT_EQ(gi::linearToSrgb(-1.f), 0.f);
  EXPECT_FLOAT_EQ(gi::linearToSrgb(2.f), 1.f);  // 1.055 - 0.055 in float: within 4 ulps
}

TEST(Color, LuminanceWeights) {
  // Rec. 709: exact weights (float), summing to 1 within 1e-6.
  EXPECT_FLOAT_EQ(gi::luminance({1, 0, 0}), 0.2126f);
  EXPECT_FLOAT_EQ(gi::luminance({0, 1, 0}), 0.7152f);
  EXPECT_FLOAT_EQ(gi::luminance({0, 0, 1}), 0.0722f);
  EXPECT_NEAR(gi::luminance({1, 1, 1}), 1.f, 1e-6f);
  EXPECT_NEAR(gi::luminance({2, 4, 8}), 2 * 0.2126f + 4 * 0.7152f + 8 * 0.0722f, 1e-5f);
}

TEST(Color, DisplayMap) {
  auto eq = [](gi::Rgb8 a, int r, int g, int b) { return a.r == r && a.g == g && a.b == b; };
  EXPECT_TRUE(eq(gi::displayMap({0, 0, 0}, 1.f), 0, 0, 0));
  EXPECT_TRUE(eq(gi::displayMap({1, 1, 1}, 1.f), 255, 255, 255));
  EXPECT_TRUE(eq(gi::displayMap({0.25f, 0.25f, 0.25f}, 2.f), 188, 188, 188));  // exposure 2: 0.5 -> 188
  EXPECT_TRUE(eq(gi::displayMap({1e6f, 0, 0}, 1.f), 255, 0, 0));
  EXPECT_TRUE(eq(gi::displayMap({-1, -0.5f, 0}, 1.f), 0, 0, 0));
  // Over-bright: scaled by the largest channel (hue kept) rather than clipped
  // per channel: (4, 2, 1) -> (1, 0.5, 0.25) -> sRGB (255, 188, 137).
  const gi::Rgb8 c = gi::displayMap({4.f, 2.f, 1.f}, 1.f);
  EXPECT_TRUE(eq(c, 255, 188, 137)) << int(c.r) << "," << int(c.g) << "," << int(c.b);
  // Decoded ratios of the bytes stay 2:1 within the 8-bit quantisation (1%).
  const glm::vec3 lin = gi::srgb8ToLinear(c.r, c.g, c.b);
  EXPECT_NEAR(lin.r / lin.g, 2.f, 0.02f);
  EXPECT_NEAR(lin.g / lin.b, 2.f, 0.02f);
  // NaN: black (per channel).
  EXPECT_TRUE(eq(gi::displayMap({kNaN, kNaN, kNaN}, 1.f), 0, 0, 0));
  const gi::Rgb8 n = gi::displayMap({kNaN, 1.f, 0.f}, 1.f);
  EXPECT_EQ(n.r, 0);
  EXPECT_EQ(n.g, 255);
  EXPECT_TRUE(eq(gi::displayMap({1.f, 1.f, 1.f}, kNaN), 0, 0, 0));
}

TEST(Color, AutoExposureIgnoresNaNAndZero) {
  // 1..100: the 0.99 percentile (rank round(0.99 * 99) = 98) is 99.
  std::vector<float> v;
  for (int i = 1; i <= 100; ++i) v.push_back(float(i));
  const float e = gi::autoExposure(v.data(), v.size());
  EXPECT_FLOAT_EQ(e, 1.f / 99.f);
  std::vector<float> dirty = v;
  for (int k = 0; k < 50; ++k) {
    dirty.insert(dirty.begin() + 2 * k, kNaN);
    dirty.push_back(0.f);
    dirty.push_back(-3.f);
  }
  dirty.push_back(kInf);
  EXPECT_FLOAT_EQ(gi::autoExposure(dirty.data(), dirty.size()), e);
  const float zeros[4] = {0.f, 0.f, kNaN, -1.f};
  EXPECT_EQ(gi::autoExposure(zeros, 4), 1.f);
  EXPECT_EQ(gi::autoExposure(nullptr, 0), 1.f);
  const float one[1] = {4.f};
  EXPECT_FLOAT_EQ(gi::autoExposure(one, 1), 0.25f);
  EXPECT_FLOAT_EQ(gi::autoExposure(v.data(), v.size(), 0.5f), 1.f / 51.f);  // rank round(49.5) = 50
}

// -------------------------------------------------------------- filters ----

// Minimal XML well-formedness check: tags balanced and nested, attributes
// name="value" with no raw '<' or unescaped '&' in values, one root.
bool wellFormed(const std::string& x, std::string* why) {
  std::vector<std::string> stack;
  size_t i = 0;
  int roots = 0;
  const std::regex attr(R"(\s+([A-Za-z_][A-Za-z0-9_]*)=\"([^\"<]*)\")");
  const std::regex entity(R"(&(amp|lt|gt|quot|apos);)");
  while ((i = x.find('<', i)) != std::string::npos) {
    const size_t j = x.find('>', i);
    if (j == std::string::npos) { *why = "unterminated tag"; return false; }
    std::string tag = x.substr(i + 1, j - i - 1);
    i = j + 1;
    if (tag.rfind("!DOCTYPE", 0) == 0) continue;
    if (tag.find('<') != std::string::npos) { *why = "'<' inside a tag"; return false; }
    if (!tag.empty() && tag[0] == '/') {
      if (stack.empty() || stack.back() != tag.substr(1)) { *why = "mismatched </" + tag.substr(1) + ">"; return false; }
      stack.pop_back();
      continue;
    }
    const bool selfClosing = !tag.empty() && tag.back() == '/';
    if (selfClosing) tag.pop_back();
    const size_t sp = tag.find_first_of(" \t\n");
    const std::string name = tag.substr(0, sp);
    if (name.empty() || !std::isalpha(static_cast<unsigned char>(name[0]))) { *why = "bad tag name"; return false; }
    std::string rest = sp == std::string::npos ? "" : tag.substr(sp);
    // Attributes must cover the rest exactly.
    std::string left = std::regex_replace(rest, attr, "");
    if (left.find_first_not_of(" \t\n") != std::string::npos) { *why = "bad attributes in <" + tag + ">"; return false; }
    for (std::sregex_iterator it(rest.begin(), rest.end(), attr), end; it != end; ++it) {
      const std::string v = (*it)[2];
      const std::string noEnt = std::regex_replace(v, entity, "");
      if (noEnt.find('&') != std::string::npos) { *why = "unescaped & in " + v; return false; }
    }
    if (stack.empty()) ++roots;
    if (!selfClosing) stack.push_back(name);
  }
  if (!stack.empty()) { *why = "unclosed <" + stack.back() + ">"; return false; }
  if (roots != 1) { *why = "not one root element"; return false; }
  return true;
}

TEST(Filters, FoundByEitherNameAndListed) {
  const std::string names = gi::cliFilterNames();
  for (const auto& d : gi::allFilters()) {
    ASSERT_EQ(gi::findFilter(d.cliName), &d);
    ASSERT_EQ(gi::findFilter(d.meshlabName), &d);
    EXPECT_NE(names.find(d.cliName), std::string::npos) << d.cliName;
  }
  EXPECT_EQ(gi::findFilter("no such filter"), nullptr);
  EXPECT_EQ(gi::findFilter(""), nullptr);
}

TEST(Filters, XmlCheckerRejectsBrokenXml) {
  std::string why;
  EXPECT_TRUE(wellFormed("<a><b x=\"1\"/></a>", &why)) << why;
  EXPECT_FALSE(wellFormed("<a><b></a>", &why));
  EXPECT_FALSE(wellFormed("<a><b x=\"1\"></a></b>", &why));
  EXPECT_FALSE(wellFormed("<a x=\"&\"/>", &why));
  EXPECT_FALSE(wellFormed("<a x=1/>", &why));
  EXPECT_FALSE(wellFormed("<a/><b/>", &why));
}

TEST(Filters, MlxScriptListsEveryParameterInOrder) {
  const double diag = 7.5;
  std::vector<gi::ScriptStep> steps;
  for (const auto& d : gi::allFilters()) steps.push_back({d.kind, gi::defaultValues(gi::filterSpecs(d.kind), diag)});
  ASSERT_GE(steps.size(), 8u);  // one per filter of allFilters()
  const std::string x = gi::mlxScript(steps, diag);
  std::string why;
  EXPECT_TRUE(wellFormed(x, &why)) << why << "\n" << x;
  EXPECT_EQ(x.rfind("<!DOCTYPE FilterScript>", 0), 0u);
  size_t pos = 0;
  for (const auto& st : steps) {
    const auto& desc = gi::filterDesc(st.kind);
    SCOPED_TRACE(desc.meshlabName);
    const size_t start = x.find("<filter name=\"" + desc.meshlabName + "\">", pos);
    ASSERT_NE(start, std::string::npos);
    const size_t end = x.find("</filter>", start);
    ASSERT_NE(end, std::string::npos);
    const std::string block = x.substr(start, end - start);
    const auto specs = gi::filterSpecs(st.kind);
    ASSERT_FALSE(specs.empty());
    // Defaults are valid, names unique.
    EXPECT_FALSE(gi::validate(specs, st.values, diag).has_value()) << *gi::validate(specs, st.values, diag);
    for (size_t a = 0; a < specs.size(); ++a)
      for (size_t b = a + 1; b < specs.size(); ++b) EXPECT_NE(specs[a].name, specs[b].name);
    // Exactly one <Param> per spec, in the spec order.
    size_t params = 0, p = 0;
    while ((p = block.find("<Param ", p)) != std::string::npos) { ++params; ++p; }
    EXPECT_EQ(params, specs.size());
    size_t at = 0;
    for (const auto& s : specs) {
      const size_t q = block.find("name=\"" + s.name + "\"", at);
      ASSERT_NE(q, std::string::npos) << s.name << " missing or out of order";
      const size_t ls = block.rfind("<Param ", q), le = block.find("/>", q);
      const std::string line = block.substr(ls, le - ls);
      static const char* types[] = {"RichBool", "RichInt", "RichFloat", "RichAbsPerc", "RichEnum", "RichColor", "RichPoint3f", "RichPoint3f", "RichString"};
      EXPECT_NE(line.find(std::string("type=\"") + types[int(s.type)] + "\""), std::string::npos) << line;
      if (s.type == gi::ParamType::Enum) {
        EXPECT_NE(line.find("enum_cardinality=\"" + std::to_string(s.choices.size()) + "\""), std::string::npos) << line;
        for (size_t k = 0; k < s.choices.size(); ++k)
          EXPECT_NE(line.find("enum_val" + std::to_string(k) + "=\""), std::string::npos) << line;
      }
      if (s.type == gi::ParamType::Distance) {
        std::smatch m;
        ASSERT_TRUE(std::regex_search(line, m, std::regex(R"re( value="([^"]*)" min="([^"]*)" max="([^"]*)")re"))) << line;
        const double value = std::stod(m[1]), lo = std::stod(m[2]), hi = std::stod(m[3]);
        EXPECT_EQ(lo, 0.0) << line;
        // max = spec max x diagonal (1 x diagonal when unbounded); relative 1e-8.
        EXPECT_NEAR(hi, (s.max > 0 ? s.max : 1.0) * diag, 1e-8 * diag) << line;
        EXPECT_NEAR(value, st.values.getFloat(s.name), 1e-8 * diag) << line;
        EXPECT_LE(value, hi) << line;
      }
      at = q + 1;
    }
    pos = end;
  }
  // Overridden values reach the script (e.g. an int and a distance).
  const auto specs = gi::filterSpecs(gi::FilterKind::AmbientOcclusion);
  gi::ParamValues v = gi::defaultValues(specs, diag);
  bool changedInt = false;
  for (const auto& s : specs) {
    if (s.type != gi::ParamType::Int) continue;
    v.set(s.name, int(s.min) + 3);
    const std::string x1 = gi::mlxScript({{gi::FilterKind::AmbientOcclusion, v}}, diag);
    EXPECT_NE(x1.find("value=\"" + std::to_string(int(s.min) + 3) + "\" name=\"" + s.name + "\""), std::string::npos) << x1;
    changedInt = true;
    break;
  }
  EXPECT_TRUE(changedInt);
}

}  // namespace

TEST(RunStats, LineShowsWarningsBeforeNotes) {
  gi::RunStats st;
  st.add("rays", 10);
  st.note("skipped nothing");
  st.warn("not converged");
  EXPECT_EQ(st.line("T"), "T: rays=10; WARNING: not converged; skipped nothing");
}

// An enumeration's table gives its dialog choices, log names and values by
// one list: index <-> value both ways, out-of-range choices refused.
TEST(EnumTable, ChoicesLogNamesAndValuesFromOneList) {
  enum class Fruit { Pear = 7, Apple = 3 };
  static constexpr auto table = gi::makeEnumTable<Fruit>(gi::EnumChoice<Fruit>{Fruit::Pear, "A pear", "pear"},
                                                         gi::EnumChoice<Fruit>{Fruit::Apple, "An apple", "apple"});
  EXPECT_EQ(table.choices(), (std::vector<std::string>{"A pear", "An apple"}));
  EXPECT_EQ(table.index(Fruit::Apple), 1);
  EXPECT_STREQ(table.logName(Fruit::Pear), "pear");
  gi::ParamValues v;
  v.set("fruit", 1);
  EXPECT_EQ(table.get(v, "fruit"), Fruit::Apple);
  v.set("fruit", 2);
  EXPECT_THROW(table.get(v, "fruit"), std::invalid_argument);
}

// .mlx scripts store an enumeration's index: every filter's choices keep
// their order (new ones may only be appended). The lists as scripts know them.
TEST(EnumTable, ScriptIndicesKeepTheirChoices) {
  using L = std::vector<std::string>;
  const std::map<std::string, L> expected = {
      {"scene_extent", L{"Current layer", "All visible layers"}},
      {"reflectance_source", L{"Auto", "Face color", "Vertex color", "Constant"}},
      {"emitter_source", L{"Selected faces", "Face quality above threshold", "None", "Auto"}},
      {"color_mapping", L{"Grey", "Multiply colour", "Keep colour"}},
      {"ray_batching", L{"Single", "Packet8", "Stream"}},
      {"estimator", L{"Per vertex", "Shared with neighbours"}},
      {"form_factor_method", L{"Monte Carlo", "Analytic point-to-polygon", "Hemicube", "Auto"}},
      {"solver", L{"Auto", "Jacobi", "Gauss-Seidel", "Progressive refinement", "Hierarchical"}},
      {"vertex_output", L{"Final gather", "Interpolated indirect", "Patch average"}},
      {"mode", L{"Whitted", "Distributed", "Two-pass", "Path traced"}},
      {"camera", L{"Frame the scene", "Look at", "The layer's camera"}},
      {"two_pass_diffuse", L{"First pass alone", "Ray-traced direct + stored indirect",
                             "Direct + caustic map + stored indirect", "Direct + caustic map + final gather"}},
      {"reference_source", L{"Attribute of this mesh", "PLY file"}},
      {"error_measure", L{"Difference (value - reference)", "Relative difference ((value - reference) / |reference|)",
                          "z-score ((value - reference) / standard error)"}},
  };
  std::set<std::string> seen;
  for (const gi::FilterDesc& d : gi::allFilters())
    for (const gi::ParamSpec& p : gi::filterSpecs(d.kind)) {
      if (p.type != gi::ParamType::Enum) continue;
      SCOPED_TRACE(d.cliName + " --" + p.name);
      ASSERT_EQ(expected.count(p.name), 1u) << "a new enumeration: add its choices above";
      EXPECT_EQ(p.choices, expected.at(p.name));
      seen.insert(p.name);
    }
  EXPECT_EQ(seen.size(), expected.size());
}
