// Light from outside the scene: a uniform sky of radiance L_sky over the
// whole sphere (an unoccluded surface gets E_sky = pi L_sky) and a sun disk
// of angular radius alpha whose radiance L_sun = E_sun / (pi sin^2 alpha)
// gives a surface facing it E_sun (its cone's projected solid angle is
// pi sin^2 alpha; over its solid angle Omega_sun = 2 pi (1 - cos alpha) the
// mean of n.w is then (1 + cos alpha) / 2, which sunDiskScale undoes). At a
// point x with normal n, the irradiance integral (Cohen and Wallace 1993,
// "Radiosity and Realistic Image Synthesis", ch. 2):
//   H_out(x) = L_sky ∫_{n.w > 0} V(x, w) (n.w) dw + L_sun ∫_{sun} V(x, w) max(0, n.w) dw
//            = E_sky <V>_{w ~ cos/pi} + E_sun <V max(0, n.w)>_{w uniform in the sun's cone}
// estimated with cosine-weighted rays for the sky and rays uniform in the
// sun's cone (soft shadows), samples keyed by (element, sample, seed).
// The radiosity and photon-mapping filters take the sky and the sun as
// emitters outside the scene; the path-traced reference and the ray traced
// view see them along rays that leave the scene. One parameter table serves
// them all (SkySun::specs).
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/scene.h"
#include "gi/vertex_part.h"

namespace gi {

// The factor from E_sun <max(0, n.w)>, w uniform in the sun's cone, to the
// irradiance: 2 / (1 + cos alpha) = 1 / cos^2(alpha / 2), so that a surface
// facing the sun gets E_sun whatever its size (without it 0.854 E_sun at
// alpha = 45 degrees; 1 - 5.6e-6 at the real sun's 0.27). The photons,
// sent through a disk facing each sampled direction, take the same factor.
inline float sunDiskScale(float angularRadiusDeg) {
  const double c = std::cos(0.5 * double(angularRadiusDeg) * 3.14159265358979323846 / 180.0);
  return float(1.0 / (c * c));
}

struct SkySun {
  glm::vec3 skyRadiance{0.f};    // uniform sky over the whole sphere, W/(m^2 sr) (linear RGB)
  glm::vec3 sunDirection = *unitDirection({0.3f, 1.f, 0.2f});  // towards the sun, unit length
  glm::vec3 sunIrradiance{0.f};  // on a surface facing the sun, W/m^2 (linear RGB)
  float sunAngularRadiusDeg = 0.27f;

