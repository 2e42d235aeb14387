// Scenes of any size: a closed box 1e-20 to 6e38 across (coordinates up to
// +-3e38, near the float limit) gives the answers of the unit box in every
// algorithm. Such scenes used to abort in Embree (NaN rays), let all the light
// escape a closed box (radiosity: NaN at every vertex) or see an open sky in
// it (AO = 1); they are now computed in local units (Scene::unit), and the
// parameters with units (distances, a point light) are converted.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gi/ambient.h"
#include "gi/color.h"
#include "gi/filter_run.h"
#include "gi/form_factors.h"
#include "gi/pathtrace.h"
#include "gi/photon.h"
#include "gi/radiosity.h"
#include "gi/refine.h"
#include "gi/scenes.h"
#include "filter_input.h"
#include "test_helpers.h"

using namespace gi;

namespace {

const double kScales[] = {1e-20, 1e-12, 1e-10, 1.0, 1e20, 1e38, 6e38};

// The inward unit box (3 x 3 patches a side) scaled by k about the origin:
// uniform rho and emission E = 1, so B = 1 / (1 - rho) everywhere (furnace).
Scene box(double k, float rho) {
  auto sf = scenes::closedBox(1.0, 3, true);
  scenes::setUniform(sf, glm::vec3(rho), glm::vec3(1.f));
  return test::transformed(sf.scene, k, glm::dvec3(0.0));
}

bool allFinite(const std::vector<glm::vec3>& v) {
  for (const auto& x : v)
    if (!std::isfinite(x.r) || !std::isfinite(x.g) || !std::isfinite(x.b)) return false;
  return true;
}

}  // namespace

TEST(Scales, FramesArePowersOfTwoAndRoundTrip) {
  for (double k : kScales) {
    const Scene s = box(k, 0.5f);
    int e = 0;
    EXPECT_EQ(std::frexp(s.unit, &e), 0.5) << k;  // a power of two
    if (k == 1.0) {
      EXPECT_EQ(s.unit, 1.0);
    }
    for (const auto& p : s.positions) EXPECT_LE(std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}), 1.f) << k;
    const SceneReport r = analyzeScene(s);
    EXPECT_NEAR(r.diagonal / (k * std::sqrt(3.0)), 1.0, 1e-6) << k;          // world units
    EXPECT_NEAR(r.emittedPower / (6.0 * k * k), 1.0, 1e-5) << k;             // 6 k^2 of area, E = 1
    EXPECT_NEAR(r.bboxMax.x / (0.5 * k), 1.0, 1e-6) << k;
    EXPECT_EQ(r.usableFaces(), s.faceCount()) << k;
  }
}

// Appending keeps world positions and picks the union's unit.
TEST(Scales, AppendAcrossUnits) {
  const Scene tiny = box(1e-20, 0.5f), unitBox = box(1.0, 0.5f), huge = box(1e20, 0.5f);
  Scene a;  // empty: takes the first part's frame
  a.append(tiny);
  EXPECT_EQ(a.unit, tiny.unit);
  EXPECT_EQ(a.positions, tiny.positions);
  a.append(huge);  // the union is 1e20 across: what was here is rescaled
  EXPECT_EQ(a.unit, huge.unit);
  for (size_t i = 0; i < tiny.vertexCount(); ++i) {
    const glm::dvec3 w = a.toWorld(a.positions[i]), w0 = tiny.toWorld(tiny.positions[i]);
    EXPECT_LE(glm::length(w - w0), 1e-6 * 1e20) << i;  // float resolution of the 1e20 frame
  }
  for (size_t i = 0; i < huge.vertexCount(); ++i) {
    const glm::dvec3 w = a.toWorld(a.positions[tiny.vertexCount() + i]), w0 = huge.toWorld(huge.positions[i]);
    EXPECT_LE(glm::length(w - w0), 1e-6 * glm::length(w0)) << i;
  }
  Scene b = unitBox;
  b.append(tiny);  // a speck inside the unit box: the unit stays 1
  EXPECT_EQ(b.unit, 1.0);
}

