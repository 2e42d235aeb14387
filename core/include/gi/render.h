// The eye pass: images ray traced from a camera (gi/camera.h). Each pixel
// is the mean over its samples of the radiance L(x, -w) arriving along eye
// rays, the rendering equation (Kajiya 1986)
//   L(x, wo) = Le(x, wo) + ∫ f(x, wi, wo) L(x', -wi) cos(theta_i) dwi,
// truncated or estimated differently by four modes:
//   Whitted      (Whitted 1980): perfect mirror and glass rays, both glass
//                branches (Fresnel split) as an explicit stack; at diffuse
//                hits the direct light only: point/spot light and sun by a
//                shadow ray, each area light (a connected set of emitting
//                faces) by its exact unoccluded form factor (Lambert's
//                contour integral) times the visibility of one shadow ray to
//                its centroid (hard shadows, no noise).
//   Distributed  (Cook, Porter and Carpenter 1984): the same light paths
//                with every integral sampled: soft shadows (area lights and
//                the sun disk sampled, with MIS against one cosine ray that
//                also sees the sky), glossy reflection (the GGX lobe
//                importance-sampled), antialiasing and depth of field, all
//                from Owen-scrambled Sobol points; no diffuse interreflection.
//   Two-pass     (Chen et al. 1991; Jensen 1996): eye rays follow mirrors,
//                glass and glossy surfaces; at the first diffuse hit the
//                view-independent first pass (per-vertex radiosity B from
//                radiosity or photon mapping) gives the diffuse light,
//                interpolated over the triangle: alone, or as the indirect
//                part beside ray-traced direct light, optionally with the
//                caustic photon map read at the hit point, or read by a
//                final gather.
//   PathTraced   unbiased path tracing: next-event estimation with multiple
//                importance sampling (power heuristic, Veach 1997), Russian
//                roulette, independent random numbers, so that every pixel
//                gets an honest standard error from its sample variance.
// Radiance conventions are the engine's: a diffuse face of radiosity B
// leaves L = B / pi; emitters emit E / pi from their front; faces seen from
// behind (diffuse, emitting or glossy) are black; radiance is scaled by
// eta^2 across glass.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/camera.h"
#include "gi/emitters.h"
#include "gi/image.h"
#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/scene.h"
#include "gi/sky.h"

