// Light from outside the scene: a uniform sky of radiance L_sky over the
// whole sphere (an unoccluded surface gets E_sky = pi L_sky) and a sun disk
// of angular radius alpha whose radiance L_sun = E_sun / Omega_sun, with
// Omega_sun = 2 pi (1 - cos alpha), gives a surface facing it E_sun. At a
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
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/scene.h"
#include "gi/vertex_part.h"

namespace gi {

struct SkySun {
  glm::vec3 skyRadiance{0.f};    // uniform sky over the whole sphere, W/(m^2 sr) (linear RGB)
  glm::vec3 sunDirection = *unitDirection({0.3f, 1.f, 0.2f});  // towards the sun, unit length
  glm::vec3 sunIrradiance{0.f};  // on a surface facing the sun, W/m^2 (linear RGB)
  float sunAngularRadiusDeg = 0.27f;

  bool sky() const;
  bool sun() const;
  bool any() const { return sky() || sun(); }
  float sunCos() const;  // cos alpha: the sun's cone
  // sky_color, sky_irradiance, sun_direction, sun_color, sun_irradiance,
  // sun_angular_radius: the names, help and ranges every filter shares.
  static std::vector<ParamSpec> specs();
  static SkySun fromParams(const ParamValues& v);
};

// H_out at x (already lifted off the surface) with unit normal n: `rays`
// cosine-weighted rays for the sky and `rays` in the sun's cone, keyed by `key`.
glm::vec3 skySunIrradianceAt(const SkySun& o, const RayCaster& caster, const glm::vec3& x, const glm::vec3& n,
                             int rays, uint32_t key);

// The mean of H_out over each face (rays from points spread over the face;
// 0 for unusable faces and without sky and sun).
std::vector<glm::vec3> patchSkySunIrradiance(const Scene& s, const RayCaster& caster, const SkySun& o, int rays,
                                             uint32_t seed, const Progress& progress = Progress(nullptr));

// H_out at every vertex of `part` (the others, and vertices without a usable
// face, 0), from the per-vertex ray origins (vertexRayOrigins).
std::vector<glm::vec3> vertexSkySunIrradiance(const Scene& s, const RayCaster& caster, const SkySun& o, int rays,
                                              uint32_t seed, const VertexPart& part = VertexPart(),
                                              const Progress& progress = Progress(nullptr));

// The power entering the scene from outside, as luminance: sum over faces
// of A_f luminance(H_out,f) (local units of area).
double enteringPower(const Scene& s, const std::vector<glm::vec3>& Hout);

}  // namespace gi
