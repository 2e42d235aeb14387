// Faces listed twice (the same corners in the same turn) are computed once.
//
// A scan or an export that lists faces twice used to have them emit twice
// and hide each other at random: an outside audit measured the Cornell box
// with its light faces listed twice at 2.11 (radiosity), 2.02 (photon
// mapping) and 1.98 (reference) times the clean box's vertex values, and
// with its walls listed twice photon mapping at 0.73 times. The filters'
// set-up now leaves every copy out of the computation (Scene::leftOut) and
// gives it its original's values in the output. The originals keep their
// face indices and the copies come after them, so every ray, seed and
// sample of the clean box is drawn again: the values must be the clean
// box's to rounding, which is a test that fails by a factor of two on the
// old code.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "filter_input.h"
#include "gi/filter_run.h"
#include "gi/filters.h"
#include "gi/params.h"
#include "gi/scenes.h"

using namespace gi;

namespace {

// The box with `faces` listed again at the end, each with its colour and
// quality; `ownVertices`: the copies get vertices of their own at the same
// positions (a triangle soup), else they reuse the originals'.
scenes::SceneFile withCopies(const scenes::SceneFile& sf, const std::vector<size_t>& faces, bool ownVertices) {
  scenes::SceneFile out = sf;
  Scene& s = out.scene;
  MeshAttributes& a = out.attrs;
  for (size_t f : faces) {
    glm::uvec3 t = s.triangles[f];
    if (ownVertices)
      for (int k = 0; k < 3; ++k) {
        s.positions.push_back(s.positions[t[k]]);
        if (!a.vertexColor.empty()) a.vertexColor.push_back(a.vertexColor[t[k]]);
        t[k] = uint32_t(s.positions.size() - 1);
      }
    s.triangles.push_back(t);
    if (!s.rho.empty()) s.rho.push_back(s.rho[f]);
    if (!s.emission.empty()) s.emission.push_back(s.emission[f]);
    if (!a.faceColor.empty()) a.faceColor.push_back(a.faceColor[f]);
    if (!a.faceQuality.empty()) a.faceQuality.push_back(a.faceQuality[f]);
    if (!a.faceSelected.empty()) a.faceSelected.push_back(a.faceSelected[f]);
  }
  return out;
}

FilterResult run(FilterKind kind, const scenes::SceneFile& sf, const std::vector<std::pair<const char*, const char*>>& values) {
  FilterInput in = test::filterInput(kind, sf);
  const auto specs = filterSpecs(kind);
  for (const auto& [k, v] : values) in.values.set(k, parseValue(*findSpec(specs, k), v, analyzeScene(in.scene).diagonal));
  return runFilter(kind, in);
}

}  // namespace

TEST(DuplicateFaces, ComputedOnceInEveryFilter) {
  const scenes::SceneFile clean = scenes::cornellBox(100.0);
  const size_t nf = clean.scene.faceCount(), nv = clean.scene.vertexCount();
  std::vector<size_t> lights, walls;
  for (size_t f = 0; f < nf; ++f) (luminance(clean.scene.faceEmission(f)) > 0.f ? lights : walls).push_back(f);
  ASSERT_FALSE(lights.empty());
  struct Case {
    FilterKind kind;
    std::vector<std::pair<const char*, const char*>> values;
  };
  const std::vector<Case> cases = {
      {FilterKind::Radiosity, {{"rays_per_patch", "256"}, {"gather_rays", "16"}, {"face_output", "true"}}},
      {FilterKind::PhotonMapping, {{"photons", "20000"}, {"gather_rays", "16"}}},
      {FilterKind::PathTracedReference, {{"samples_per_vertex", "16"}}},
      {FilterKind::AmbientOcclusion, {{"rays_per_vertex", "32"}}},
  };
  for (const Case& c : cases) {
    const FilterResult base = run(c.kind, clean, c.values);
    ASSERT_EQ(base.vertexQuality.size(), nv);
    for (const auto& [what, faces, own] : {std::tuple{"lights, shared vertices", lights, false},
                                           std::tuple{"lights, own vertices", lights, true},
                                           std::tuple{"walls, own vertices", walls, true}}) {
      const scenes::SceneFile doubled = withCopies(clean, faces, own);
      const FilterResult r = run(c.kind, doubled, c.values);
      const std::string name = filterDesc(c.kind).cliName + ", " + what;
      ASSERT_EQ(r.vertexQuality.size(), doubled.scene.vertexCount()) << name;
      EXPECT_TRUE(r.stats.warnings.empty()) << name << ": " << r.stats.warnings.front();
      EXPECT_NE(r.setupLog.find(std::to_string(faces.size()) + " faces repeat another face's corners"), std::string::npos)
          << name << ": " << r.setupLog;
      double worst = 0.0;
      for (size_t v = 0; v < nv; ++v)
        worst = std::max(worst, std::fabs(double(r.vertexQuality[v]) - base.vertexQuality[v]) /
                                    std::max(1e-3, double(base.vertexQuality[v])));
      EXPECT_LT(worst, 1e-5) << name;
      // A copy's own vertices show their original corners' values.
      size_t copy = nv;
      for (size_t f : faces)
        for (int k = 0; own && k < 3; ++k, ++copy)
          ASSERT_EQ(r.vertexQuality[copy], r.vertexQuality[clean.scene.triangles[f][k]]) << name << ", face " << f;
      // Per-face output: each copy shows its original's value.
      if (!r.faceQuality.empty())
        for (size_t k = 0; k < faces.size(); ++k) ASSERT_EQ(r.faceQuality[nf + k], r.faceQuality[faces[k]]) << name;
    }
  }
}
