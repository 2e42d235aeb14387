// A library caller builds Scene, RayCaster and the options structs by hand,
// past the front ends' checks: what an outside audit of the engine as a
// library did wrong on purpose. Each mistake is refused with an exception
// naming it (std::invalid_argument, std::out_of_range for an index), never a
// crash, a read past an array, NaN vertices or a silently different run.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "gi/ambient.h"
#include "gi/form_factors.h"
#include "gi/pathtrace.h"
#include "gi/photon.h"
#include "gi/radiosity.h"
#include "gi/raycaster.h"
#include "gi/scenes.h"

using namespace gi;

namespace {

// Two parallel plates, the top one emitting: every filter has light.
Scene plates() {
  auto sf = scenes::parallelPlates(1.0, 2);
  return sf.scene;
}

template <class F>
std::string refusal(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// A per-face array of another length was read past its end (a one-entry
// emission gave B = 1.3e-44 and hundreds of invalid reads under valgrind).
TEST(LibraryMisuse, PerFaceArraysOfAnotherLengthAreRefused) {
  const Scene good = plates();
  using Edit = std::function<void(Scene&)>;
  const std::vector<std::pair<const char*, Edit>> bad = {
      {"emission", [](Scene& s) { s.emission.assign(1, glm::vec3(1.f)); }},
      {"rho", [](Scene& s) { s.rho.assign(s.faceCount() + 3, glm::vec3(0.5f)); }},
      {"material", [](Scene& s) { s.material.assign(2, Material::Diffuse); }},
      {"ior", [](Scene& s) { s.ior.assign(1, 1.5f); }},
      {"roughness", [](Scene& s) { s.roughness.assign(1, 0.2f); }},
      {"leftOut", [](Scene& s) { s.leftOut.assign(1, 0); }},
  };
  for (const auto& [name, edit] : bad) {
    Scene s = good;
    edit(s);
    const std::string why = refusal([&] { makeEmbreeCaster(s); });
    EXPECT_NE(why.find(std::string("Scene::") + name), std::string::npos) << name << ": " << why;
    auto caster = makeEmbreeCaster(good);  // same face count: only the arrays differ
    EXPECT_NE(refusal([&] { solveRadiosity(s, *caster, RadiosityOptions{}); }), "") << name;
    EXPECT_NE(refusal([&] { computeAmbient(s, *caster, AmbientOptions{}); }), "") << name;
    EXPECT_NE(refusal([&] { pathTrace(s, *caster, PathTraceOptions{}); }), "") << name;
  }
}

// A caster built from another scene answered with faces this one lacks
// (radiosity vertices of 1.7e19 under AddressSanitizer).
TEST(LibraryMisuse, ACasterOfAnotherSceneIsRefused) {
  const Scene s = plates();
  const Scene other = scenes::parallelPlates(1.0, 4).scene;
  ASSERT_NE(other.faceCount(), s.faceCount());
  auto caster = makeEmbreeCaster(other);
  for (const std::string& why :
       {refusal([&] { solveRadiosity(s, *caster, RadiosityOptions{}); }),
        refusal([&] { computeAmbient(s, *caster, AmbientOptions{}); }),
        refusal([&] { pathTrace(s, *caster, PathTraceOptions{}); }),
        refusal([&] { FormFactors(s, *caster, FormFactors::Settings{}); })})
    EXPECT_NE(why.find("ray caster was built for a scene of"), std::string::npos) << why;
}

// A triangle naming a vertex that does not exist is left out as invalid
// everywhere; the form factors' set-up computed its normal first (a
// segmentation fault from solveRadiosity).
TEST(LibraryMisuse, ATriangleBeyondTheVerticesIsLeftOut) {
  Scene s = plates();
  const Scene whole = s;
  s.triangles.push_back(glm::uvec3(0, 2, 0xfffffff0u));
  if (!s.emission.empty()) s.emission.push_back(glm::vec3(0.f));
  if (!s.rho.empty()) s.rho.push_back(glm::vec3(0.5f));
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions o;
  o.vertexOutput = RadiosityVertexOutput::PatchAverage;
  const RadiosityResult r = solveRadiosity(s, *caster, o);
  auto wholeCaster = makeEmbreeCaster(whole);
  const RadiosityResult w = solveRadiosity(whole, *wholeCaster, o);
  ASSERT_EQ(r.B.size(), w.B.size() + 1);
  for (size_t f = 0; f < w.B.size(); ++f) EXPECT_EQ(r.B[f], w.B[f]) << f;
  EXPECT_EQ(r.B.back(), glm::vec3(0.f));
}

// FormFactors keeps references: temporaries do not compile; indices past the
// patches and settings without samples are refused (row 1,000,000 was a
// segmentation fault, rays_per_patch 0 a NaN escaped share, -5 a
// std::length_error).
TEST(LibraryMisuse, FormFactorsRefuseIndicesAndSettingsWithoutSamples) {
  static_assert(!std::is_constructible_v<FormFactors, Scene&&, const RayCaster&, const FormFactors::Settings&>);
  static_assert(!std::is_constructible_v<FormFactors, const Scene&, RayCaster&&, int, uint32_t>);
  const Scene s = plates();
  auto caster = makeEmbreeCaster(s);
  const FormFactors ff(s, *caster, FormFactors::Settings{});
  EXPECT_THROW(ff.row(uint32_t(s.faceCount())), std::out_of_range);
  EXPECT_THROW(ff.row(1000000u), std::out_of_range);
  EXPECT_THROW(ff.area(uint32_t(s.faceCount())), std::out_of_range);
  using Edit = std::function<void(FormFactors::Settings&)>;
  const std::vector<std::pair<const char*, Edit>> bad = {
      {"rays_per_patch", [](FormFactors::Settings& t) { t.raysPerPatch = 0; }},
      {"rays_per_patch", [](FormFactors::Settings& t) { t.raysPerPatch = -5; }},
      {"analytic_points", [](FormFactors::Settings& t) { t.method = FormFactorMethod::Analytic; t.analyticPoints = 0; }},
      {"hemicube_resolution", [](FormFactors::Settings& t) { t.method = FormFactorMethod::Hemicube; t.hemicubeResolution = 0; }},
      {"hemicube_points", [](FormFactors::Settings& t) { t.method = FormFactorMethod::Hemicube; t.hemicubePoints = -3; }},
  };
  for (const auto& [name, edit] : bad) {
    FormFactors::Settings t;
    edit(t);
    const std::string why = refusal([&] { FormFactors(s, *caster, t); });
    EXPECT_NE(why.find(name), std::string::npos) << name << ": " << why;
    RadiosityOptions o;
    o.formFactors = t;
    EXPECT_NE(refusal([&] { solveRadiosity(s, *caster, o); }).find(name), std::string::npos) << name;
  }
}

// Radiosity's options outside the table's ranges: gather_rays 0 made every
// vertex NaN, a NaN tolerance ran no sweep (the direct light alone, with a
// warning about max_iterations = -2147483648), negative counts ran as if
// valid.
TEST(LibraryMisuse, RadiosityRefusesWhatTheTableRefuses) {
  const Scene s = plates();
  auto caster = makeEmbreeCaster(s);
  using Edit = std::function<void(RadiosityOptions&)>;
  const std::vector<std::pair<const char*, Edit>> bad = {
      {"gather_rays", [](RadiosityOptions& o) { o.gatherRays = 0; }},
      {"gather_rays", [](RadiosityOptions& o) { o.gatherRays = -4; }},
      {"tolerance", [](RadiosityOptions& o) { o.tolerance = NAN; }},
      {"tolerance", [](RadiosityOptions& o) { o.tolerance = -1; }},
      {"max_iterations", [](RadiosityOptions& o) { o.maxIterations = -3; }},
      {"bounces", [](RadiosityOptions& o) { o.bounces = -5; }},
      {"light_samples", [](RadiosityOptions& o) { o.lightSamples = 0; }},
      {"link_rays", [](RadiosityOptions& o) { o.linkRays = 0; }},
      {"hierarchy_epsilon", [](RadiosityOptions& o) { o.hierarchyEpsilon = NAN; }},
      {"memory_budget_mb", [](RadiosityOptions& o) { o.memoryBudgetMB = NAN; }},
      {"sky's radiance", [](RadiosityOptions& o) { o.outside.skyRadiance = glm::vec3(NAN); }},
      {"sun's irradiance", [](RadiosityOptions& o) { o.outside.sunIrradiance = glm::vec3(-1.f); }},
      {"sun_direction", [](RadiosityOptions& o) { o.outside.sunIrradiance = glm::vec3(1.f); o.outside.sunDirection = glm::vec3(0.f, 2.f, 0.f); }},
      {"sun_angular_radius", [](RadiosityOptions& o) { o.outside.sunIrradiance = glm::vec3(1.f); o.outside.sunAngularRadiusDeg = 60.f; }},
  };
  for (const auto& [name, edit] : bad) {
    RadiosityOptions o;
    edit(o);
    const std::string why = refusal([&] { solveRadiosity(s, *caster, o); });
    EXPECT_NE(why.find(name), std::string::npos) << name << ": " << why;
  }
}

// The path tracer: a NaN sky made every vertex NaN with a standard error of
// 0; a NaN target and a depth below -1 ran.
TEST(LibraryMisuse, PathTracerRefusesWhatTheTableRefuses) {
  const Scene s = plates();
  auto caster = makeEmbreeCaster(s);
  using Edit = std::function<void(PathTraceOptions&)>;
  const std::vector<std::pair<const char*, Edit>> bad = {
      {"sky's radiance", [](PathTraceOptions& o) { o.skyRadiance = glm::vec3(NAN); }},
      {"sun's irradiance", [](PathTraceOptions& o) { o.sunIrradiance = glm::vec3(INFINITY); }},
      {"target_relative_error", [](PathTraceOptions& o) { o.targetRelativeError = NAN; }},
      {"max_depth", [](PathTraceOptions& o) { o.maxDepth = -7; }},
  };
  for (const auto& [name, edit] : bad) {
    PathTraceOptions o;
    o.samplesPerVertex = 4;
    edit(o);
    const std::string why = refusal([&] { pathTrace(s, *caster, o); });
    EXPECT_NE(why.find(name), std::string::npos) << name << ": " << why;
  }
}

// Photon mapping: gather_rays 0 gave NaN at every gathered vertex, a NaN sky
// ran. And a bound handed through single precision passes, as the front
// ends' check lets it (MeshLab's dialog holds tolerance 1e-12 as
// 9.99999996e-13).
TEST(LibraryMisuse, PhotonMapRefusesAndBoundsSurviveSinglePrecision) {
  const Scene s = plates();
  auto caster = makeEmbreeCaster(s);
  PhotonOptions o;
  o.photons = 1000;
  o.finalGather = true;
  o.gatherRays = 0;
  EXPECT_NE(refusal([&] { computePhotonMap(s, *caster, o); }).find("gather_rays"), std::string::npos);
  o.gatherRays = 4;
  o.outside.skyRadiance = glm::vec3(NAN);
  EXPECT_NE(refusal([&] { computePhotonMap(s, *caster, o); }).find("sky's radiance"), std::string::npos);
  RadiosityOptions r;
  r.tolerance = double(float(1e-12));
  ASSERT_LT(r.tolerance, 1e-12);
  r.vertexOutput = RadiosityVertexOutput::PatchAverage;
  EXPECT_EQ(refusal([&] { solveRadiosity(s, *caster, r); }), "");
}