// AO inside a closed box is 0 at every scale, with rays cast (infinite
// reach) and with a reach of twice the box (a world distance, converted to
// local units: unconverted, 2e-20 would be no reach at all at 1e-20). With a
// reach of 0.3 box sizes the corners see walls and the face centres do not:
// the values match the unit box's (same rays up to float rounding of the
// scaled positions: rms 1e-3).
TEST(Scales, AmbientOcclusionInsideAClosedBox) {
  auto run = [](const Scene& s, double reach) {
    auto caster = makeEmbreeCaster(s);
    AmbientOptions o;
    o.raysPerVertex = 64;
    o.maxDistance = reach;
    return computeAmbient(s, *caster, o);
  };
  const AmbientResult base = run(box(1.0, 0.5f), 0.3);
  double sum = 0;
  for (float v : base.value) sum += v;
  ASSERT_GT(sum / base.value.size(), 0.2);  // the reach-limited case is not all 0 or all 1
  ASSERT_LT(sum / base.value.size(), 0.8);
  for (double k : kScales) {
    const Scene s = box(k, 0.5f);
    for (double reach : {0.0, 2.0 * k}) {
      const AmbientResult r = run(s, reach);
      for (size_t i = 0; i < r.value.size(); ++i) ASSERT_EQ(r.value[i], 0.f) << "scale " << k << " reach " << reach;
      EXPECT_EQ(r.stats.get("rays"), 64.0 * s.vertexCount()) << k;
    }
    EXPECT_LT(test::rms(run(s, 0.3 * k).value, base.value), 1e-3) << k;
  }
}

// Radiosity furnace, rho = 0.5: B = 2 at every patch and vertex (the
// analytic form factors of a closed box sum to 1 up to 1e-3; tolerance 1%),
// no energy escapes, and the energy statistics are in world units (W:
// emitted power = 6 k^2).
TEST(Scales, RadiosityFurnace) {
  for (double k : kScales) {
    const Scene s = box(k, 0.5f);
    auto caster = makeEmbreeCaster(s);
    RadiosityOptions o;
    o.formFactors.method = FormFactorMethod::Analytic;
    o.gatherRays = 64;
    const RadiosityResult r = solveRadiosity(s, *caster, o);
    ASSERT_TRUE(allFinite(r.B) && allFinite(r.Bvertex)) << k;
    for (const auto& b : r.B) EXPECT_NEAR(b.g, 2.0, 0.02) << k;
    for (const auto& b : r.Bvertex) EXPECT_NEAR(b.g, 2.0, 0.02) << k;
    EXPECT_NEAR(r.stats.get("emitted_power_W") / (6.0 * k * k), 1.0, 1e-5) << k;
    EXPECT_LT(std::fabs(r.stats.get("escaped_power_W")) / r.stats.get("emitted_power_W"), 0.01) << k;
  }
}

// Adaptive refinement at the extremes: the refined mesh keeps the frame and
// its vertices stay on the box (world coordinates within its bbox).
TEST(Scales, RefinementKeepsTheFrame) {
  for (double k : {1e-20, 1e38}) {
    const Scene s = box(k, 0.5f);
    RadiosityOptions o;
    o.refine = true;
    o.refinement.maxDepth = 1;
    o.refinement.threshold = 1e-4;  // refine whatever differs at all
    o.vertexOutput = RadiosityVertexOutput::PatchAverage;
    const AdaptiveRadiosity a = solveRadiosityAdaptive(s, o);
    EXPECT_EQ(a.mesh.scene.unit, s.unit);
    EXPECT_EQ(a.mesh.scene.origin, s.origin);
    ASSERT_TRUE(allFinite(a.result.B)) << k;
    for (const auto& p : a.mesh.scene.positions) {
      const glm::dvec3 w = a.mesh.scene.toWorld(p);
      EXPECT_LE(std::max({std::fabs(w.x), std::fabs(w.y), std::fabs(w.z)}), 0.5 * k * (1 + 1e-6)) << k;
    }
  }
}

