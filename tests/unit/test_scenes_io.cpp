// Canonical scenes (gi::scenes) and mesh files (gi::io): geometry against the
// analytic sizes of docs/design.md, "Analytic references", orientation, and PLY round trips.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include "gi/scenes.h"
#include "gi/color.h"
#include "gi/scene_setup.h"
#include "gi/filters.h"
#include "mesh_io.h"
#include "result_file.h"

namespace fs = std::filesystem;
using gi::scenes::SceneFile;

namespace {

constexpr double kPi = 3.14159265358979323846;

glm::dvec3 centroid(const gi::Scene& s, size_t f) {
  const auto& t = s.triangles[f];
  return (s.toWorld(s.positions[t.x]) + s.toWorld(s.positions[t.y]) + s.toWorld(s.positions[t.z])) / 3.0;
}
glm::dvec3 unitNormal(const gi::Scene& s, size_t f) {
  return glm::normalize(glm::dvec3(gi::faceNormalUnnormalized(s, f)));
}
// Total area of the faces whose world centroid satisfies `pick`.
double areaWhere(const gi::Scene& s, const std::function<bool(const glm::dvec3&)>& pick) {
  double a = 0.0;
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (pick(centroid(s, f))) a += gi::faceArea(s, f);
  return a;
}
double totalArea(const gi::Scene& s) {
  return areaWhere(s, [](const glm::dvec3&) { return true; });
}
double emitterArea(const SceneFile& sf) {
  double a = 0.0;
  for (size_t f = 0; f < sf.scene.faceCount(); ++f)
    if (sf.attrs.faceQuality[f] > 0.f) a += gi::faceArea(sf.scene, f);
  return a;
}
bool hasVertexAt(const gi::Scene& s, const glm::dvec3& p) {
  for (const auto& q : s.positions)
    if (s.toWorld(q) == p) return true;
  return false;
}
// Every face whose centroid satisfies `pick` has its normal along want(centroid).
void expectFacing(const gi::Scene& s, const std::function<bool(const glm::dvec3&)>& pick,
                  const std::function<glm::dvec3(const glm::dvec3&)>& want, const char* what) {
  size_t checked = 0, wrong = 0;
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const glm::dvec3 c = centroid(s, f);
    if (!pick(c)) continue;
    ++checked;
    if (glm::dot(unitNormal(s, f), glm::normalize(want(c))) <= 0.0) ++wrong;
  }
  EXPECT_GT(checked, 0u) << what;
  EXPECT_EQ(wrong, 0u) << what;
}
auto all = [](const glm::dvec3&) { return true; };

std::string tempPath(const std::string& name) {
  return (fs::temp_directory_path() / ("gi_test_" + std::to_string(::getpid()) + "_" + name)).string();
}
void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

}  // namespace

TEST(Scenes, EveryNamedSceneIsUsable) {
  for (const auto& name : gi::scenes::names())
  for (const auto& layer : gi::scenes::layersByName(name)) {
    SCOPED_TRACE(layer.name);
    const SceneFile& sf = layer.file;
    const auto& s = sf.scene;
    const bool specular = gi::matchesLayerPatterns(layer.name, "*mirror*,*glass*");
    const gi::SceneReport r = gi::analyzeScene(s);
    EXPECT_GT(s.faceCount(), 0u);
    EXPECT_EQ(r.nonFiniteVertices, 0u);
    EXPECT_EQ(r.usableFaces(), s.faceCount());
    EXPECT_EQ(r.isolatedVertices, 0u);
    ASSERT_EQ(s.rho.size(), s.faceCount());
    ASSERT_EQ(s.emission.size(), s.faceCount());
    ASSERT_EQ(sf.attrs.faceColor.size(), s.faceCount());
    ASSERT_EQ(sf.attrs.faceQuality.size(), s.faceCount());
    for (size_t f = 0; f < s.faceCount(); ++f) {
      const bool emits = gi::luminance(s.emission[f]) > 0.f;
      EXPECT_EQ(sf.attrs.faceQuality[f], emits ? 1.f : 0.f);
      EXPECT_LT(std::max({s.rho[f].r, s.rho[f].g, s.rho[f].b}), specular ? 1.0001f : 1.f);
      const glm::vec3 back = gi::srgb8ToLinear(sf.attrs.faceColor[f].r, sf.attrs.faceColor[f].g, sf.attrs.faceColor[f].b);
      EXPECT_NEAR(back.g, s.rho[f].g, 0.01f);
    }
  }
  EXPECT_THROW(gi::scenes::byName("no_such_scene"), std::invalid_argument);
}

