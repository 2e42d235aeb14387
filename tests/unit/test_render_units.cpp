// The ray-traced view where the scene is kept in a local unit (Scene::unit:
// scenes below 2^-10 or above 2^20 across), and the chain from a first pass
// to the view through the filters as the front ends run them: the first
// pass's direct part, and the vertex colours it leaves behind.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "gi/filter_files.h"
#include "gi/ambient.h"
#include "gi/filters.h"
#include "gi/filter_run.h"
#include "gi/render.h"
#include "render_test_helpers.h"

using namespace gi;
using gi::test::SceneBuilder;

namespace {

// A floor of reflectance 0.5 (2 x 2, 4 x 4 cells) with a small lamp above it
// facing down and a point light beside it, all scaled by s.
Scene litFloor(double s) {
  SceneBuilder b;
  b.quad({-s, -s, 0}, {s, -s, 0}, {s, s, 0}, {-s, s, 0}, glm::vec3(0.5f), glm::vec3(0.f), Material::Diffuse, 4);
  const double a = 0.1 * s, h = 0.8 * s;
  b.quad({-a, -a, h}, {-a, a, h}, {a, a, h}, {a, -a, h}, glm::vec3(0.f), glm::vec3(3.f));
  return b.build();
}

RenderOptions viewOf(double s, RenderMode mode) {
  RenderOptions o;
  o.mode = mode;
  o.samplesPerPixel = 4;
  o.camera = Camera::lookAt(glm::dvec3(0.3, -2.0, 1.5) * s, glm::dvec3(0.0), {0, 0, 1}, 40.0, 24, 24);
  o.point.position = glm::vec3(glm::dvec3(0.5, 0.2, 0.6) * s);  // relative to the scene origin, in world lengths
  o.point.intensity = glm::vec3(float(0.4 * s * s));             // I cos / r^2: the same radiance at every scale
  return o;
}

}  // namespace

// The camera and the point light are given in world coordinates; the
// scene 1e-5 and 1e7 across is traced in its own unit (2^-17 and 2^23), so
// the image must be the scale-1 image (up to float rounding of the
// positions). Before the camera's rays and the point light were mapped to
// the local unit, the small scene showed nothing and the large one the
// floor's corner.
TEST(RenderUnits, SmallAndLargeScenesGiveTheScaleOneImage) {
  for (const RenderMode mode : {RenderMode::Whitted, RenderMode::Distributed}) {
    const Scene s1 = litFloor(1.0);
    ASSERT_EQ(s1.unit, 1.0);
    const auto c1 = makeEmbreeCaster(s1);
    const Image ref = render(s1, *c1, viewOf(1.0, mode), Progress(nullptr)).image;
    ASSERT_GT(gi::test::meanLuminance(ref), 0.01);  // 0.023: the floor fills a third of the view
    for (const double s : {1e-5, 1e7}) {
      const Scene sc = litFloor(s);
      ASSERT_NE(sc.unit, 1.0) << s;
      const auto c = makeEmbreeCaster(sc);
      const Image img = render(sc, *c, viewOf(s, mode), Progress(nullptr)).image;
      ASSERT_EQ(img.px.size(), ref.px.size());
      double worst = 0;
      for (size_t p = 0; p < ref.px.size(); ++p)
        worst = std::max(worst, double(glm::length(img.px[p] - ref.px[p])) / (glm::length(ref.px[p]) + 1e-3));
      EXPECT_LT(worst, 1e-3) << "scale " << s << ", mode " << renderModeName(mode);
    }
  }
}

