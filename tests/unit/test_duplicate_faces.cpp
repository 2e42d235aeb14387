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
// old code. The copies' own vertices are not said to be isolated or to have
// got 0 (an outside audit).
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
      {FilterKind::SkyLighting, {{"rays_per_vertex", "32"}}},
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
      // The copies' own vertices are neither isolated nor "got 0" (they were
      // said to be both while they showed their originals' values).
      EXPECT_EQ(r.report.isolatedVertices, 0u) << name;
      for (const std::string& note : r.stats.notes) EXPECT_EQ(note.find("got 0"), std::string::npos) << name << ": " << note;
      // A copy's own vertices show their original corners' values.
      size_t copy = nv;
      for (size_t f : faces)
        for (int k = 0; own && k < 3; ++k, ++copy)
          ASSERT_EQ(r.vertexQuality[copy], r.vertexQuality[clean.scene.triangles[f][k]]) << name << ", face " << f;
      // Per-face output: each copy shows its original's value.
      if (!r.faceQuality.empty()) {
        for (size_t k = 0; k < faces.size(); ++k) ASSERT_EQ(r.faceQuality[nf + k], r.faceQuality[faces[k]]) << name;
      }
    }
  }
}

// Thickness of a solid box with faces listed again on vertices of their own:
// the same values, and the copies' vertices neither isolated nor "got 0".
TEST(DuplicateFaces, ThicknessOfASolidWithCopies) {
  const scenes::SceneFile clean = scenes::closedBox(1.0, 3, false);
  const std::vector<std::pair<const char*, const char*>> values = {{"rays_per_vertex", "16"}};
  const FilterResult base = run(FilterKind::Thickness, clean, values);
  const scenes::SceneFile doubled = withCopies(clean, {0, 1, 2, 7}, true);
  const FilterResult r = run(FilterKind::Thickness, doubled, values);
  ASSERT_EQ(r.vertexQuality.size(), doubled.scene.vertexCount());
  for (size_t v = 0; v < clean.scene.vertexCount(); ++v) EXPECT_EQ(r.vertexQuality[v], base.vertexQuality[v]) << v;
  EXPECT_EQ(r.report.isolatedVertices, 0u);
  for (const std::string& note : r.stats.notes) EXPECT_EQ(note.find("got 0"), std::string::npos) << note;
  EXPECT_TRUE(r.stats.warnings.empty()) << r.stats.warnings.front();
}

// The face kept of a group is the one that emits (or is not diffuse), not
// the first: a light given as faces of its own over the ceiling's (a layer
// after the room's) is the light (an outside review: the room's faces came
// first, the light's were left out, and the scene had no emitter).
TEST(DuplicateFaces, TheLightIsKeptOverTheSurfaceItCovers) {
  const scenes::SceneFile clean = scenes::cornellBox(100.0);
  const size_t nv = clean.scene.vertexCount();
  std::vector<size_t> lights;
  for (size_t f = 0; f < clean.scene.faceCount(); ++f)
    if (luminance(clean.scene.faceEmission(f)) > 0.f) lights.push_back(f);
  ASSERT_FALSE(clean.attrs.faceQuality.empty());
  // The copies (own vertices) emit; the faces they cover do not.
  scenes::SceneFile panel = withCopies(clean, lights, true);
  for (size_t f : lights) panel.attrs.faceQuality[f] = 0.f;
  const std::vector<std::pair<const char*, const char*>> values = {{"rays_per_patch", "256"}, {"gather_rays", "16"}};
  const FilterResult base = run(FilterKind::Radiosity, clean, values), r = run(FilterKind::Radiosity, panel, values);
  // Away from the light's own corners (a separate sheet now: its border
  // vertices belong to the ceiling alone) the same values; the light's
  // samples are drawn on other faces (other seeds), the mean must agree to
  // the sampling noise.
  std::vector<uint8_t> onLight(nv, 0);
  for (size_t f : lights)
    for (int k = 0; k < 3; ++k) onLight[clean.scene.triangles[f][k]] = 1;
  double sumA = 0, sumB = 0, worst = 0;
  for (size_t v = 0; v < nv; ++v) {
    if (onLight[v]) continue;
    sumA += base.vertexQuality[v], sumB += r.vertexQuality[v];
    worst = std::max(worst, std::fabs(double(r.vertexQuality[v]) - base.vertexQuality[v]) /
                                std::max(1e-3, double(base.vertexQuality[v])));
  }
  EXPECT_NEAR(sumB / sumA, 1.0, 0.002);
  EXPECT_LT(worst, 0.02);  // before: no emitter at all
  EXPECT_NEAR(r.stats.get("emitted_power_W"), base.stats.get("emitted_power_W"), 1e-6 * base.stats.get("emitted_power_W"));
}

