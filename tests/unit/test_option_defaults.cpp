// Each options struct's defaults equal its filter's parameter table: the
// options read from the table's defaults (defaultValues, as the dialog and
// the CLI start) are a default-constructed struct, field by field, so that
// code building options directly (tests, benchmarks) computes what the
// filter computes by default. Defaults that depend on the scene are stated
// and compared with the scene (or diagonal) they depend on.
#include <gtest/gtest.h>

#include <limits>

#include "gi/ambient.h"
#include "gi/filters.h"
#include "gi/form_factors.h"
#include "gi/pathtrace.h"
#include "gi/photon.h"
#include "gi/radiosity.h"
#include "gi/refine.h"
#include "gi/render.h"
#include "gi/scenes.h"
#include "gi/thickness.h"

using namespace gi;

namespace {

// Any diagonal: Distance defaults are fractions of it.
constexpr double kDiag = 7.5;

#define SAME(field) EXPECT_EQ(got.field, want.field) << #field

ParamValues defaults(FilterKind k) { return defaultValues(filterSpecs(k), kDiag); }

void expectSame(const FormFactors::Settings& got, const FormFactors::Settings& want) {
  SAME(method);
  SAME(raysPerPatch);
  SAME(analyticPoints);
  SAME(hemicubeResolution);
  SAME(seed);
  SAME(hemicubePoints);
}

void expectSame(const RefineOptions& got, const RefineOptions& want) {
  SAME(maxDepth);
  SAME(maxPatches);
  SAME(threshold);
  SAME(shadowThreshold);
  SAME(visibilityRays);
  SAME(creaseDegrees);
  SAME(seed);
}

void expectSame(const PointLight& got, const PointLight& want) {
  SAME(position);
  SAME(intensity);
  SAME(spotDirection);
  SAME(spotAngleDeg);
}

TEST(OptionDefaults, AmbientEveryMode) {
  const std::pair<FilterKind, AmbientMode> modes[] = {{FilterKind::AmbientOcclusion, AmbientMode::Occlusion},
                                                       {FilterKind::AmbientObscurance, AmbientMode::Obscurance},
                                                       {FilterKind::SkyLighting, AmbientMode::Sky}};
  for (const auto& [kind, mode] : modes) {
    SCOPED_TRACE(int(mode));
    const AmbientOptions got = AmbientOptions::fromParams(mode, defaults(kind));
    AmbientOptions want;
    want.mode = mode;
    // Obscurance needs a finite d_max: 10% of the bbox diagonal.
    if (mode == AmbientMode::Obscurance) want.maxDistance = 0.1 * kDiag;
    SAME(mode);
    SAME(raysPerVertex);
    SAME(targetError);
    SAME(minRays);
    SAME(maxRays);
    SAME(maxDistance);
    SAME(seed);
    SAME(bentNormals);
    SAME(useCone);
    SAME(coneDirection);
    SAME(coneAngleDeg);
    SAME(falloffExponent);
    SAME(skyRadiantColor);
    SAME(sunColor);
    SAME(skyIrradiance);
    SAME(sunIrradiance);
    SAME(sunDirection);
    SAME(sunAngularRadiusDeg);
    SAME(sunRays);
    SAME(batch);
    SAME(skipOpenVertices);
    SAME(mergeDuplicates);
    SAME(estimator);
    SAME(shareRings);
    SAME(shareNormalAngleDeg);
  }
  // The colour output is the filter's (not an option of the computation): grey.
  EXPECT_EQ(kAOColorMappings.get(defaults(FilterKind::AmbientOcclusion), "color_mapping"), AOColorMapping::Grey);
}

// The same sun by default wherever there is one: sky lighting's sun was
// warm (sRGB 255, 244, 214) where radiosity's, photon mapping's and the
// reference's is white, so the same sun_irradiance gave 0.908 of the
// reference's irradiance (an outside audit).
TEST(OptionDefaults, OneSunColourInEveryFilter) {
  const glm::vec3 sky = defaults(FilterKind::SkyLighting).getVec("sun_color");
  for (FilterKind k : {FilterKind::Radiosity, FilterKind::PhotonMapping, FilterKind::PathTracedReference})
    EXPECT_EQ(defaults(k).getVec("sun_color"), sky) << int(k);
  EXPECT_EQ(sky, glm::vec3(1.f));
}

void expectSame(const SkySun& got, const SkySun& want) {
  SAME(skyRadiance);
  SAME(sunDirection);
  SAME(sunIrradiance);
  SAME(sunAngularRadiusDeg);
}

TEST(OptionDefaults, Thickness) {
  const ThicknessOptions got = ThicknessOptions::fromParams(defaults(FilterKind::Thickness)), want;
  SAME(raysPerVertex);
  SAME(targetError);
  SAME(minRays);
  SAME(maxRays);
  SAME(coneAngleDeg);
  SAME(rejectOutliers);
  SAME(seed);
}

TEST(OptionDefaults, FormFactorSettings) {
  expectSame(formFactorSettings(defaults(FilterKind::FormFactorsOfFace)), FormFactors::Settings{});
}

TEST(OptionDefaults, Radiosity) {
  const ParamValues v = defaults(FilterKind::Radiosity);
  const RadiosityOptions got = RadiosityOptions::fromParams(v), want;
  expectSame(got.formFactors, want.formFactors);
  SAME(lightSamples);
  SAME(solver);
  SAME(bounces);
  SAME(tolerance);
  SAME(maxIterations);
  SAME(memoryBudgetMB);
  SAME(hierarchyEpsilon);
  SAME(linkRays);
  SAME(closureRays);
  SAME(vertexOutput);
  SAME(gatherRays);
  SAME(refine);
  expectSame(got.outside, want.outside);
  expectSame(got.refinement, want.refinement);
  expectSame(RefineOptions::fromParams(v), RefineOptions{});
}

TEST(OptionDefaults, PhotonMapping) {
  // The point light's position is kept relative to the scene's origin: at
  // the origin here, so the table's (0, 0, 0) is the struct's.
  const PhotonOptions got = PhotonOptions::fromParams(defaults(FilterKind::PhotonMapping), glm::dvec3(0.0));
  PhotonOptions want;
  want.maxRadius = 0.05 * kDiag;  // the gather radius cap: 5% of the bbox diagonal
  SAME(photons);
  SAME(kNearest);
  SAME(causticK);
  SAME(causticProjection);
  SAME(maxRadius);
  SAME(maxDepth);
  SAME(directLight);
  SAME(lightSamples);
  SAME(finalGather);
  SAME(gatherRays);
  SAME(progressive);
  SAME(passes);
  SAME(alpha);
  expectSame(got.outside, want.outside);
  expectSame(got.point, want.point);
  SAME(seed);
}

TEST(OptionDefaults, PathTracedReference) {
  const PathTraceOptions got =
      PathTraceOptions::fromParams(defaults(FilterKind::PathTracedReference), glm::dvec3(0.0));
  const PathTraceOptions want;
  SAME(samplesPerVertex);
  SAME(targetRelativeError);
  SAME(minSamples);
  SAME(maxSamples);
  SAME(maxDepth);
  SAME(seed);
  SAME(skyRadiance);
  SAME(sunDirection);
  SAME(sunIrradiance);
  SAME(sunAngularRadiusDeg);
  expectSame(got.point, want.point);
  SAME(tracedVertices);
  SAME(tracedVertexSeed);
}

TEST(OptionDefaults, RayTracedView) {
  const auto sf = scenes::cornellBox(100.0);
  const RenderOptions got = RenderOptions::fromParams(defaults(FilterKind::RayTracedView), sf.scene);
  RenderOptions want;
  want.causticMaxRadius = 0.05 * kDiag;  // the caustic gather radius: 5% of the bbox diagonal
  // The point light's position is relative to the scene's origin (the table's is absolute, (0, 0, 0)).
  want.point.position = glm::vec3(-sf.scene.origin);
  SAME(mode);
  SAME(samplesPerPixel);
  SAME(maxDepth);
  SAME(maxDiffuseBounces);
  SAME(lightSamples);
  SAME(whittedMinWeight);
  SAME(twoPass);
  SAME(firstPassHasCaustics);
  SAME(causticPhotons);
  SAME(causticK);
  SAME(causticMaxRadius);
  SAME(gatherRays);
  SAME(renderImage);
  SAME(vertexRadiance);
  SAME(skyRadiance);
  SAME(sunDirection);
  SAME(sunIrradiance);
  SAME(sunAngularRadiusDeg);
  expectSame(got.point, want.point);
  SAME(seed);
  SAME(firstPassB);
  SAME(firstPassBdirect);
  // The camera depends on the scene: it frames the bounding box, looking
  // along +z with +y up, 39.3 degrees, 512 x 512 pixels, a pinhole.
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  for (const glm::vec3& p : sf.scene.positions) {
    lo = glm::min(lo, sf.scene.toWorld(p));
    hi = glm::max(hi, sf.scene.toWorld(p));
  }
  Camera framed = Camera::frame(lo, hi, {0, 0, 1}, {0, 1, 0}, 39.3, 512, 512);
  framed.setLens(0.0, 0.0);
  EXPECT_EQ(got.camera.eye(), framed.eye());
  EXPECT_EQ(got.camera.forward(), framed.forward());
  EXPECT_EQ(got.camera.right(), framed.right());
  EXPECT_EQ(got.camera.up(), framed.up());
  EXPECT_EQ(got.camera.width(), framed.width());
  EXPECT_EQ(got.camera.height(), framed.height());
  EXPECT_EQ(got.camera.pixelsPerTangent(), framed.pixelsPerTangent());
}

#undef SAME

}  // namespace