namespace {

// A floor (4 x 4 cells of 1 x 1) under a uniform sky of irradiance pi:
// B = rho E = 0.5029 pi, radiance rho E / pi = rho everywhere (sRGB 188).
FilterInput skyFloor(FilterKind kind) {
  SceneBuilder b;
  b.quad({-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}, glm::vec3(0.f), glm::vec3(0.f), Material::Diffuse, 4);
  FilterInput in;
  in.scene = b.build();
  in.values = defaultValues(filterSpecs(kind), 4.0 * std::sqrt(2.0));
  in.values.set("sky_irradiance", M_PI);
  in.values.set("emitter_source", kEmitterSources.index(EmitterSource::None));
  return in;
}

// The two-pass view of a first pass's attributes, looking down at the floor
// from 3 above, size x size pixels.
void twoPassFromAbove(FilterInput& in, const std::vector<VertexAttribute>& firstPass, TwoPassDiffuse diffuse,
                      int size, int samplesPerPixel) {
  in.attributes = firstPass;
  in.values.set("mode", kRenderModes.index(RenderMode::TwoPass));
  in.values.set("two_pass_diffuse", kTwoPassDiffuse.index(diffuse));
  in.values.set("camera", 1);  // Look at
  in.values.set("eye", glm::vec3(0.f, 0.f, 3.f));
  in.values.set("target", glm::vec3(0.f));
  in.values.set("width", size);
  in.values.set("height", size);
  in.values.set("samples_per_pixel", samplesPerPixel);
}

double floorRadianceInTwoPass(const std::vector<VertexAttribute>& firstPass, TwoPassDiffuse diffuse) {
  FilterInput in = skyFloor(FilterKind::RayTracedView);
  twoPassFromAbove(in, firstPass, diffuse, 16, 4);
  const FilterResult r = runFilter(FilterKind::RayTracedView, in);
  EXPECT_EQ(r.images.size(), 1u);
  return r.images.empty() ? 0.0 : gi::test::meanLuminance(r.images[0].image);
}

}  // namespace

// A first pass by radiosity under a sky, then the two-pass view under the
// same sky: its direct light is ray-traced again, so the first pass's own
// direct part must come out of the stored light, whether radiosity left it
// (RadiosityDirect) or the view estimates it (the sky and sun included).
// Before, the sky's direct light was counted twice (radiance 2 rho).
TEST(RenderUnits, TwoPassAfterRadiosityUnderASkyCountsItOnce) {
  FilterInput first = skyFloor(FilterKind::Radiosity);
  const FilterResult r = runFilter(FilterKind::Radiosity, first);
  ASSERT_NE(r.attribute("RadiosityDirect"), nullptr);
  const double rho = srgbToLinear(188.f / 255.f);
  for (const TwoPassDiffuse d : {TwoPassDiffuse::DirectIndirect, TwoPassDiffuse::Caustics}) {
    EXPECT_NEAR(floorRadianceInTwoPass(r.attributes, d), rho, 0.002 * rho) << "with RadiosityDirect";
    std::vector<VertexAttribute> withoutDirect;
    for (const VertexAttribute& a : r.attributes)
      if (a.name != "RadiosityDirect") withoutDirect.push_back(a);
    EXPECT_NEAR(floorRadianceInTwoPass(withoutDirect, d), rho, 0.002 * rho) << "estimated by the view";
  }
}

// The vertex colours a lighting filter writes display its result: the
// reflectance source 'Auto' passes them over (the constant, sRGB 188), where
// before a second run took the display's white as a reflectance of 0.999.
TEST(RenderUnits, AutoReflectancePassesOverAResultsColours) {
  FilterInput first = skyFloor(FilterKind::Radiosity);
  const FilterResult r = runFilter(FilterKind::Radiosity, first);
  ASSERT_EQ(r.vertexColor.size(), first.scene.vertexCount());
  for (const bool withResult : {true, false}) {
    FilterInput again = skyFloor(FilterKind::Radiosity);
    again.attrs.vertexColor.clear();
    for (const Rgb8& c : r.vertexColor) again.attrs.vertexColor.push_back({c.r, c.g, c.b});
    if (withResult) again.attributes = r.attributes;
    const FilterResult r2 = runFilter(FilterKind::Radiosity, again);
    EXPECT_NE(r2.setupLog.find(withResult ? "reflectance from constant" : "reflectance from vertex colour"),
              std::string::npos)
        << r2.setupLog;
    const VertexAttribute* B = r2.attribute("Radiosity");
    ASSERT_NE(B, nullptr);
    const double rho = srgbToLinear(188.f / 255.f);
    if (withResult) {
      EXPECT_NEAR(B->values[0], rho * M_PI, 0.01 * rho * M_PI);
    }
  }
}