// The path-traced reference: B = 2 within 4 standard errors of the mean over
// the vertices + 0.5% (the truncation at max_depth 1000 is 0.5^1000).
TEST(Scales, ReferenceFurnace) {
  for (double k : kScales) {
    const Scene s = box(k, 0.5f);
    auto caster = makeEmbreeCaster(s);
    PathTraceOptions o;
    o.samplesPerVertex = 16;
    const PathTraceResult r = pathTrace(s, *caster, o);
    ASSERT_TRUE(allFinite(r.B)) << k;
    double sum = 0, var = 0;
    for (size_t i = 0; i < r.B.size(); ++i) { sum += r.B[i].g; var += double(r.stdError[i]) * r.stdError[i]; }
    const double n = double(r.B.size());
    EXPECT_NEAR(sum / n, 2.0, 4 * std::sqrt(var) / n + 0.01) << k;
  }
}

// Photon mapping (direct light apart, k-nearest estimates): the same value
// at every scale as in the unit box (the same photons up to float rounding
// of the scaled positions: mean within 0.2%), finite everywhere, and near
// the furnace value (the k-nearest estimate dims the corners and edges of a
// box of 3 x 3 patches, where its disk reaches past the crease: the mean is
// 1.79, 10% low; accepted within 15%).
TEST(Scales, PhotonMapFurnace) {
  auto run = [](const Scene& s) {
    auto caster = makeEmbreeCaster(s);
    PhotonOptions o;
    o.photons = 20000;
    o.lightSamples = 64;
    return computePhotonMap(s, *caster, o);
  };
  auto mean = [](const std::vector<glm::vec3>& B) {
    double m = 0;
    for (const auto& b : B) m += b.g;
    return m / double(B.size());
  };
  const double base = mean(run(box(1.0, 0.5f)).B);
  EXPECT_NEAR(base, 2.0, 0.3);
  for (double k : kScales) {
    const VertexRadiometry r = run(box(k, 0.5f));
    ASSERT_TRUE(allFinite(r.B)) << k;
    EXPECT_NEAR(mean(r.B), base, 0.002 * base) << k;
    EXPECT_NEAR(r.stats.get("emitted_power_W") / (6.0 * k * k), 1.0, 1e-5) << k;
  }
}

// Form factors of a face of the closed box sum to 1 with nothing lost, for
// all three methods (Monte Carlo: every ray lands; analytic: exact per
// point, 1e-3 of quadrature; hemicube at resolution 64: cells along the
// edges shared with the neighbouring walls can show no patch, 0.36% here).
TEST(Scales, FormFactorRowsSumToOne) {
  for (double k : kScales) {
    const Scene s = box(k, 0.5f);
    auto caster = makeEmbreeCaster(s);
    for (auto m : {FormFactorMethod::MonteCarlo, FormFactorMethod::Analytic, FormFactorMethod::Hemicube}) {
      FormFactors::Settings set;
      set.method = m;
      set.hemicubeResolution = 64;
      const FormFactorReport rep = formFactorsOfFace(s, *caster, set, 4);
      const double tol = m == FormFactorMethod::Hemicube ? 5e-3 : 2e-3;
      EXPECT_NEAR(rep.rowSum, 1.0, tol) << k << " method " << int(m);
      EXPECT_LT(rep.escaped, tol) << k << " method " << int(m);
    }
  }
}

