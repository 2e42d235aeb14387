// Photon mapping (Jensen 1996) for the light paths radiosity cannot carry.
// Photons leave the lights in proportion to power (area emitters; an optional
// point or spot light; a uniform sky and a sun disk, gi/sky.h: a direction w
// towards the light drawn (uniform over the sphere, or in the sun's cone),
// the photon starts on the disk of the bounding sphere's radius R facing w,
// outside the scene, and travels along -w with the power L x (solid angle)
// x pi R^2 / count: 4 E_sky pi R^2 / count, or E_sun pi R^2 / count, so that
// a surface facing the light receives E_sky or E_sun per unit area; where
// the sky's openings are the only way in, R and the disk those of a sphere
// around their portals), low-
// discrepancy in position and direction, and are
// traced with Russian roulette through diffuse (Lambertian), mirror and glass
// faces (gi/specular.h) and glossy ones (the GGX lobe, gi/glossy.h,
// importance-sampled). Every diffuse hit is stored (glossy hits are not);
// by the path so far a photon is
//   direct   L D      (read only when the direct light is not computed apart),
//   caustic  L S+ D   (the caustic map; S: mirror, glass or glossy, so that
//                      light a glossy surface focuses, a blurred caustic, is
//                      read with the caustic map's sharper filter),
//   indirect L ... D D (at least one diffuse bounce before: the global map).
// Per-vertex radiosity B = E + rho H, with the irradiance H from
//   - the direct light by explicit light sampling with shadow rays (default),
//   - the caustic map: density estimate over the k nearest caustic photons on
//     the same side with Jensen's cone filter (w = 1 - d / (1.1 r)),
//   - the global map: uniform kernel, H ~ sum Phi / A(r_k) over the k
//     nearest, or a final gather that reads the map where cosine rays from
//     the vertex land (following mirrors and glass on the way),
//   - or, with progressive photon mapping (Hachisuka et al. 2008), per-vertex
//     radius and flux statistics over passes of photons, the radius shrinking
//     by alpha = 2/3, so that the estimate converges (bias and noise -> 0).
// A(r) is the area of the surface whose photons count (facing the vertex's
// side) inside the gather sphere: Jensen's pi r^2 on a plane, a half or a
// quarter of it at a crease or a corner, less at a mesh border; the cone
// filter and the progressive flux are normalised the same way.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/direct.h"
#include "gi/emitters.h"
#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/scene.h"
#include "gi/sky.h"

