// Photons as a point-cloud layer (GI: Photon Mapping, photon_layer): one
// point per photon of the maps (or the cap, evenly subsampled), coloured by
// map, quality = power; the caustic points gather on the floor under the
// glass sphere of the caustic Cornell box; none with progressive photon
// mapping (a warning); and the CLI's file name beside the output.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "gi/filter_run.h"
#include "gi/filters.h"
#include "gi/scenes.h"
#include "mesh_io.h"

using namespace gi;

namespace {

// The caustic Cornell box as the CLI loads it: three files, three layers
// named by file, the light marked by face quality.
FilterInput causticInput(const std::map<std::string, std::string>& params) {
  const std::string dir = GI_TEST_MESHES;
  FilterInput in;
  io::LoadedMesh m = io::loadMesh(dir + "/caustic_cornell_box.ply");
  in.layers.push_back({"caustic_cornell_box.ply", 0, m.scene.faceCount()});
  for (const char* name : {"caustic_cornell_glass_sphere.ply", "caustic_cornell_mirror.ply"}) {
    const size_t off = m.scene.faceCount();
    io::appendMesh(m, io::loadMesh(dir + "/" + name));
    in.layers.push_back({name, off, m.scene.faceCount() - off});
  }
  m.scene.vertexNormals.clear();
  const auto specs = filterSpecs(FilterKind::PhotonMapping);
  const double diag = analyzeScene(m.scene).diagonal;
  in.values = defaultValues(specs, diag);
  std::map<std::string, std::string> p = {{"emitter_source", "1"}, {"light_samples", "16"}, {"photons", "20000"}};
  for (const auto& [k, v] : params) p[k] = v;
  for (const auto& [k, v] : p) in.values.set(k, parseValue(*findSpec(specs, k), v, diag));
  in.scene = std::move(m.scene);
  in.attrs = m.attrs;
  return in;
}

bool isCaustic(const Rgb8& c) { return c.b > c.r; }

}  // namespace

// Every photon of the two maps is a point (stats: photons_global_map and
// photons_caustic_map), blue for the caustic map, orange for the global one,
// with its power as quality. The glass sphere (radius 80 mm) focuses the
// light of the ceiling lamp to a spot on the floor on the line from the lamp
// through its centre: of the caustic points on the floor, 36% lie within
// 40 mm of that spot (seen; 0.9% of the floor's 0.31 m^2, so 22 times the
// density of an even spread; the rest is the mirror's reflection of the lamp
// and the sphere's wider halo). Asked: 20%, far outside the binomial noise
// of ~5000 floor points (standard deviation 0.7%) and 20 times what points
// spread evenly over the floor would give.
TEST(PhotonLayer, OnePointPerStoredPhotonColouredByMap) {
  FilterInput in = causticInput({{"photon_layer", "true"}});
  const FilterResult r = runFilter(FilterKind::PhotonMapping, in);
  ASSERT_EQ(r.layers.size(), 1u);
  const FilterLayer& L = r.layers[0];
  EXPECT_EQ(L.name, "Photons");
  EXPECT_TRUE(L.mesh.triangles.empty());
  const size_t n = L.mesh.vertexCount();
  const double global = r.stats.get("photons_global_map", -1), caustic = r.stats.get("photons_caustic_map", -1);
  ASSERT_GT(caustic, 100.0);
  EXPECT_EQ(double(n), global + caustic);
  EXPECT_EQ(r.stats.get("photon_layer_points"), double(n));
  ASSERT_EQ(L.color.size(), n);
  ASSERT_EQ(L.quality.size(), n);
  ASSERT_EQ(L.normals.size(), n);
  size_t blue = 0, onFloor = 0, nearFocus = 0;
  const glm::dvec3 lamp(278.0, 548.7, 279.5), c = scenes::kGlassCentre;
  const glm::dvec3 focus = lamp + (c - lamp) * (lamp.y / (lamp.y - c.y));
  for (size_t i = 0; i < n; ++i) {
    EXPECT_GT(L.quality[i], 0.f);
    if (!isCaustic(L.color[i])) continue;
    ++blue;
    const glm::dvec3 p = L.mesh.toWorld(L.mesh.positions[i]);
    if (std::abs(p.y) > 1e-2) continue;
    ++onFloor;
    nearFocus += glm::length(glm::dvec2(p.x - focus.x, p.z - focus.z)) < 40.0;
  }
  EXPECT_EQ(double(blue), caustic);
  ASSERT_GT(onFloor, 100u);
  EXPECT_GT(double(nearFocus) / double(onFloor), 0.2) << nearFocus << " of " << onFloor;
}

// Past the cap: exactly the cap's number of points, evenly from both maps,
// and a note; progressive photon mapping keeps no map: a warning, no layer.
TEST(PhotonLayer, CapAndProgressive) {
  FilterInput in = causticInput({{"photon_layer", "true"}, {"photon_layer_max", "1000"}});
  const FilterResult r = runFilter(FilterKind::PhotonMapping, in);
  ASSERT_EQ(r.layers.size(), 1u);
  EXPECT_EQ(r.layers[0].mesh.vertexCount(), 1000u);
  const double total = r.stats.get("photons_global_map") + r.stats.get("photons_caustic_map");
  size_t blue = 0;
  for (const Rgb8& c : r.layers[0].color) blue += isCaustic(c);
  // Each map keeps its share of the cap, within one point.
  EXPECT_NEAR(double(blue), 1000.0 * r.stats.get("photons_caustic_map") / total, 1.0);
  EXPECT_NE(r.logLines("x")[1].find("photon layer: 1000 of"), std::string::npos);

  FilterInput pin = causticInput({{"photon_layer", "true"}, {"progressive", "true"}, {"passes", "2"}});
  const FilterResult p = runFilter(FilterKind::PhotonMapping, pin);
  EXPECT_TRUE(p.layers.empty());
  ASSERT_FALSE(p.stats.warnings.empty());
  EXPECT_NE(p.stats.warnings.back().find("progressive"), std::string::npos);
  // Off by default: no layer.
  FilterInput off = causticInput({});
  EXPECT_TRUE(runFilter(FilterKind::PhotonMapping, off).layers.empty());
}

TEST(PhotonLayer, FileNameBesideTheOutput) {
  EXPECT_EQ(layerPath("out/result.ply", "Photons"), "out/result.Photons.ply");
  EXPECT_EQ(layerPath("a.b/result", "My layer/1"), "a.b/result.My_layer_1.ply");
}