// A point light's irradiance I cos / r^2 is not scale-invariant: with the
// plane and the light scaled by k and I by k^2 (world units, W/sr), H stays
// that of the unit scene, exactly (delta light, one shadow ray): in the
// reference and in photon mapping's direct light.
TEST(Scales, PointLightUnits) {
  for (double k : {1e-15, 1e-6, 1.0, 1e6, 1e15}) {
    auto sf = scenes::openPlane(2.0, 4);
    sf.scene.rho.assign(sf.scene.faceCount(), glm::vec3(0.f));
    sf.scene.emission.clear();
    const Scene s = test::transformed(sf.scene, k, glm::dvec3(0.0));
    if (k != 1.0) {
      ASSERT_NE(s.unit, 1.0) << k;  // the conversion is exercised
    }
    const glm::dvec3 P = glm::dvec3(0.3, -0.2, 1.5) * k;
    PointLight L;
    L.position = glm::vec3(P - s.origin);
    L.intensity = glm::vec3(float(2.0 * k * k));
    auto caster = makeEmbreeCaster(s);
    PathTraceOptions po;
    po.samplesPerVertex = 2;
    po.point = L;
    const PathTraceResult pr = pathTrace(s, *caster, po);
    PhotonOptions ph;
    ph.photons = 1000;
    ph.point = L;
    const VertexRadiometry mr = computePhotonMap(s, *caster, ph);
    for (size_t i = 0; i < s.vertexCount(); ++i) {
      const glm::dvec3 d = (P - s.toWorld(s.positions[i])) / k;
      const double r2 = glm::dot(d, d), exact = 2.0 * d.z / std::sqrt(r2) / r2;
      EXPECT_NEAR(pr.H[i].g, exact, 1e-4 * exact) << "scale " << k;
      EXPECT_NEAR(mr.H[i].g, exact, 1e-4 * exact) << "scale " << k;
    }
  }
}

// The point light as the filters read it (a parameter, as the CLI and a
// script give it) among coordinates far from the origin: a plane in UTM-like
// metres (512,345 m east, 4,123,456 m north) with a lamp 3 m over it. The
// position was read in float, whose step there is 0.5 m: 2.6% off under the
// lamp and no warning (an outside audit); in double it is exact, in the
// reference and in photon mapping, but for the shadow rays' start lifted off
// the surface towards the lamp (about 1e-5 of the diagonal: 1.1e-4 to
// 1.4e-4 of the value here; 5e-4 allowed).
TEST(Scales, PointLightParameterFarFromTheOrigin) {
  const glm::dvec3 o(512345.3, 4123456.7, 100.1);
  auto sf = scenes::openPlane(10.0, 10);
  sf.scene = test::transformed(sf.scene, 1.0, o);
  const glm::dvec3 P = o + glm::dvec3(1.0, 2.0, 3.0);
  char pos[128];
  std::snprintf(pos, sizeof pos, "%.17g,%.17g,%.17g", P.x, P.y, P.z);
  const double rho = srgbToLinear(188.f / 255.f);  // the default reflectance
  for (FilterKind kind : {FilterKind::PathTracedReference, FilterKind::PhotonMapping}) {
    FilterInput in = test::filterInput(kind, sf);
    const auto specs = filterSpecs(kind);
    const double diag = analyzeScene(in.scene).diagonal;
    for (const auto& [k, v] : {std::pair<const char*, const char*>{"emitter_source", "None"},
                               {"point_position", pos}, {"point_intensity", "300"}})
      in.values.set(k, parseValue(*findSpec(specs, k), v, diag));
    if (kind == FilterKind::PathTracedReference) in.values.set("samples_per_vertex", 2);
    const FilterResult r = runFilter(kind, in);
    const VertexAttribute* B = nullptr;
    for (const auto& a : r.attributes)
      if (a.name == "Radiosity") B = &a;
    ASSERT_NE(B, nullptr);
    ASSERT_EQ(B->components, 3);
    for (size_t i = 0; i < in.scene.vertexCount(); ++i) {
      const glm::dvec3 d = P - in.scene.toWorld(in.scene.positions[i]);
      const double r2 = glm::dot(d, d), exact = rho * 300.0 * d.z / std::sqrt(r2) / r2;
      EXPECT_NEAR(B->values[3 * i + 1], exact, 5e-4 * exact) << filterDesc(kind).cliName << ", vertex " << i;
    }
  }
}