TEST(Scenes, CornellBoxGeometry) {
  const SceneFile sf = gi::scenes::cornellBox(50.0);
  const auto& s = sf.scene;
  const double floorArea = areaWhere(s, [](const glm::dvec3& c) { return std::abs(c.y) < 1e-3; });
  EXPECT_NEAR(floorArea, 0.5 * (552.8 + 549.6) * 559.2, 1e-6 * floorArea);
  // Ceiling 556 x 559.2 without the light's hole.
  const double ceilingArea = areaWhere(s, [](const glm::dvec3& c) { return std::abs(c.y - 548.8) < 1e-3; });
  EXPECT_NEAR(ceilingArea, 556.0 * 559.2 - 130.0 * 105.0, 1e-6 * ceilingArea);
  EXPECT_NEAR(emitterArea(sf), 130.0 * 105.0, 0.01 * 130.0 * 105.0);
  // Walls (faces on the box's boundary) face the interior.
  const glm::dvec3 centre(278.0, 274.4, 279.6);
  auto onWall = [](const glm::dvec3& c) {
    return c.y < 1e-3 || c.y > 548.75 || c.z > 559.1 || c.x < 1e-3 || c.x > 549.0;
  };
  expectFacing(s, onWall, [&](const glm::dvec3& c) { return centre - c; }, "walls face the interior");
  // Light faces down; block tops face up; nothing but the open front at z = 0.
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (sf.attrs.faceQuality[f] > 0.f) {
      EXPECT_NEAR(unitNormal(s, f).y, -1.0, 1e-6);
      EXPECT_NEAR(s.emission[f].r, kPi * 17.0, 1e-4);
    }
    const glm::dvec3 c = centroid(s, f);
    if (std::abs(c.y - 165.0) < 1e-3 || std::abs(c.y - 330.0) < 1e-3) {
      EXPECT_NEAR(unitNormal(s, f).y, 1.0, 1e-6);
    }
  }
  // Block sides face away from their block: no side normal points to the block's axis.
  expectFacing(s, [](const glm::dvec3& c) { return c.y > 1 && c.y < 164 && c.x > 82 && c.x < 290 && c.z < 272; },
               [](const glm::dvec3& c) { return c - glm::dvec3(185.5, c.y, 169.0); }, "short block sides");
  const double blockSides =
      165.0 * (std::hypot(48, 160) + std::hypot(158, 47) + std::hypot(50, 158) + std::hypot(160, 49)) +
      330.0 * (std::hypot(158, 49) + std::hypot(49, 160) + std::hypot(158, 50) + std::hypot(49, 159));
  const double sideArea = areaWhere(s, [&](const glm::dvec3& c) { return !onWall(c) && c.y < 329.9 && c.y > 0.1 &&
                                                                       std::abs(c.y - 165.0) > 1e-3; });
  EXPECT_NEAR(sideArea, blockSides, 1e-3 * blockSides);
  // Patch edge about 50 mm: a few hundred patches per wall set.
  EXPECT_GT(s.faceCount(), 1000u);
  EXPECT_GT(gi::scenes::cornellBox(25.0).scene.faceCount(), 3 * s.faceCount());
}

TEST(Scenes, PlatesAreUnitSquaresFacingEachOther) {
  const SceneFile pp = gi::scenes::parallelPlates(0.5, 8);
  EXPECT_EQ(pp.scene.faceCount(), 2u * 8 * 8 * 2);
  EXPECT_NEAR(totalArea(pp.scene), 2.0, 1e-9);
  EXPECT_NEAR(emitterArea(pp), 1.0, 1e-9);
  expectFacing(pp.scene, [](const glm::dvec3& c) { return c.z < 0.25; }, [](const glm::dvec3&) { return glm::dvec3(0, 0, 1); }, "bottom");
  expectFacing(pp.scene, [](const glm::dvec3& c) { return std::abs(c.z - 0.5) < 1e-9; },
               [](const glm::dvec3&) { return glm::dvec3(0, 0, -1); }, "top at L");
  const SceneFile pq = gi::scenes::perpendicularPlates(4);
  EXPECT_NEAR(totalArea(pq.scene), 2.0, 1e-9);
  EXPECT_NEAR(emitterArea(pq), 1.0, 1e-9);
  expectFacing(pq.scene, [](const glm::dvec3& c) { return c.z == 0.0; }, [](const glm::dvec3&) { return glm::dvec3(0, 0, 1); }, "floor");
  expectFacing(pq.scene, [](const glm::dvec3& c) { return c.x == 0.0; }, [](const glm::dvec3&) { return glm::dvec3(1, 0, 0); }, "wall");
}

TEST(Scenes, SpheresAndBoxes) {
  const SceneFile in = gi::scenes::byName("furnace_sphere");
  EXPECT_NEAR(totalArea(in.scene), 4 * kPi, 0.02 * 4 * kPi);
  expectFacing(in.scene, all, [](const glm::dvec3& c) { return -c; }, "inward sphere");
  EXPECT_NEAR(emitterArea(in), totalArea(in.scene), 1e-9);
  for (size_t f = 0; f < in.scene.faceCount(); ++f) EXPECT_EQ(in.scene.rho[f], glm::vec3(0.5f));
  const SceneFile out = gi::scenes::sphere(2.0, 4, false);
  EXPECT_EQ(out.scene.faceCount(), 20u * 256);
  EXPECT_NEAR(totalArea(out.scene), 16 * kPi, 0.01 * 16 * kPi);
  expectFacing(out.scene, all, [](const glm::dvec3& c) { return c; }, "outward sphere");

  const SceneFile box = gi::scenes::closedBox(2.0, 3, true);
  EXPECT_NEAR(totalArea(box.scene), 24.0, 1e-9);
  expectFacing(box.scene, all, [](const glm::dvec3& c) { return -c; }, "inward box");
  expectFacing(gi::scenes::closedBox(1.0, 2, false).scene, all, [](const glm::dvec3& c) { return c; }, "outward box");
}