namespace gi {

struct PhotonOptions {
  int photons = 200000;       // emitted photon paths (per pass when progressive)
  int kNearest = 64;          // photons per global-map estimate
  int causticK = 128;         // photons per caustic-map estimate
  bool causticProjection = true;  // caustic photons aimed at the mirrors and glass (else: the global pass's)
  // Photons from the sky and the sun only (tracePhotons): the two-pass
  // view's caustic map adds theirs to the projected ones of the other lights.
  bool outsideLightsOnly = false;
  double maxRadius = 0.0;     // 0 = unlimited; else gather radius cap (absolute)
  int maxDepth = 32;          // bounces (diffuse and specular) before a path stops for sure
  bool directLight = true;    // direct light by light sampling at vertices; photons for the rest
  int lightSamples = 256;     // shadow rays per vertex for the direct light
  bool finalGather = false;   // read the global map where gather rays land instead of at the vertex
  int gatherRays = 64;
  bool progressive = false;   // progressive photon mapping over `passes` passes
  int passes = 16;
  double alpha = 2.0 / 3.0;   // PPM: fraction of new photons kept per pass
  PointLight point;           // optional point or spot light (relative to the scene origin, world units)
  SkySun outside;             // sky and sun: photons enter from a disk covering the scene's bounding sphere
  // Or a smaller sphere every way in from outside passes through (local
  // units; radius 0: the scene's bounding sphere): photon mapping sets the
  // sky openings' (gi/sky.h) where they are the only way in, a window room's
  // window, so that the photons shot at it are not spent on the walls'
  // outsides (about 1% entered a room through its window before).
  glm::vec3 outsideAimCentre{0.f};
  float outsideAimRadius = 0.f;
  bool lightPathSplit = false;  // also B per light-path kind (light_paths.h)
  uint32_t seed = 0;
  // Memory the stored photons may take (gi/memory_limit.h); 0: what the
  // machine has available when the trace starts.
  size_t memoryLimitBytes = 0;
  // What a refusal under that limit tells the user to do; "" for the
  // photon filters' own advice (a run that shares the limit says how).
  std::string memoryRemedy;
  static std::vector<ParamSpec> specs();
  static PhotonOptions fromParams(const ParamValues& v, const glm::dvec3& sceneOrigin);
};

enum PhotonPath : uint8_t { kDirectPhoton = 0, kCausticPhoton = 1, kIndirectPhoton = 2 };
// A photon's path kind is the light-path kind of the light it brings (light_paths.h).
static_assert(int(kDirectPhoton) == kPathDirect && int(kCausticPhoton) == kPathCaustic &&
              int(kIndirectPhoton) == kPathIndirect);

struct Photon {
  glm::vec3 p;      // position (local scene coordinates)
  glm::vec3 power;  // RGB flux, W
  glm::i8vec3 n;    // normal of the surface side it arrived on, x 127
  uint8_t path;     // PhotonPath
  glm::vec3 normal() const { return glm::vec3(n) * (1.f / 127.f); }
};

struct PhotonTraceStats {
  size_t emitted = 0, stored = 0, caustic = 0, direct = 0, indirect = 0;
  size_t diffuseBounces = 0, specularBounces = 0, glossyBounces = 0, totalInternal = 0;
  size_t lostAtMaxDepth = 0, escaped = 0;
  size_t causticEmitted = 0, causticStored = 0, causticMissed = 0;  // the projection pass
  size_t passes = 0;                             // calls of tracePhotons summed here
  bool pointOnSurface = false;                   // the point light lies on a surface (within the ray epsilon)
  double storedPower = 0.0;                      // luminance, W, summed over passes
  double emittedPower = 0.0;                     // luminance power of the lights, W
  double lostPower = 0.0;  // luminance still carried by paths cut at max depth, and by the photons lastHit flags (caustics apart)
  // The same per channel, and the power emitted per channel (summed over
  // passes): a channel's share lost is what its radiosity misses in a
  // closed room, where the luminance's share understates a colour that
  // reflects more (lostPower: 5% where the result was 16.5% dark).
  glm::dvec3 lostRGB{0.0}, emittedRGB{0.0};
  // Where the hits left were asked for, lostPower leaves out the paths
  // whose last allowed hit stored a photon (but a caustic): the power they
  // still carried after it, lost in every mode (the caller adds it).
  double lastHitCutPower = 0.0;
  glm::dvec3 lastHitCutRGB{0.0};
};

// Traces photons `first` .. `first + count - 1` of the seed's sequence (each
// carrying 1/count of the power); deterministic for any thread count. A
// path stores photons at its hits 0 .. max_depth (a photon at hit i brings
// light of i reflections). `lastHit`, if given, gets the hits each photon's
// path had left, min(max_depth - i, 255): 0 where it was stored at hit
// max_depth (the final gather's map leaves those out: its rays add the last
// reflection; a near hit relit by one more ray reads only photons with 2 or
// more left).
std::vector<Photon> tracePhotons(const Scene& s, const RayCaster& caster, const PhotonOptions& opt, size_t first,
                                 size_t count, const Progress& progress, PhotonTraceStats& stats,
                                 std::vector<uint8_t>* lastHit = nullptr);

// Caustic photons by projection (Jensen 1996's projection maps): from points
// on the lights, directions only towards the bounding spheres of the groups of
// mirror, glass and glossy faces (uniform in the cones they subtend, chosen by
// solid angle; the density sums the cones containing a direction); photons
// whose first hit is diffuse are dropped (the global photons carry those
// paths), the others follow mirrors, glass and glossy lobes and are stored at
// their first diffuse hit
// (L S+ D) with flux L cos / (pdf_A pdf_w count). Far more caustic photons per
// emitted photon than the global pass gives when the specular objects are small.
std::vector<Photon> traceCausticPhotons(const Scene& s, const RayCaster& caster, const PhotonOptions& opt, size_t first,
                                        size_t count, const Progress& progress, PhotonTraceStats& stats);

// The options of a trace that runs while `heldPhotons` photons of the same
// run (and `otherBytes` more) are kept: a fixed memoryLimitBytes less what
// they take at the run's peak, at least one byte (a limit they fill refuses
// the trace at once). A limit of 0, the machine's figure read when the
// trace starts, counts them already (they are allocated). Without it a
// second trace was checked against the whole limit beside the first's
// photons: the caustic projection beside the global photons, the two-pass
// view's sky and sun trace beside its projection.
PhotonOptions whileHolding(const PhotonOptions& o, size_t heldPhotons, double otherBytes = 0.0);

// Where the openings are the only way in from outside (findSkyOpenings), the
// sky's and the sun's photons aim at a sphere around their portals instead
// of the scene's (opt.outsideAimCentre and outsideAimRadius): the same lines
// through the openings, none spent on the outsides of the walls. True where
// it did.
bool aimAtOpenings(const SkyOpenings& openings, const Scene& s, PhotonOptions& opt);

// The warning for a k-nearest density estimate k Phi / (pi r_k^2) whose k
// leaves it without a finite mean (k = 1) or variance (k = 2), or none.
std::optional<std::string> smallKWarning(const std::string& name, int k);

// Area of the triangle abc inside the ball of centre x and radius r (exact:
// the triangle clipped to the disk in which the sphere cuts its plane). The
// density estimates divide by the sum of these over the faces whose photons
// they count, instead of pi r^2, which holds only on a plane all around x.
double triangleBallArea(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& x, double r);

// The photons the density estimates read, in local scene coordinates: the
// global map's (with a final gather, every photon the gather rays read) and
// the caustic map's. Progressive photon mapping keeps no map (each pass's
// photons are dropped once counted): both stay empty.
struct PhotonMapContents {
  std::vector<Photon> global, caustic;
};

// `maps` (optional) receives the photons of the maps (the photon layer).
VertexRadiometry computePhotonMap(const Scene& s, const RayCaster& caster, const PhotonOptions& opt,
                                  const Progress& progress = Progress(nullptr), PhotonMapContents* maps = nullptr);

}  // namespace gi
