// Parameters a setting does not use (ParamSpec::usedWhen): not range-checked
// there, in the table's validation or in the filters' own checks, and named
// as such in the help. A .mlx script carries every parameter with absolute
// distances, so one written for a 2 m room (a caustic gather radius of
// 0.17) refused a 1 cm part in the distributed mode, which has no caustic
// map (an outside audit).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "filter_input.h"
#include "gi/filters.h"
#include "gi/params.h"
#include "gi/radiosity.h"
#include "gi/render.h"
#include "gi/scene_setup.h"

namespace {

using namespace gi;

// v with every setting of p's usedWhen turned to one that does not use p
// (the first choice outside each list; a Bool's other value); false if
// there is none.
bool disableUse(const std::vector<ParamSpec>& specs, const ParamSpec& p, ParamValues& v) {
  if (p.usedWhen.empty()) return false;
  const ParamUse& u = p.usedWhen[0];
  const ParamSpec* c = findSpec(specs, u.param);
  if (!c) return false;
  const int n = c->type == ParamType::Bool ? 2 : int(c->choices.size());
  for (int x = 0; x < n; ++x)
    if (std::find(u.values.begin(), u.values.end(), x) == u.values.end()) {
      if (c->type == ParamType::Bool) v.set(u.param, x != 0);
      else v.set(u.param, x);
      return true;
    }
  return false;
}

// Every number with a usedWhen, in every filter: far outside its range (or
// NaN) it passes validation where the settings do not use it, and is
// refused where they do.
TEST(ParamsUsed, ANumberIsCheckedOnlyWhereItIsUsed) {
  const double diag = 2.0;
  int checked = 0;
  for (const FilterDesc& d : allFilters()) {
    const std::vector<ParamSpec> specs = filterSpecs(d.kind);
    for (const ParamSpec& p : specs) {
      if (p.usedWhen.empty()) continue;
      EXPECT_NE(usedWhenText(specs, p, false), "") << p.name;
      if (p.type != ParamType::Int && p.type != ParamType::Float && p.type != ParamType::Distance) continue;
      ParamValues off = defaultValues(specs, diag);
      ASSERT_TRUE(disableUse(specs, p, off)) << d.cliName << " " << p.name;
      ASSERT_FALSE(isUsed(specs, p, off)) << d.cliName << " " << p.name;
      ParamValues on = defaultValues(specs, diag);
      for (const ParamUse& u : p.usedWhen) {
        const ParamSpec* c = findSpec(specs, u.param);
        if (c->type == ParamType::Bool) on.set(u.param, u.values[0] != 0);
        else on.set(u.param, u.values[0]);
      }
      ASSERT_TRUE(isUsed(specs, p, on)) << d.cliName << " " << p.name;
      std::vector<ParamValue> bad;
      if (p.type == ParamType::Int) bad = {int(p.min) - 1};
      else if (p.type == ParamType::Float) bad = {p.max + 1e3 * (1.0 + std::fabs(p.max)), std::nan("")};
      else bad = {p.max * diag * 20.0 + 1.0, std::nan(""), -1.0};
      if (p.type == ParamType::Int && p.max < 2147483647.0) bad.push_back(int(p.max) + 1);
      for (const ParamValue& x : bad) {
        off.set(p.name, x);
        on.set(p.name, x);
        EXPECT_FALSE(validate(specs, off, diag).has_value()) << d.cliName << " " << p.name << ": "
                                                              << *validate(specs, off, diag);
        const auto refused = validate(specs, on, diag);
        EXPECT_TRUE(refused && refused->find("'" + p.name + "'") != std::string::npos) << d.cliName << " " << p.name;
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 30);  // render, photon mapping, radiosity, AO and obscurance
}

TEST(ParamsUsed, HelpNamesTheSettings) {
  const std::vector<ParamSpec> specs = filterSpecs(FilterKind::RayTracedView);
  const ParamSpec* r = findSpec(specs, "caustic_max_radius");
  ASSERT_TRUE(r);
  EXPECT_EQ(usedWhenText(specs, *r, false),
            "used only when mode is Two-pass and two_pass_diffuse is Direct + caustic map + stored indirect or "
            "Direct + caustic map + final gather");
  EXPECT_EQ(usedWhenText(specs, *findSpec(specs, "whitted_min_weight"), true),
            "used only when 'Rendering method' is 'Whitted'");
  EXPECT_EQ(usedWhenText(specs, *findSpec(specs, "width"), true), "");
  const std::vector<ParamSpec> pm = filterSpecs(FilterKind::PhotonMapping);
  EXPECT_EQ(usedWhenText(pm, *findSpec(pm, "passes"), false), "used only when progressive is on");
}

// The filters run with such values: the script of a big room on the Cornell
// box's scale, every unused number out of its range.
TEST(ParamsUsed, FiltersRunWithUnusedValuesOutOfRange) {
  const scenes::SceneFile box = scenes::cornellBox(200.0);
  const double diag = analyzeScene(box.scene).diagonal;
  {
    FilterInput in = test::filterInput(FilterKind::RayTracedView, box);
    in.values.set("mode", kRenderModes.index(RenderMode::Distributed));
    in.values.set("width", 16);
    in.values.set("height", 12);
    in.values.set("samples_per_pixel", 1);
    in.values.set("image_path", std::string());
    in.values.set("vertex_radiance", true);
    in.values.set("caustic_max_radius", 20.0 * diag);
    in.values.set("caustic_photons", 0);
    in.values.set("gather_rays", 0);
    in.values.set("whitted_min_weight", std::nan(""));
    in.values.set("max_diffuse_bounces", -7);
    const FilterResult r = runFilter(FilterKind::RayTracedView, in);
    ASSERT_FALSE(r.attributes.empty());
    // The same values in the mode that reads them: refused, by name.
    in.values.set("mode", kRenderModes.index(RenderMode::Whitted));
    try {
      runFilter(FilterKind::RayTracedView, in);
      ADD_FAILURE() << "whitted_min_weight NaN taken in the Whitted mode";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("whitted_min_weight"), std::string::npos) << e.what();
    }
  }
  {
    FilterInput in = test::filterInput(FilterKind::Radiosity, box);
    in.values.set("solver", kRadiositySolvers.index(RadiositySolver::GaussSeidel));
    in.values.set("vertex_output", kRadiosityVertexOutputs.index(RadiosityVertexOutput::PatchAverage));
    in.values.set("hierarchy_epsilon", std::nan(""));
    in.values.set("link_rays", 0);
    in.values.set("max_links", -1);
    in.values.set("gather_rays", 0);
    in.values.set("gather_share_rings", 99);
    const FilterResult r = runFilter(FilterKind::Radiosity, in);
    EXPECT_FALSE(r.attributes.empty());
  }
  {
    FilterInput in = test::filterInput(FilterKind::AmbientOcclusion, box);
    in.values.set("rays_per_vertex", 16);
    in.values.set("share_normal_angle", std::nan(""));
    in.values.set("share_rings", 0);
    in.values.set("cone_angle", 0.0);
    EXPECT_NO_THROW(runFilter(FilterKind::AmbientOcclusion, in));
  }
  {
    FilterInput in = test::filterInput(FilterKind::PhotonMapping, box);
    in.values.set("photons", 2000);
    in.values.set("passes", 0);
    EXPECT_NO_THROW(runFilter(FilterKind::PhotonMapping, in));
  }
}

}  // namespace