TEST(Scenes, OpenGeometriesForAmbientOcclusion) {
  const SceneFile plane = gi::scenes::openPlane(3.0, 5);
  EXPECT_NEAR(totalArea(plane.scene), 9.0, 1e-9);
  expectFacing(plane.scene, all, [](const glm::dvec3&) { return glm::dvec3(0, 0, 1); }, "plane");

  const SceneFile fw = gi::scenes::floorWithWall(4.0, 1.0, 20);
  const double W = 20.0;  // 20 x wall height
  EXPECT_NEAR(areaWhere(fw.scene, [](const glm::dvec3& c) { return c.z == 0.0; }), 4.0 * W, 1e-6);
  EXPECT_NEAR(areaWhere(fw.scene, [](const glm::dvec3& c) { return c.x == 0.0; }), 1.0 * W, 1e-6);
  expectFacing(fw.scene, [](const glm::dvec3& c) { return c.z == 0.0; }, [](const glm::dvec3&) { return glm::dvec3(0, 0, 1); }, "floor");
  expectFacing(fw.scene, [](const glm::dvec3& c) { return c.x == 0.0; }, [](const glm::dvec3&) { return glm::dvec3(1, 0, 0); }, "wall");
  // Reference points of docs/design.md, "Analytic references" (d = 0, H, 2H) are vertices.
  for (double d : {0.0, 1.0, 2.0}) EXPECT_TRUE(hasVertexAt(fw.scene, {d, 0.0, 0.0})) << d;

  const SceneFile bowl = gi::scenes::hemisphericalBowl(2.0, 12);
  EXPECT_NEAR(totalArea(bowl.scene), 8 * kPi, 0.02 * 8 * kPi);
  expectFacing(bowl.scene, all, [](const glm::dvec3& c) { return -c; }, "bowl");
  EXPECT_TRUE(hasVertexAt(bowl.scene, {0.0, 0.0, -2.0}));

  const double a = 0.5, h = 1.5;
  const SceneFile hole = gi::scenes::cylindricalHole(a, h, 8);
  auto ground = [](const glm::dvec3& c) { return c.z == 0.0; };
  auto bottom = [h](const glm::dvec3& c) { return c.z == -h; };
  auto wall = [h](const glm::dvec3& c) { return c.z < 0.0 && c.z > -h; };
  EXPECT_NEAR(areaWhere(hole.scene, ground), 99 * kPi * a * a, 0.02 * 99 * kPi * a * a);
  EXPECT_NEAR(areaWhere(hole.scene, bottom), kPi * a * a, 0.02 * kPi * a * a);
  EXPECT_NEAR(areaWhere(hole.scene, wall), 2 * kPi * a * h, 0.02 * 2 * kPi * a * h);
  expectFacing(hole.scene, ground, [](const glm::dvec3&) { return glm::dvec3(0, 0, 1); }, "ground");
  expectFacing(hole.scene, bottom, [](const glm::dvec3&) { return glm::dvec3(0, 0, 1); }, "bottom");
  expectFacing(hole.scene, wall, [](const glm::dvec3& c) { return glm::dvec3(-c.x, -c.y, 0); }, "wall");
  EXPECT_TRUE(hasVertexAt(hole.scene, {0.0, 0.0, -h}));
}

TEST(ScenesIo, PlyRoundTripKeepsGeometryAndAttributes) {
  for (const char* name : {"cornell_box", "furnace_sphere", "cylinder_hole"}) {
    SCOPED_TRACE(name);
    const SceneFile sf = gi::scenes::byName(name);
    const auto& s = sf.scene;
    std::vector<float> q(s.vertexCount());
    std::vector<gi::Rgb8> col(s.vertexCount());
    gi::io::PlyExtras extras;
    for (size_t v = 0; v < s.vertexCount(); ++v) {
      q[v] = 0.25f * float(v);
      col[v] = {uint8_t(v), uint8_t(v / 7), 200};
      extras.normals.push_back(glm::normalize(glm::vec3(1.f, float(v % 5), 2.f)));
    }
    const std::string path = tempPath(std::string(name) + ".ply");
    gi::io::writePly(path, s, sf.attrs, q, col, extras);
    const gi::io::LoadedMesh m = gi::io::loadMesh(path);
    fs::remove(path);
    ASSERT_EQ(m.scene.vertexCount(), s.vertexCount());
    ASSERT_EQ(m.scene.faceCount(), s.faceCount());
    // Float rounding on write and again on re-centring: a few ulps of the extent.
    const double tol = 1e-6 * std::max(1.0, gi::analyzeScene(s).diagonal);
    for (size_t v = 0; v < s.vertexCount(); ++v) {
      const glm::dvec3 a = s.toWorld(s.positions[v]), b = m.scene.toWorld(m.scene.positions[v]);
      ASSERT_NEAR(glm::length(a - b), 0.0, tol) << v;
    }
    // OpenMesh 9 keeps the vertex order and each face's first vertex.
    for (size_t f = 0; f < s.faceCount(); ++f) {
      ASSERT_EQ(m.scene.triangles[f], s.triangles[f]) << f;
      EXPECT_EQ(m.triangleToFace[f], f);
    }
    EXPECT_EQ(m.attrs.faceColor, sf.attrs.faceColor);
    EXPECT_EQ(m.attrs.faceQuality, sf.attrs.faceQuality);
    ASSERT_EQ(m.attrs.vertexColor.size(), s.vertexCount());
    EXPECT_EQ(m.attrs.vertexColor[5], glm::u8vec3(col[5].r, col[5].g, col[5].b));
    ASSERT_EQ(m.scene.vertexNormals.size(), s.vertexCount());
    EXPECT_NEAR(glm::length(m.scene.vertexNormals[3] - extras.normals[3]), 0.f, 1e-6f);
  }
}