// Ambient occlusion, obscurance and thickness paint their greys into the
// vertex colours: radiosity's 'Auto' reflectance took them as the surface's
// (AO 0 inside a closed box made every wall black; an outside audit). Their
// value left as an attribute marks the colours while they are still greys;
// AO's 'Keep colour' and 'Multiply colour' leave the surface's colours (the
// latter darkened as asked), and colours painted since the run are the
// surface's again.
TEST(RenderUnits, AutoReflectancePassesOverAmbientGreys) {
  struct Case {
    FilterKind kind;
    AOColorMapping mapping;
    const char* attribute;
  };
  for (const Case c : {Case{FilterKind::AmbientOcclusion, AOColorMapping::Grey, "AmbientOcclusion"},
                       Case{FilterKind::AmbientOcclusion, AOColorMapping::MultiplyColor, nullptr},
                       Case{FilterKind::AmbientOcclusion, AOColorMapping::KeepColor, nullptr},
                       Case{FilterKind::AmbientObscurance, AOColorMapping::Grey, "AmbientObscurance"},
                       Case{FilterKind::Thickness, AOColorMapping::Grey, "Thickness"}}) {
    FilterInput first = skyFloor(c.kind);
    first.attrs.vertexColor.assign(first.scene.vertexCount(), glm::u8vec3(30, 100, 200));
    if (c.kind == FilterKind::AmbientOcclusion) first.values.set("color_mapping", kAOColorMappings.index(c.mapping));
    const std::string what = std::string(filterDesc(c.kind).cliName) + " " + kAOColorMappings.logName(c.mapping);
    const FilterResult r = runFilter(c.kind, first);
    FilterInput again = skyFloor(FilterKind::Radiosity);
    again.attrs.vertexColor.clear();
    if (r.vertexColor.empty()) again.attrs.vertexColor = first.attrs.vertexColor;
    for (const Rgb8& col : r.vertexColor) again.attrs.vertexColor.push_back({col.r, col.g, col.b});
    again.attributes = r.attributes;
    std::string names;
    for (const VertexAttribute& a : r.attributes) names += a.name + " ";
    EXPECT_EQ(r.attribute(c.attribute ? c.attribute : "AmbientOcclusion") != nullptr, c.attribute != nullptr) << what << ": " << names;
    const FilterResult r2 = runFilter(FilterKind::Radiosity, again);
    EXPECT_NE(r2.setupLog.find(c.attribute ? "reflectance from constant" : "reflectance from vertex colour"),
              std::string::npos)
        << what << ": " << r2.setupLog;
    if (!c.attribute) continue;
    // Painted since: the marker no longer holds.
    FilterInput painted = skyFloor(FilterKind::Radiosity);
    painted.attrs.vertexColor.assign(painted.scene.vertexCount(), glm::u8vec3(30, 100, 200));
    painted.attributes = r.attributes;
    const FilterResult r3 = runFilter(FilterKind::Radiosity, painted);
    EXPECT_NE(r3.setupLog.find("reflectance from vertex colour"), std::string::npos) << what << ": " << r3.setupLog;
  }
}