// With refinement the copies are never split nor counted against the
// patch budget; their own vertices show their originals' values, and each
// copy's face the area-weighted mean of the faces its original became.
TEST(DuplicateFaces, RefinementLeavesTheCopiesWhole) {
  const scenes::SceneFile clean = scenes::cornellBox(100.0);
  const size_t nv = clean.scene.vertexCount(), nf = clean.scene.faceCount();
  std::vector<size_t> lights;
  for (size_t f = 0; f < nf; ++f)
    if (luminance(clean.scene.faceEmission(f)) > 0.f) lights.push_back(f);
  const std::vector<std::pair<const char*, const char*>> values = {
      {"rays_per_patch", "256"}, {"gather_rays", "16"}, {"refine", "true"}, {"refine_max_depth", "1"},
      {"refine_max_patches", "2000"}, {"face_output", "true"}};
  const FilterResult base = run(FilterKind::Radiosity, clean, values);
  for (bool own : {false, true}) {
    const scenes::SceneFile doubled = withCopies(clean, lights, own);
    const FilterResult r = run(FilterKind::Radiosity, doubled, values);
    ASSERT_TRUE(base.refined && r.refined);
    // The same patches: the copies add none and none of theirs is split.
    EXPECT_EQ(r.refined->scene.faceCount(), base.refined->scene.faceCount() + lights.size()) << own;
    for (size_t v = 0; v < nv; ++v) ASSERT_EQ(r.vertexQuality[v], base.vertexQuality[v]) << own << ", vertex " << v;
    size_t copy = nv;
    for (size_t f : lights)
      for (int k = 0; own && k < 3; ++k, ++copy)
        ASSERT_EQ(r.vertexQuality[copy], r.vertexQuality[clean.scene.triangles[f][k]]) << "face " << f;
    // Each copy's face: the mean of its original's refined faces.
    const RefinedMesh& m = *r.refined;
    for (size_t k = 0; k < lights.size(); ++k) {
      double a = 0, q = 0;
      size_t at = m.sourceFace.size();
      for (size_t f = 0; f < m.sourceFace.size(); ++f) {
        if (m.sourceFace[f] == lights[k]) a += faceArea(m.scene, f), q += faceArea(m.scene, f) * r.faceQuality[f];
        if (m.sourceFace[f] == nf + k) at = f;
      }
      ASSERT_LT(at, m.sourceFace.size());
      EXPECT_NEAR(r.faceQuality[at], q / a, 1e-4 * q / a) << own << ", light face " << lights[k];
    }
  }
}

// A copy chosen for the form factors or the hemicube stands for its
// original (it was refused as degenerate).
TEST(DuplicateFaces, AChosenCopyStandsForItsOriginal) {
  const scenes::SceneFile clean = scenes::cornellBox(100.0);
  const size_t nf = clean.scene.faceCount();
  const scenes::SceneFile doubled = withCopies(clean, {7}, true);
  for (FilterKind kind : {FilterKind::FormFactorsOfFace, FilterKind::HemicubeOfFace}) {
    const FilterResult a = run(kind, doubled, {{"face_index", "7"}});
    const FilterResult b = run(kind, doubled, {{"face_index", std::to_string(nf).c_str()}});
    ASSERT_EQ(a.faceQuality.size(), b.faceQuality.size());
    for (size_t f = 0; f < a.faceQuality.size(); ++f) ASSERT_EQ(a.faceQuality[f], b.faceQuality[f]) << f;
  }
}