TEST(ScenesIo, PlyFarFromOriginKeepsFloatPrecision) {
  SceneFile sf = gi::scenes::openPlane(1.0, 2);
  sf.scene.origin += glm::dvec3(1e5, -2e5, 3e4);  // representable in float to ~0.01
  const std::string path = tempPath("far.ply");
  gi::io::writePly(path, sf.scene, sf.attrs, {}, {});
  const auto m = gi::io::loadMesh(path);
  fs::remove(path);
  ASSERT_EQ(m.scene.vertexCount(), sf.scene.vertexCount());
  for (size_t v = 0; v < m.scene.vertexCount(); ++v)
    EXPECT_NEAR(glm::length(m.scene.toWorld(m.scene.positions[v]) - sf.scene.toWorld(sf.scene.positions[v])), 0.0, 0.02);
  EXPECT_TRUE(m.attrs.vertexColor.empty());
  EXPECT_EQ(m.attrs.faceQuality, sf.attrs.faceQuality);
}

TEST(ScenesIo, AsciiPolygonsAreFanTriangulated) {
  const std::string path = tempPath("quad.ply");
  writeBytes(path,
             "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 2\nproperty list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\n"
             "property uchar blue\nproperty float quality\nend_header\n"
             "0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n4 0 1 2 3 200 100 50 1.5\n3 1 4 2 1 2 3 0.25\n");
  const auto m = gi::io::loadMesh(path);
  fs::remove(path);
  ASSERT_EQ(m.scene.faceCount(), 3u);
  EXPECT_EQ(m.triangleToFace, (std::vector<uint32_t>{0, 0, 1}));
  EXPECT_EQ(m.attrs.faceQuality, (std::vector<float>{1.5f, 1.5f, 0.25f}));
  ASSERT_EQ(m.attrs.faceColor.size(), 3u);
  EXPECT_EQ(m.attrs.faceColor[1], glm::u8vec3(200, 100, 50));
  EXPECT_EQ(m.attrs.faceColor[2], glm::u8vec3(1, 2, 3));
  EXPECT_TRUE(m.attrs.vertexColor.empty());
  EXPECT_TRUE(m.scene.vertexNormals.empty());
  for (size_t f = 0; f < 3; ++f) EXPECT_GT(gi::faceNormalUnnormalized(m.scene, f).z, 0.f);
}

// A concave polygon is cut into triangles inside it (ear clipping; a fan
// from its reflex corner covered the notch outside: the quad (2,0),
// (0.5,0.5), (0,2), (0,0) of area 1 came out 3; an outside audit), in PLY,
// OFF and OBJ alike; a convex one keeps the fan's triangles. An L-shaped
// hexagon and a concave star of 10 corners too: the areas add up to the
// polygon's (shoelace) and every triangle faces the polygon's way.
TEST(ScenesIo, ConcavePolygonsAreCutInsideThem) {
  struct Poly { std::vector<glm::dvec2> p; double area; };
  std::vector<glm::dvec2> star;
  for (int k = 0; k < 10; ++k) {
    const double a = kPi * k / 5, r = k % 2 ? 0.4 : 1.0;
    star.push_back({r * std::cos(a), r * std::sin(a)});
  }
  double starArea = 0;
  for (size_t k = 0; k < star.size(); ++k) {
    const auto &a = star[k], &b = star[(k + 1) % star.size()];
    starArea += 0.5 * (a.x * b.y - b.x * a.y);
  }
  const std::vector<Poly> polys = {{{{2, 0}, {0.5, 0.5}, {0, 2}, {0, 0}}, 1.0},
                                   {{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}, 3.0},
                                   {star, starArea}};
  for (const Poly& poly : polys) {
    const size_t n = poly.p.size();
    std::string ply = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(n) +
                      "\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
                      "property list uchar int vertex_indices\nend_header\n";
    std::string off = "OFF\n" + std::to_string(n) + " 1 0\n", obj, face = std::to_string(n), objFace = "f";
    for (size_t k = 0; k < n; ++k) {
      char line[96];
      std::snprintf(line, sizeof line, "%.17g %.17g 0.5\n", poly.p[k].x, poly.p[k].y);
      ply += line, off += line, obj += std::string("v ") + line;
      face += " " + std::to_string(k), objFace += " " + std::to_string(k + 1);
    }
    ply += face + "\n", off += face + "\n", obj += objFace + "\n";
    for (const auto& [format, text] : {std::pair{"ply", ply}, std::pair{"off", off}, std::pair{"obj", obj}}) {
      const auto m = gi::io::parseMesh(text, format, std::string("p.") + format);
      ASSERT_EQ(m.scene.faceCount(), n - 2) << format;
      double area = 0;
      for (size_t f = 0; f < m.scene.faceCount(); ++f) {
        const glm::vec3 c = gi::faceNormalUnnormalized(m.scene, f);
        EXPECT_GT(c.z, 0.f) << format << ", " << n << " corners, triangle " << f;
        area += 0.5 * double(glm::length(c));
      }
      EXPECT_NEAR(area, poly.area, 1e-6 * poly.area) << format << ", " << n << " corners";
    }
  }
}