// The path-traced view's error bars per pixel as a picture of their own
// (raster layer in MeshLab, NAME_stderr.png and .pfm beside the image): the
// standard error of each pixel's luminance, whose RMS is the log's
// rms_std_error; the other modes give one picture, and the file plan names
// the two error files only for path tracing.
TEST(RenderUnits, PathTracedViewGivesItsErrorBarsPerPixel) {
  FilterInput in = skyFloor(FilterKind::RayTracedView);
  in.values.set("camera", 1);  // Look at
  in.values.set("eye", glm::vec3(0.5f, -3.f, 2.f));
  in.values.set("target", glm::vec3(0.f));
  in.values.set("width", 16);
  in.values.set("height", 12);
  in.values.set("samples_per_pixel", 8);
  in.values.set("image_path", std::string("dir/view.png"));
  in.values.set("mode", kRenderModes.index(RenderMode::PathTraced));
  FilterResult r = runFilter(FilterKind::RayTracedView, in);
  ASSERT_EQ(r.images.size(), 2u);
  EXPECT_EQ(r.images[1].path, "dir/view_stderr.png");
  double sum2 = 0;
  for (const glm::vec3& p : r.images[1].image.px) sum2 += double(p.r) * p.r;
  const double rms = std::sqrt(sum2 / double(r.images[1].image.px.size()));
  EXPECT_GT(rms, 0.0);
  EXPECT_NEAR(rms, r.stats.get("rms_std_error"), 1e-6 * rms);
  const FilterFiles plan = filterFiles(FilterKind::RayTracedView, in.values);
  auto planned = [&](const std::string& path) {
    for (const NamedFile& w : plan.writes)
      if (w.path == path) return true;
    return false;
  };
  EXPECT_TRUE(planned("dir/view_stderr.png") && planned("dir/view_stderr.pfm"));
  in = skyFloor(FilterKind::RayTracedView);
  in.values.set("width", 16);
  in.values.set("height", 12);
  in.values.set("image_path", std::string("dir/view.png"));
  EXPECT_EQ(runFilter(FilterKind::RayTracedView, in).images.size(), 1u);  // distributed
  EXPECT_EQ(filterFiles(FilterKind::RayTracedView, in.values).writes.size(), 2u);  // the PNG and the PFM
}

// A view of another mode written to a name a path-traced view used before
// removes that view's NAME_stderr.png and .pfm (they stayed beside the new
// image, error bars of another picture; an outside audit) and says so; a
// path-traced view writes its own over them.
TEST(RenderUnits, ErrorImagesOfAnEarlierPathTracedViewAreRemoved) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("gi_stale_stderr_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string png = (dir / "view.png").string(), errPng = (dir / "view_stderr.png").string(),
                    errPfm = (dir / "view_stderr.pfm").string();
  auto run = [&](RenderMode mode) {
    FilterInput in = skyFloor(FilterKind::RayTracedView);
    in.values.set("width", 8);
    in.values.set("height", 6);
    in.values.set("samples_per_pixel", 4);
    in.values.set("image_path", png);
    in.values.set("mode", kRenderModes.index(mode));
    FilterResult r = runFilter(FilterKind::RayTracedView, in);
    writeOutputFiles(r);
    return r;
  };
  run(RenderMode::PathTraced);
  ASSERT_TRUE(fs::exists(errPng) && fs::exists(errPfm));
  for (RenderMode m : {RenderMode::Whitted, RenderMode::Distributed}) {
    const FilterResult r = run(m);
    EXPECT_TRUE(fs::exists(png));
    EXPECT_FALSE(fs::exists(errPng) || fs::exists(errPfm)) << renderModeName(m);
    bool said = false;
    for (const std::string& n : r.stats.notes) said |= n.find("the error bars of an earlier path-traced view") != std::string::npos;
    EXPECT_TRUE(said) << renderModeName(m);
    run(RenderMode::PathTraced);
    EXPECT_TRUE(fs::exists(errPng) && fs::exists(errPfm));
  }
  // With none there, nothing is said.
  fs::remove(errPng), fs::remove(errPfm);
  const FilterResult r = run(RenderMode::Whitted);
  for (const std::string& n : r.stats.notes) EXPECT_EQ(n.find("earlier path-traced"), std::string::npos) << n;
  fs::remove_all(dir);
}