namespace gi {

enum class RenderMode { Whitted, Distributed, TwoPass, PathTraced };
inline constexpr auto kRenderModes = makeEnumTable<RenderMode>({
    {RenderMode::Whitted, "Whitted", "Whitted"},
    {RenderMode::Distributed, "Distributed", "Distributed"},
    {RenderMode::TwoPass, "Two-pass", "Two-pass"},
    {RenderMode::PathTraced, "Path traced", "Path traced"},
});

// How the two-pass mode lights a diffuse hit (reflected light; its own
// emission E / pi is added in every case).
enum class TwoPassDiffuse {
  Map = 0,             // (B - E) interpolated / pi: the first pass alone (its shadows are as coarse as its mesh)
  DirectIndirect = 1,  // ray-traced direct light + the first pass's indirect part (B - Bdirect) interpolated
  Caustics = 2,        // + the caustic photon map read at the hit (Jensen's rendering pass); the first pass's
                       //   own caustics removed from its indirect part when it has them
  FinalGather = 3,     // direct + caustic map + gather rays reading the first pass's reflected radiosity
};
inline constexpr auto kTwoPassDiffuse = makeEnumTable<TwoPassDiffuse>({
    {TwoPassDiffuse::Map, "First pass alone", "first pass alone"},
    {TwoPassDiffuse::DirectIndirect, "Ray-traced direct + stored indirect", "direct + stored indirect"},
    {TwoPassDiffuse::Caustics, "Direct + caustic map + stored indirect", "direct + caustic map + stored indirect"},
    {TwoPassDiffuse::FinalGather, "Direct + caustic map + final gather", "direct + caustic map + final gather"},
});

struct RenderOptions {
  RenderMode mode = RenderMode::Distributed;
  Camera camera;
  int samplesPerPixel = 16;
  int maxDepth = 32;            // scattering events on a path (mirror, glass, glossy, diffuse)
  int maxDiffuseBounces = -1;   // path traced: diffuse vertices that continue (-1 = any, 0 = direct light only)
  int lightSamples = 1;         // shadow-ray samples per light at the first diffuse hit of an eye path
  float whittedMinWeight = 1e-3f;  // Whitted: branches below this weight are not traced
  TwoPassDiffuse twoPass = TwoPassDiffuse::Caustics;
  bool firstPassHasCaustics = true;
  int causticPhotons = 200000;  // caustic photons shot (projection towards mirrors and glass)
  int causticK = 128;
  double causticMaxRadius = 0;  // absolute; 0 = unlimited
  // (With the first pass's photons, caustic k, gather radius and seed, its
  // vertex caustics are exactly those the eye pass takes out.)
  int gatherRays = 16;          // final-gather rays per eye-path diffuse hit
  bool renderImage = true;
  bool vertexRadiance = false;  // also the radiance each vertex sends towards the camera
  // Lights besides the emitting faces (as in the path-traced reference).
  glm::vec3 skyRadiance{0.f};
  glm::vec3 sunDirection = *unitDirection({0.3f, 1.f, 0.2f});  // towards the sun, unit length
  glm::vec3 sunIrradiance{0.f};
  float sunAngularRadiusDeg = 0.27f;
  // The sky and the sun above as gi/sky.h's settings (fromParams reads them so).
  SkySun outside() const { return {skyRadiance, sunDirection, sunIrradiance, sunAngularRadiusDeg}; }
  PointLight point;
  uint32_t seed = 0;
  // Memory the image and the caustic photons may take (gi/memory_limit.h);
  // 0: what the machine has available when the run starts.
  size_t memoryLimitBytes = 0;
  // The first pass (two-pass mode): per-vertex radiosity B (linear RGB,
  // W/m^2, emission included) and optionally its direct part Bdirect = E +
  // rho H_direct (photon mapping leaves it as the attribute RadiosityDirect;
  // empty, or not below B everywhere: estimated here at the vertices from
  // the area emitters and the point light with 256 shadow rays each).
  std::vector<glm::vec3> firstPassB, firstPassBdirect;

  static std::vector<ParamSpec> specs();
  // Camera from the table: framing the scene's bounding box, look-at, or
  // the layer's camera (layerCamera; a clear error if there is none).
  static RenderOptions fromParams(const ParamValues& v, const Scene& s, const ShotData* layerCamera = nullptr);
};

struct RenderResult {
  Image image;                     // radiance, W / (m^2 sr), linear RGB
  std::vector<float> stdError;     // per pixel: standard error of the luminance from the sample variance
                                   // (an honest error bar for PathTraced; QMC modes: conservative)
  std::vector<uint8_t> seesEmitter;  // per pixel: its first sample's eye ray hits an emitter (for auto exposure)
  std::vector<glm::vec3> vertexRadiance;  // per vertex, towards the camera (if asked), W / (m^2 sr);
                                          // 0 where the vertex normal faces away from the camera
  std::vector<float> vertexStdError;  // per vertex, path traced with 2 or more samples: the standard error of
                                      // vertexRadiance's luminance (its variance at least its 2-ring's mean)
  RunStats stats;
};

// Throws std::invalid_argument for unusable input (no light, two-pass
// without a first pass, bad sample counts) and Cancelled.
RenderResult render(const Scene& s, const RayCaster& caster, const RenderOptions& opt,
                    const Progress& progress = Progress(nullptr));

// The mode names as the parameter table spells them.
const char* renderModeName(RenderMode m);

}  // namespace gi