// One vertex no face uses, far away (1e8 from a scene of 1e3: a stray point
// a scanner or an export left), changes nothing a filter computes: it sized
// the convex-room test's tolerance (radiosity then cast no shadow ray: 199
// of the Cornell box's 1,010 vertices off by more than 20%), the disk the
// sky's photons start from (none stored) and a framed view (a black image;
// an outside audit). Each filter's values on the scene's own vertices are
// compared with the same scene without the stray vertex.
TEST(Scales, StrayVertexFarAwayChangesNothing) {
  auto withStray = [](scenes::SceneFile sf, double far) {
    Scene& s = sf.scene;
    s.positions.push_back(glm::vec3((glm::dvec3(far, 0.0, 0.0) - s.origin) / s.unit));
    if (!sf.attrs.vertexColor.empty()) sf.attrs.vertexColor.push_back(sf.attrs.vertexColor.back());
    if (!sf.attrs.vertexSelected.empty()) sf.attrs.vertexSelected.push_back(0);
    if (!sf.attrs.vertexColorGiven.empty()) sf.attrs.vertexColorGiven.push_back(0);
    return sf;
  };
  struct Case {
    FilterKind kind;
    scenes::SceneFile sf;
    std::vector<std::pair<const char*, const char*>> params;
    double far = 1e8;
  };
  const std::vector<Case> cases = {
      {FilterKind::Radiosity, scenes::cornellBox(100.0), {}},
      {FilterKind::PhotonMapping, scenes::floorWithWall(4.0, 1.0, 10),
       {{"emitter_source", "None"}, {"sky_irradiance", "100"}, {"photons", "20000"}}},
      {FilterKind::RayTracedView, scenes::cornellBox(100.0),
       {{"width", "24"}, {"height", "24"}, {"samples_per_pixel", "1"}, {"mode", "Whitted"}}},
      // Beyond the coordinates rays can represent (it refused every
      // ray-casting filter in the ray caster's own words).
      {FilterKind::AmbientOcclusion, scenes::cornellBox(100.0), {{"rays_per_vertex", "16"}}, 2e13},
  };
  for (const Case& c : cases) {
    std::vector<FilterResult> r;
    for (const auto& sf : {c.sf, withStray(c.sf, c.far)}) {
      FilterInput in = test::filterInput(c.kind, sf);
      const auto specs = filterSpecs(c.kind);
      const double diag = analyzeScene(in.scene).diagonal;
      for (const auto& [k, v] : c.params) in.values.set(k, parseValue(*findSpec(specs, k), v, diag));
      r.push_back(runFilter(c.kind, in));
    }
    const std::string name = filterDesc(c.kind).cliName;
    if (c.kind == FilterKind::RayTracedView) {
      ASSERT_EQ(r[0].images.size(), r[1].images.size());
      ASSERT_FALSE(r[0].images.empty());
      double lit = 0.0;
      for (size_t k = 0; k < r[0].images[0].image.px.size(); ++k) {
        EXPECT_EQ(r[0].images[0].image.px[k], r[1].images[0].image.px[k]) << name << ", pixel " << k;
        lit += luminance(r[0].images[0].image.px[k]);
      }
      EXPECT_GT(lit, 0.0);
      continue;
    }
    const size_t nv = c.sf.scene.vertexCount();
    ASSERT_EQ(r[1].vertexQuality.size(), nv + 1);
    for (size_t i = 0; i < nv; ++i)
      EXPECT_NEAR(r[1].vertexQuality[i], r[0].vertexQuality[i], 1e-5 * std::max(1.f, r[0].vertexQuality[i]))
          << name << ", vertex " << i;
    if (c.kind == FilterKind::Radiosity) {
      EXPECT_GT(r[1].stats.get("direct_shadow_rays"), 0.0);
    }
    if (c.kind == FilterKind::PhotonMapping) {
      EXPECT_GT(r[1].stats.get("photons_stored"), 0.0);
    }
  }
}