// A polygon that crosses itself has no inside to cut: a bow tie (the
// symmetric one's lobes cancel, so it has no net normal; a lopsided one's
// do not), a pentagram (turning the same way at every corner, twice round)
// and a bow tie among concave corners are each split and warned about, once
// per file; the simple polygons beside them are not (an outside audit: a
// bow-tie quad was cut without a word).
TEST(ScenesIo, SelfCrossingPolygonsAreWarned) {
  std::vector<glm::dvec2> pentagram;
  for (int k = 0; k < 5; ++k) pentagram.push_back({std::cos(4 * kPi * k / 5), std::sin(4 * kPi * k / 5)});
  const std::vector<std::pair<std::vector<glm::dvec2>, bool>> polys = {
      {{{0, 0}, {1, 1}, {1, 0}, {0, 1}}, true},                    // symmetric bow tie
      {{{0, 0}, {2, 2}, {2, 0}, {0, 1}}, true},                    // lopsided bow tie
      {pentagram, true},                                           // every corner turns left
      {{{0, 0}, {3, 0}, {3, 3}, {2, 1}, {1, 3}, {1, -1}}, true},   // concave, one pair of edges crossing
      {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, false},                   // square
      {{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}, false},   // L
      {{{0, 0}, {1, 0}, {2, 0}, {2, 1}, {0, 1}}, false},           // a flat corner
  };
  for (const auto& [p, crossing] : polys) {
    const size_t n = p.size();
    std::string off = "OFF\n" + std::to_string(n) + " 1 0\n", face = std::to_string(n);
    for (size_t k = 0; k < n; ++k) {
      char line[96];
      std::snprintf(line, sizeof line, "%.17g %.17g 0\n", p[k].x, p[k].y);
      off += line;
      face += " " + std::to_string(k);
    }
    const auto m = gi::io::parseMesh(off + face + "\n", "off", "p.off");
    EXPECT_EQ(m.scene.faceCount(), n - 2) << face;
    ASSERT_EQ(m.warnings.size(), crossing ? 1u : 0u) << face;
    if (crossing) {
      EXPECT_NE(m.warnings[0].find("cross"), std::string::npos) << m.warnings[0];
    }
  }
}

// Ear clipping stops at 256 corners (its rounds are O(n^2)): a concave
// star of 254 corners is cut inside itself, one of 258 is split as a fan
// and the loader says so (an outside audit found a 258-corner comb's area
// 22 times too large, a quarter of its triangles reversed, and no word).
TEST(ScenesIo, LargeConcavePolygonsAreCutOrWarned) {
  for (int n : {254, 258}) {
    std::string ply = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(n) +
                      "\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
                      "property list int int vertex_indices\nend_header\n";
    std::string face = std::to_string(n);
    double exact = 0;
    std::vector<glm::dvec2> p;
    for (int k = 0; k < n; ++k) {
      const double a = 2 * kPi * k / n, r = k % 2 ? 0.4 : 1.0;
      p.push_back({r * std::cos(a), r * std::sin(a)});
    }
    for (int k = 0; k < n; ++k) {
      char line[96];
      std::snprintf(line, sizeof line, "%.17g %.17g 0\n", p[size_t(k)].x, p[size_t(k)].y);
      ply += line;
      face += " " + std::to_string(k);
      const auto &a = p[size_t(k)], &b = p[size_t(k + 1) % p.size()];
      exact += 0.5 * (a.x * b.y - b.x * a.y);
    }
    const auto m = gi::io::parseMesh(ply + face + "\n", "ply", "star.ply");
    double area = 0;
    for (size_t f = 0; f < m.scene.faceCount(); ++f) area += 0.5 * double(glm::length(gi::faceNormalUnnormalized(m.scene, f)));
    if (n <= 256) {
      EXPECT_TRUE(m.warnings.empty()) << n;
      EXPECT_NEAR(area, exact, 1e-5 * exact) << n;
    } else {
      ASSERT_EQ(m.warnings.size(), 1u) << n;
      EXPECT_NE(m.warnings[0].find("258"), std::string::npos) << m.warnings[0];
      EXPECT_GT(area, 1.1 * exact) << "the fan covers area outside the star";
    }
  }
}

// Several layers keep each its own reflectance rule (an outside audit: a
// layer without colours beside one with face colours took the filler grey,
// not the constant; a layer's vertex colours gave way to another's face
// colours; a layer whose vertex colours display an earlier result, beside
// one without that result, had them read as reflectance).
TEST(ScenesIo, LayersKeepTheirOwnReflectanceRule) {
  auto ply = [](const std::string& vertexProps, const std::string& faceProps, const std::string& vx,
                const std::string& fx) {
    std::string h = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n" +
                    vertexProps + "element face 1\nproperty list uchar int vertex_indices\n" + faceProps + "end_header\n";
    return h + "0 0 0" + vx + "\n1 0 0" + vx + "\n0 1 0" + vx + "\n3 0 1 2" + fx + "\n";
  };
  const std::string rgb = "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  const std::string shown = "property float Radiosity_x\nproperty float Radiosity_y\nproperty float Radiosity_z\n";
  const auto faceColoured = gi::io::parseMesh(ply("", rgb, "", " 200 100 30"), "ply", "f.ply");
  const auto bare = gi::io::parseMesh(ply("", "", "", ""), "ply", "n.ply");
  const auto vertexColoured = gi::io::parseMesh(ply(rgb, "", " 30 100 200", ""), "ply", "v.ply");
  const auto display = gi::io::parseMesh(ply(rgb + shown, "", " 255 255 255 1 1 1", ""), "ply", "r.ply");
  const auto specs = gi::filterSpecs(gi::FilterKind::Radiosity);
  auto rho = [&](const gi::io::LoadedMesh& a, const gi::io::LoadedMesh& b, const char* constant) {
    gi::io::LoadedMesh m = a;
    gi::io::appendMesh(m, b);
    gi::ParamValues v = gi::defaultValues(specs, 1.0);
    v.set("reflectance", glm::vec3(float(std::atof(constant)) / 255.f));
    gi::Scene s = m.scene;
    std::string log;
    EXPECT_FALSE(gi::applySceneConventions(s, m.attrs, v, false, &log).has_value());
    return std::make_pair(s.rho, log);
  };
  auto lin = [](int a, int b, int c) { return gi::srgb8ToLinear(uint8_t(a), uint8_t(b), uint8_t(c)); };
  auto near = [](glm::vec3 a, glm::vec3 b) { return glm::length(a - b) < 1e-6f; };
  {
    const auto [r, log] = rho(faceColoured, bare, "100");
    EXPECT_TRUE(near(r[0], lin(200, 100, 30)));
    EXPECT_TRUE(near(r[1], lin(100, 100, 100))) << "the layer without colours takes the constant";
    EXPECT_NE(log.find("reflectance per layer"), std::string::npos) << log;
  }
  {
    const auto [r, log] = rho(vertexColoured, faceColoured, "100");
    EXPECT_TRUE(near(r[0], lin(30, 100, 200))) << "its own vertex colours";
    EXPECT_TRUE(near(r[1], lin(200, 100, 30)));
  }
  for (bool first : {true, false}) {
    const auto [r, log] = first ? rho(display, vertexColoured, "188") : rho(vertexColoured, display, "188");
    EXPECT_TRUE(near(r[first ? 0 : 1], lin(188, 188, 188))) << "displayed result colours are no reflectance";
    EXPECT_TRUE(near(r[first ? 1 : 0], lin(30, 100, 200)));
  }
  {  // one kind of colour everywhere: the one mesh's rule and its log
    const auto [r, log] = rho(faceColoured, faceColoured, "100");
    EXPECT_NE(log.find("reflectance from face colour"), std::string::npos) << log;
  }
}