// The two-pass view takes the first pass's caustics out of its stored light
// (to add the caustic map's) only where the first pass holds caustics. The
// parameter first_pass_caustics defaulted to yes, so after radiosity (no
// caustics) the caustics were taken out of light that never held them (an
// outside audit, 5 December 2026). Now the lighting filters say it with the
// attribute RadiosityCaustics (radiosity 0, photon mapping and the
// reference 1), which the view follows, with a note when it overrides the
// parameter. A floor under the sky and a lamp with a glass block between,
// so the caustic map holds photons.
TEST(RenderUnits, TwoPassTakesOutOnlyCausticsTheFirstPassHolds) {
  auto withGlass = [](FilterKind kind) {
    FilterInput in = skyFloor(kind);
    SceneBuilder b;
    b.quad({-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}, glm::vec3(0.f), glm::vec3(0.f), Material::Diffuse, 4);
    b.quad({-0.3, -0.3, 3}, {-0.3, 0.3, 3}, {0.3, 0.3, 3}, {0.3, -0.3, 3}, glm::vec3(0.f), glm::vec3(0.f),
           Material::Diffuse, 1);  // the lamp, facing down
    const size_t floorFaces = 34;
    b.box({-0.5, -0.5, 1.0}, {0.5, 0.5, 1.5}, glm::vec3(1.f), glm::vec3(0.f), Material::Glass, false);
    in.scene = b.build();
    in.layers.push_back({"floor", 0, floorFaces});
    in.layers.push_back({"glass", floorFaces, in.scene.faceCount() - floorFaces});  // glass_layers '*glass*'
    in.attrs.faceSelected.assign(in.scene.faceCount(), 0);
    in.attrs.faceSelected[32] = in.attrs.faceSelected[33] = 1;
    in.values.set("emitter_source", kEmitterSources.index(EmitterSource::SelectedFaces));
    return in;
  };
  for (const FilterKind first : {FilterKind::Radiosity, FilterKind::PhotonMapping}) {
    FilterInput in = withGlass(first);
    if (first == FilterKind::PhotonMapping) in.values.set("photons", 20000);
    const FilterResult r = runFilter(first, in);
    const VertexAttribute* c = r.attribute("RadiosityCaustics");
    ASSERT_NE(c, nullptr);
    ASSERT_EQ(c->values.size(), in.scene.vertexCount());
    const bool holds = first == FilterKind::PhotonMapping;
    EXPECT_EQ(c->values[0], holds ? 1.f : 0.f);
    FilterInput view = withGlass(FilterKind::RayTracedView);
    twoPassFromAbove(view, r.attributes, TwoPassDiffuse::Caustics, 8, 1);
    view.values.set("caustic_photons", 20000);
    for (const bool parameter : {true, false}) {
      view.values.set("first_pass_caustics", parameter);
      const FilterResult v = runFilter(FilterKind::RayTracedView, view);
      const std::string line = v.stats.line("view");
      EXPECT_GT(v.stats.get("caustic_photons_stored"), 0.0) << line;
      EXPECT_EQ(line.find("the first pass's caustics replaced") != std::string::npos, holds) << line;
      EXPECT_EQ(line.find("RadiosityCaustics attribute") != std::string::npos, parameter != holds) << line;
    }
    // A flag that is neither 0 nor 1 anywhere (NaN, -5, 1e30) was read as
    // "no caustics" in silence (an outside audit): refused, naming it.
    for (const float bad : {std::nanf(""), -5.f, 1e30f, 0.5f}) {
      FilterInput damaged = view;
      for (VertexAttribute& a : damaged.attributes)
        if (a.name == "RadiosityCaustics") a.values[1] = bad;
      try {
        runFilter(FilterKind::RayTracedView, damaged);
        ADD_FAILURE() << bad << " was taken";
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("RadiosityCaustics attribute is neither 0 nor 1 at 1 vertices"),
                  std::string::npos) << e.what();
      }
    }
  }
}