  bool sky() const;
  bool sun() const;
  bool any() const { return sky() || sun(); }
  float sunCos() const;  // cos alpha: the sun's cone
  // Throws std::invalid_argument for a sky or sun colour that is not finite
  // or below 0, a sun direction that is not a finite unit vector where the
  // sun shines, or an angular radius outside the table's range.
  void check() const;
  // sky_color, sky_irradiance, sun_direction, sun_color, sun_irradiance,
  // sun_angular_radius: the names, help and ranges every filter shares.
  static std::vector<ParamSpec> specs();
  static SkySun fromParams(const ParamValues& v);
};

// The sky through openings (portals). In a closed room with a window every
// cosine ray that reaches the sky passes through the window, a few percent
// of them: 256 rays leave the sky's share of a vertex 40% noisy. An opening
// of the mesh (a planar, convex boundary loop that no face covers and
// through which rays reach the sky) is taken as a luminaire of the sky's
// radiosity E_sky = pi L_sky, seen from either side:
//   H_sky(x) = E_sky F(x -> P) V(x, P) + E_sky <V_rest>_{w ~ cos/pi},
// F the exact point-to-polygon factor and V the fraction of shadow rays
// through P that leave the scene (gi/luminaires.h: stratified rays, more in
// penumbra), as portal sampling of an environment does (Bitterli, Novak and
// Jarosz 2015, "Portal-masked environment map sampling"; pbrt-v4's portal
// light). Every direction that leaves the scene is counted once: for the
// portal of lowest index it crosses, or, crossing none, by the cosine rays
// (V_rest). Where probe rays from the patches find no other way out, or
// one that carries below kRestShare of the sky's light at 95% confidence,
// the cosine rays are skipped (the log says so and what the probes found).
struct SkyPortal {
  std::vector<glm::dvec3> corners;  // convex, counter-clockwise about normal
  glm::dvec3 normal{0.0};           // unit
  glm::dvec3 centre{0.0};
  double area = 0.0;
};

struct SkyOpenings {
  static constexpr size_t kMaxPortals = 8;          // the largest openings; smaller ones stay with the cosine rays
  static constexpr double kMinAreaShare = 1e-3;     // of the scene's surface area, at least
  static constexpr int kProbeFaces = 4096;          // patches the probe rays leave from
  static constexpr int kProbeRays = 64;             // cosine rays from each
  static constexpr double kRestShare = 0.005;       // sky light outside the openings that may be left out
  std::vector<SkyPortal> portals;
  glm::vec3 E{0.f};      // pi L_sky: what the portals emit
  bool rest = true;      // the cosine rays are still needed (no portals, or the probes found another way out)
  size_t loops = 0;      // boundary loops of the mesh looked at
  double unit = 1.0;     // the scene's world length of one local unit (SkyPortal is in local units)
  uint64_t probeRays = 0, probeEscapes = 0, probeRest = 0;
  bool any() const { return !portals.empty(); }
  // The lowest index of a portal the ray from o along d crosses (t > 0), -1 for none.
  int crossed(const glm::vec3& o, const glm::vec3& d) const;
  void report(RunStats& st) const;
};

// The openings of s to the sky o (none without a sky).
SkyOpenings findSkyOpenings(const Scene& s, const RayCaster& caster, const SkySun& o, uint32_t seed);

// H_out at x (already lifted off the surface) with unit normal n: `rays`
// cosine-weighted rays for the sky and `rays` in the sun's cone, keyed by `key`.
glm::vec3 skySunIrradianceAt(const SkySun& o, const RayCaster& caster, const glm::vec3& x, const glm::vec3& n,
                             int rays, uint32_t key);

// The mean of H_out over each face (rays from points spread over the face;
// 0 for unusable faces and without sky and sun). With `openings`, the sky
// through its portals is left out (the direct light adds it, as a
// luminaire), and so are the cosine rays where it found no other way out.
std::vector<glm::vec3> patchSkySunIrradiance(const Scene& s, const RayCaster& caster, const SkySun& o, int rays,
                                             uint32_t seed, const Progress& progress = Progress(nullptr),
                                             const SkyOpenings* openings = nullptr);

// The mean of H_out over given points of each face (points[f] on face f,
// not lifted; faces without points get 0): the seen part of a partly buried
// patch (PatchSeen::seenPoints), whose outside light, like its emitters'
// (seenPartDirectIrradiance), is the mean over its own points. The patch
// mean over all of it divided by the seen share, two estimates from
// different points, read a floor patch half inside a box, under a sun
// straight above, 4% high or low (it is lit wherever it is seen). Every
// point of a face (PatchSeen keeps up to 64), each with rays / points (at
// least one) sky and sun rays; `openings` as for the patches.
std::vector<glm::vec3> seenPartSkySunIrradiance(const Scene& s, const RayCaster& caster, const SkySun& o, int rays,
                                                uint32_t seed, const std::vector<std::vector<glm::vec3>>& points,
                                                const SkyOpenings* openings = nullptr);

// H_out at every vertex of `part` (the others, and vertices without a usable
// face, 0), from the per-vertex ray origins (vertexRayOrigins); `openings`
// as for the patches.
std::vector<glm::vec3> vertexSkySunIrradiance(const Scene& s, const RayCaster& caster, const SkySun& o, int rays,
                                              uint32_t seed, const VertexPart& part = VertexPart(),
                                              const Progress& progress = Progress(nullptr),
                                              const SkyOpenings* openings = nullptr);

// The power entering the scene from outside, as luminance: sum over faces
// of A_f luminance(H_out,f) (local units of area).
double enteringPower(const Scene& s, const std::vector<glm::vec3>& Hout);

}  // namespace gi