TEST(ScenesIo, ObjOffAndStlAreRead) {
  const std::string obj = tempPath("quad.obj"), off = tempPath("quad.off");
  writeBytes(obj, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  writeBytes(off, "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
  for (const auto& p : {obj, off}) {
    const auto m = gi::io::loadMesh(p);
    fs::remove(p);
    EXPECT_EQ(m.scene.faceCount(), 2u) << p;
    EXPECT_NEAR(totalArea(m.scene), 1.0, 1e-9) << p;
    EXPECT_TRUE(m.attrs.faceColor.empty()) << p;
  }
  // Face colours after the indices, as MeshLab writes them (OpenMesh 9's OFF
  // reader loses the faces there); integer and float colours; COFF vertex colours.
  writeBytes(off, "OFF\n# comment\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n"
                  "4 0 1 2 3 221 219 215\n3 1 4 2 0.5 1.0 0\n");
  auto m = gi::io::loadMesh(off);
  ASSERT_EQ(m.scene.faceCount(), 3u);
  EXPECT_EQ(m.triangleToFace, (std::vector<uint32_t>{0, 0, 1}));
  EXPECT_EQ(m.attrs.faceColor, (std::vector<glm::u8vec3>{{221, 219, 215}, {221, 219, 215}, {128, 255, 0}}));
  writeBytes(off, "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n");
  m = gi::io::loadMesh(off);
  fs::remove(off);
  EXPECT_EQ(m.attrs.vertexColor, (std::vector<glm::u8vec3>{{255, 0, 0}, {0, 255, 0}, {0, 0, 255}}));
  EXPECT_TRUE(m.attrs.faceColor.empty());

  // Binary STL: coincident corners merged, no colours (its colour bytes are not a standard).
  std::string stl(80, ' ');
  auto u32 = [&](uint32_t v) { stl.append(reinterpret_cast<const char*>(&v), 4); };
  auto f32 = [&](float v) { stl.append(reinterpret_cast<const char*>(&v), 4); };
  u32(2);
  for (const auto& tri : {std::vector<float>{0, 0, 0, 1, 0, 0, 1, 1, 0}, std::vector<float>{0, 0, 0, 1, 1, 0, 0, 1, 0}}) {
    for (int k = 0; k < 3; ++k) f32(k == 2 ? 1.f : 0.f);
    for (float c : tri) f32(c);
    stl.append(2, '\0');
  }
  const std::string stlPath = tempPath("quad.stl");
  writeBytes(stlPath, stl);
  m = gi::io::loadMesh(stlPath);
  fs::remove(stlPath);
  EXPECT_EQ(m.scene.vertexCount(), 4u);
  EXPECT_EQ(m.scene.faceCount(), 2u);
  EXPECT_TRUE(m.attrs.faceColor.empty());
  EXPECT_TRUE(m.attrs.vertexColor.empty());
  EXPECT_GT(gi::faceNormalUnnormalized(m.scene, 0).z, 0.f);
}

TEST(ScenesIo, StanfordBunnyIsClosedAndOutward) {
  const std::string path = std::string(GI_TEST_MESHES) + "/bunny.ply";
  ASSERT_TRUE(fs::exists(path)) << "test_meshes/bunny.ply is shipped (test_meshes/bunny_from_npm.sh regenerates it)";
  const auto m = gi::io::loadMesh(path);
  EXPECT_EQ(m.scene.vertexCount(), 1839u);
  EXPECT_EQ(m.scene.faceCount(), 3674u);
  EXPECT_EQ(gi::analyzeScene(m.scene).usableFaces(), 3674u);
  // Divergence theorem: positive volume means outward normals.
  double volume = 0.0;
  for (const auto& t : m.scene.triangles)
    volume += glm::dot(glm::dvec3(m.scene.positions[t.x]),
                       glm::cross(glm::dvec3(m.scene.positions[t.y]), glm::dvec3(m.scene.positions[t.z]))) / 6.0;
  EXPECT_GT(volume, 0.0);
}

TEST(ScenesIo, BadFilesThrowOneSentenceNamingTheFile) {
  auto expectFails = [](const std::string& path) {
    try {
      gi::io::loadMesh(path);
      ADD_FAILURE() << "no exception for " << path;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  expectFails(tempPath("does_not_exist.ply"));
  const std::string garbage = tempPath("garbage.ply"), garbageObj = tempPath("garbage.obj");
  const std::string huge = tempPath("huge.ply"), truncated = tempPath("truncated.ply"), txt = tempPath("mesh.txt");
  writeBytes(garbage, std::string("\x00\xff garbage \x13\x37", 14) + std::string(3000, '\x7f'));
  writeBytes(garbageObj, "hello world\nthis is not a mesh\n");
  writeBytes(huge, "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\n"
                   "property float y\nproperty float z\nend_header\n\x01\x02");
  // A valid header whose body stops after one vertex.
  writeBytes(truncated, "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n" +
                            std::string(12, '\0'));
  writeBytes(txt, "v 0 0 0\n");
  const std::string badOff = tempPath("bad_index.off"), shortOff = tempPath("short.off");
  writeBytes(badOff, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  writeBytes(shortOff, "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  for (const auto& p : {garbage, garbageObj, huge, truncated, txt, badOff, shortOff}) {
    expectFails(p);
    fs::remove(p);
  }
  // Writing where no file can be created.
  const SceneFile sf = gi::scenes::openPlane(1.0, 1);
  EXPECT_THROW(gi::io::writePly("/nonexistent_dir/x.ply", sf.scene, sf.attrs, {}, {}), std::runtime_error);
  EXPECT_THROW(gi::io::writePly(tempPath("bad.ply"), sf.scene, sf.attrs, {1.f}, {}), std::runtime_error);
}

// What an earlier run left per vertex comes back: a vector attribute is
// written as NAME_x, NAME_y, NAME_z and read as the vector NAME, a scalar
// as itself, value for value (both are floats); other float and double
// vertex properties are kept by name (an ASCII "nan" as NaN, for the filter
// that reads it to judge), integer ones are not; appending keeps only what
// both parts have.
TEST(ScenesIo, PlyVertexAttributesRoundTrip) {
  const SceneFile sf = gi::scenes::byName("cornell_box");
  const auto& s = sf.scene;
  gi::io::PlyExtras extras;
  gi::VertexAttribute B{"Radiosity", 3, {}}, n{"Paths", 1, {}};
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    B.values.insert(B.values.end(), {0.1f * float(v), 1.f / float(v + 3), 7e-20f});
    n.values.push_back(float(64 * v));
  }
  extras.attributes = {B, n};
  const std::string path = tempPath("attributes.ply");
  gi::io::writePly(path, s, sf.attrs, {}, {}, extras);
  gi::io::LoadedMesh m = gi::io::loadMesh(path);
  fs::remove(path);
  ASSERT_EQ(m.attributes.size(), 2u);
  EXPECT_EQ(m.attributes[0].name, "Radiosity");
  EXPECT_EQ(m.attributes[0].components, 3);
  EXPECT_EQ(m.attributes[0].values, B.values);
  EXPECT_EQ(m.attributes[1].name, "Paths");
  EXPECT_EQ(m.attributes[1].components, 1);
  EXPECT_EQ(m.attributes[1].values, n.values);

  const auto a = gi::io::parseMesh(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property double E_x\nproperty float E_y\nproperty float quality\nproperty int flags\nproperty float E_z\n"
      "property double big\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 1 2 nan 5 3 1\n1 0 0 4 5 0.5 5 6 2\n0 1 0 7 8 2 5 9 1e300\n3 0 1 2\n",
      "ply", "a.ply");
  ASSERT_EQ(a.attributes.size(), 3u);
  EXPECT_EQ(a.attributes[0].name, "E");
  EXPECT_EQ(a.attributes[0].values, (std::vector<float>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(a.attributes[1].name, "quality");
  EXPECT_TRUE(std::isnan(a.attributes[1].values[0]));
  EXPECT_EQ(a.attributes[1].values[1], 0.5f);
  EXPECT_EQ(a.attributes[2].name, "big");
  EXPECT_TRUE(std::isnan(a.attributes[2].values[2]));  // a double beyond float's range

  gi::io::LoadedMesh both = a, other = a;
  other.attributes.resize(1);  // only E
  gi::io::appendMesh(both, other);
  ASSERT_EQ(both.attributes.size(), 1u);
  EXPECT_EQ(both.attributes[0].name, "E");
  EXPECT_EQ(both.attributes[0].values.size(), 18u);
  EXPECT_EQ(both.attributes[0].values[9], 1.f);
}

// A scene of several layers written into one PLY records them ("comment
// gi_layer COUNT NAME"), so that the next run (the CLI's two-pass view after
// its photon mapping) finds the mirror and glass layers by name again. A
// name's control characters become '_'; a file whose recorded layers no
// longer cover its faces (edited elsewhere), or holding polygons, or naming
// a single layer, is one layer named by its file.
TEST(ScenesIo, PlyRecordsItsLayers) {
  const SceneFile sf = gi::scenes::byName("cornell_box");
  const auto& s = sf.scene;
  const size_t nf = s.faceCount();
  gi::io::PlyExtras extras;
  extras.layers = {{"room.ply", nf - 12}, {"my glass\tball\n.ply", 10}, {"mirror.ply", 2}};
  const std::string path = tempPath("layers.ply");
  gi::io::writePly(path, s, sf.attrs, {}, {}, extras);
  const gi::io::LoadedMesh m = gi::io::loadMesh(path);
  ASSERT_EQ(m.layers.size(), 3u);
  EXPECT_EQ(m.layers[1].first, "my glass_ball_.ply");
  const std::vector<gi::LayerRange> layers = gi::io::meshLayers(m, "layers.ply", 5);
  ASSERT_EQ(layers.size(), 3u);
  EXPECT_EQ(layers[0].name, "room.ply");
  EXPECT_EQ(layers[0].faceOffset, 5u);
  EXPECT_EQ(layers[2].name, "mirror.ply");
  EXPECT_EQ(layers[2].faceOffset, 5 + nf - 2);
  EXPECT_EQ(layers[2].faceCount, 2u);
  gi::io::LoadedMesh both = m;
  gi::io::appendMesh(both, m);
  EXPECT_TRUE(both.layers.empty()) << "stale after an append";
  extras.layers[0].second -= 1;  // not covering the faces: ignored when written
  gi::io::writePly(path, s, sf.attrs, {}, {}, extras);
  EXPECT_TRUE(gi::io::loadMesh(path).layers.empty());
  fs::remove(path);
  const auto edited = gi::io::parseMesh(
      "ply\nformat ascii 1.0\ncomment gi_layer 1 a.ply\ncomment gi_layer 1 b.ply\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
      "ply", "edited.ply");
  EXPECT_TRUE(edited.layers.empty());
  const auto wrapped = gi::io::parseMesh(  // 2^63 + 2^63 + 1 wraps round to the one face
      "ply\nformat ascii 1.0\ncomment gi_layer 9223372036854775807 a\ncomment gi_layer 9223372036854775807 b\n"
      "comment gi_layer 3 c\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
      "ply", "wrapped.ply");
  EXPECT_TRUE(wrapped.layers.empty());
  const auto one = gi::io::meshLayers(edited, "edited.ply");
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].name, "edited.ply");
  EXPECT_EQ(one[0].faceCount, 1u);
}

TEST(ScenesIo, CommittedTestMeshesMatchTheGenerators) {
  for (const auto& name : gi::scenes::names())
  for (const auto& layer : gi::scenes::layersByName(name)) {
    const std::string path = std::string(GI_TEST_MESHES) + "/" + layer.name;
    if (!fs::exists(path)) continue;  // large ones are not committed
    SCOPED_TRACE(path);
    const SceneFile& sf = layer.file;
    const auto m = gi::io::loadMesh(path);
    EXPECT_EQ(m.scene.vertexCount(), sf.scene.vertexCount());
    EXPECT_EQ(m.scene.faceCount(), sf.scene.faceCount());
    EXPECT_EQ(m.attrs.faceQuality, sf.attrs.faceQuality);
    EXPECT_EQ(m.attrs.faceColor, sf.attrs.faceColor);
  }
}

// Result files: a round trip keeps every array bit for bit; the cache path
// depends on the filter, the scene hash and the parameters; a damaged file is
// a clear error.
TEST(ResultFile, RoundTripAndCacheKey) {
  gi::FilterResult r;
  r.vertexQuality = {0.1f, 1.f / 3.f};
  r.vertexColor = {{1, 2, 3}, {250, 251, 252}};
  r.faceQuality = {7.f};
  r.faceColor = {{9, 8, 7}};
  r.attributes.push_back({"Radiosity", 3, {1, 2, 3, 4, 5, 6.000001f}});
  r.attributes.push_back({"Paths", 1, {64, 128}});
  r.stats.add("seconds", 1.5);
  r.stats.note("a note");
  r.stats.warn("a warning");
  const gi::io::ResultKey key{"reference", "m.ply", 0x0123456789abcdefull, "samples_per_vertex=64"};
  const std::string path = ::testing::TempDir() + "roundtrip.giresult.json";
  gi::io::writeResultFile(path, key, r);
  gi::FilterResult q;
  const auto k = gi::io::readResultFile(path, q);
  EXPECT_EQ(k.sceneHash, key.sceneHash);
  EXPECT_EQ(k.parameters, key.parameters);
  EXPECT_EQ(k.filter, key.filter);
  EXPECT_EQ(q.vertexQuality, r.vertexQuality);
  EXPECT_EQ(q.faceQuality, r.faceQuality);
  ASSERT_EQ(q.vertexColor.size(), 2u);
  EXPECT_EQ(q.vertexColor[1].b, 252);
  ASSERT_NE(q.attribute("Radiosity"), nullptr);
  EXPECT_EQ(q.attribute("Radiosity")->values, r.attributes[0].values);
  EXPECT_EQ(q.attribute("Paths")->components, 1);
  EXPECT_EQ(q.stats.get("seconds"), 1.5);
  EXPECT_EQ(q.stats.warnings, r.stats.warnings);
  const auto a = gi::io::resultCachePath("d", key);
  auto other = key;
  other.sceneHash = 2;
  EXPECT_NE(a, gi::io::resultCachePath("d", other));
  other = key;
  other.parameters = "p=2";
  EXPECT_NE(a, gi::io::resultCachePath("d", other));
  other = key;
  other.filter = "photonmap";
  EXPECT_NE(a, gi::io::resultCachePath("d", other));
  EXPECT_EQ(a.rfind("d/m-reference-", 0), 0u);
  { std::ofstream(path) << "{\"format\": \"gi-result\", \"version\": 1}"; }
  EXPECT_THROW(gi::io::readResultFile(path, q), std::runtime_error);
  // The scene hash sees geometry and materials.
  auto sf = gi::scenes::openPlane(1.0, 2);
  const uint64_t h0 = gi::sceneHash(sf.scene);
  sf.scene.rho[0] = glm::vec3(0.3f);
  EXPECT_NE(gi::sceneHash(sf.scene), h0);
}