// Embree asserts (aborting MeshLab) on a ray with a NaN or infinite origin
// or direction, or coordinates beyond 1.8e18: the caster throws instead.
TEST(Scales, UnrepresentableRaysAreAnErrorNotAnAbort) {
  const Scene s = box(1.0, 0.5f);
  for (BatchMode mode : {BatchMode::Single, BatchMode::Packet8, BatchMode::Stream}) {
    auto caster = makeEmbreeCaster(s, mode);
    Ray ok;
    EXPECT_TRUE(caster->intersect(ok).valid());
    for (const Ray& bad : {Ray{glm::vec3(NAN, 0.f, 0.f)}, Ray{glm::vec3(2e18f, 0.f, 0.f)},
                           Ray{glm::vec3(0.f), 0.f, glm::vec3(0.f, INFINITY, 0.f)},
                           Ray{glm::vec3(0.f), 0.f, glm::vec3(0.f, 0.f, 1.f), NAN}}) {
      EXPECT_THROW(caster->intersect(bad), std::runtime_error);
      EXPECT_THROW(caster->occluded(bad), std::runtime_error);
      uint8_t occ[2];
      const Ray two[2] = {ok, bad};
      EXPECT_THROW(caster->occludedBatch(two, 2, occ), std::runtime_error);
      EXPECT_THROW(caster->occludedFan(bad.o, &bad.d, 1, bad.tfar, occ), std::runtime_error);
    }
  }
}

// A light whose result lies beyond single precision is refused, not
// written as 0 or a crash: a plane of 1e-18 m under a lamp of 1e12 W/sr
// 1e-18 m over it (1e48 in the scene's units) crashed photon mapping and came
// out black from the reference with exit 0 (an outside audit). Refused from
// the parameter where the lamp itself is beyond float in the scene's units,
// and where only the result is: a plane 2e-13 across (its unit 2^-42) under
// the same lamp 1.1e-14 over its middle vertex (1.9e37 and 0.05 in its units:
// 7.7e39 W/m^2 there). The same lamp 1e-12 over it (1e36 W/m^2) and the
// small plane under a lamp of 1e-30 W/sr are computed.
TEST(Scales, ResultBeyondSinglePrecisionIsRefused) {
  auto small = scenes::openPlane(2.0, 4), mid = small;
  small.scene = test::transformed(small.scene, 1e-18, glm::dvec3(0.0));
  mid.scene = test::transformed(mid.scene, 1e-13, glm::dvec3(0.0));
  ASSERT_EQ(mid.scene.unit, std::ldexp(1.0, -42));
  struct Case {
    const scenes::SceneFile* scene;
    const char *position, *intensity, *refusal;  // refusal: a phrase of the message, or null
    float lo, hi;                                // else the quality's range: rho I cos / r^2 over the plane
  };
  const Case cases[] = {{&small, "0,0,1e-18", "1e12", "too strong for a scene 2.83e-18 across", 0.f, 0.f},
                        {&mid, "0,0,1.1368683772161603e-14", "1e12", "not finite at", 0.f, 0.f},
                        {&mid, "0,0,1e-12", "1e12", nullptr, 1e34f, 1e37f},
                        {&small, "0,0,1e-18", "1e-30", nullptr, 1e4f, 1e7f}};
  for (FilterKind kind : {FilterKind::PathTracedReference, FilterKind::PhotonMapping}) {
    for (const Case& c : cases) {
      FilterInput in = test::filterInput(kind, *c.scene);
      const auto specs = filterSpecs(kind);
      const double diag = analyzeScene(in.scene).diagonal;
      for (const auto& [k, v] : {std::pair<const char*, const char*>{"emitter_source", "None"},
                                 {"point_position", c.position}, {"point_intensity", c.intensity}})
        in.values.set(k, parseValue(*findSpec(specs, k), v, diag));
      if (kind == FilterKind::PathTracedReference) in.values.set("samples_per_vertex", 2);
      const std::string what = std::string(filterDesc(kind).cliName) + " at " + c.position + ", " + c.intensity;
      if (!c.refusal) {
        const FilterResult r = runFilter(kind, in);
        for (float q : r.vertexQuality) {
          EXPECT_GT(q, c.lo) << what;
          EXPECT_LT(q, c.hi) << what;
        }
        continue;
      }
      try {
        runFilter(kind, in);
        ADD_FAILURE() << what << ": accepted";
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find(c.refusal), std::string::npos) << what << ": " << e.what();
        EXPECT_NE(std::string(e.what()).find("beyond single precision"), std::string::npos) << e.what();
      }
    }
  }
}
