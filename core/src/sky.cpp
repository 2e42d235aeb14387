#include "gi/sky.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "gi/color.h"
#include "gi/direct.h"
#include "gi/sampling.h"
#include "hit_origin.h"

namespace gi {

bool SkySun::sky() const { return luminance(skyRadiance) > 0.f; }
bool SkySun::sun() const { return luminance(sunIrradiance) > 0.f; }
float SkySun::sunCos() const { return std::cos(glm::radians(sunAngularRadiusDeg)); }

void SkySun::check() const {
  auto colour = [](const glm::vec3& c) { return finite3(c) && c.r >= 0.f && c.g >= 0.f && c.b >= 0.f; };
  if (!colour(skyRadiance)) throw std::invalid_argument("the sky's radiance must be finite and >= 0 in every channel");
  if (!colour(sunIrradiance)) throw std::invalid_argument("the sun's irradiance must be finite and >= 0 in every channel");
  if (!sun()) return;
  if (!finite3(sunDirection) || !(std::fabs(glm::length(sunDirection) - 1.f) < 1e-3f))
    throw std::invalid_argument("sun_direction must be a finite vector of unit length (gi::unitDirection makes one)");
  requireInRange(specs(), "sun_angular_radius", sunAngularRadiusDeg);
}

std::vector<ParamSpec> SkySun::specs() {
  return {
      {.name = "sky_color", .label = "Sky colour",
       .help = "Colour of a uniform sky around the scene (sRGB).",
       .type = ParamType::Color, .defVec = glm::vec3(1.f)},
      {.name = "sky_irradiance", .label = "Sky irradiance (W/m^2)",
       .help = "Irradiance the sky gives an unoccluded surface (pi x its radiance); 0 = no sky. The sky covers the "
               "whole sphere (no ground): a surface of any orientation with nothing around it gets all of it.",
       .type = ParamType::Float, .def = 0.0, .min = 0.0, .max = 1e9},
      {.name = "sun_direction", .label = "Sun direction",
       .help = "Direction towards the sun.",
       .type = ParamType::Direction, .defVec = glm::vec3(0.3f, 1.f, 0.2f)},
      {.name = "sun_color", .label = "Sun colour",
       .help = "Colour of the sun (sRGB): scales each channel of its irradiance (linear colour).",
       .type = ParamType::Color, .defVec = glm::vec3(1.f)},
      {.name = "sun_irradiance", .label = "Sun irradiance (W/m^2)",
       .help = "Irradiance of a white sun on a surface facing it (times the linear sun colour per channel); 0 = no "
               "sun.",
       .type = ParamType::Float, .def = 0.0, .min = 0.0, .max = 1e9},
      {.name = "sun_angular_radius", .label = "Sun angular radius (deg)",
       .help = "0 gives a sharp directional light.",
       .type = ParamType::Float, .def = 0.27, .min = 0.0, .max = 45},
  };
}

SkySun SkySun::fromParams(const ParamValues& v) {
  auto lin = [](glm::vec3 c) { return glm::vec3(srgbToLinear(c.r), srgbToLinear(c.g), srgbToLinear(c.b)); };
  SkySun o;
  o.skyRadiance = lin(v.getVec("sky_color")) * float(v.getFloat("sky_irradiance") / M_PI);
  o.sunDirection = v.getDirection("sun_direction");
  o.sunIrradiance = lin(v.getVec("sun_color")) * float(v.getFloat("sun_irradiance"));
  o.sunAngularRadiusDeg = float(v.getFloat("sun_angular_radius"));
  return o;
}

namespace {

// Sample k of a padded sequence: dimension `skyDim` for the sky's cosine
// direction, skyDim + 1 for the direction in the sun's cone.
// With openings: the sky only where it is still sampled by cosine rays,
// and only through no portal (the portals' light is the direct light's).
glm::vec3 skySunSample(const SkySun& o, const RayCaster& caster, const glm::vec3& x, const Frame& frame,
                       const glm::vec3& n, const Frame& sunFrame, float sunCos, float sunScale, const PaddedSobol& smp, uint32_t k,
                       uint32_t skyDim, const SkyOpenings* op) {
  glm::vec3 H(0.f);
  Ray ray;
  ray.o = x;
  if (o.sky() && (!op || op->rest)) {
    ray.d = frame.toWorld(cosineHemisphere(smp(k, skyDim)));
    ray.tfar = std::numeric_limits<float>::infinity();
    if (!caster.occluded(ray) && (!op || op->crossed(ray.o, ray.d) < 0)) H += o.skyRadiance * float(M_PI);
  }
  if (o.sun()) {
    ray.d = sunFrame.toWorld(uniformCone(smp(k, skyDim + 1), sunCos));
    const float c = glm::dot(ray.d, n);
    ray.tfar = std::numeric_limits<float>::infinity();
    if (c > 0.f && !caster.occluded(ray)) H += o.sunIrradiance * (c * sunScale);
  }
  return H;
}

}  // namespace

namespace {

constexpr uint32_t kPortalSalt = 0x50f7a1u;  // the portals' shadow rays: other seeds than the emitters'

glm::vec3 skySunAt(const SkySun& o, const RayCaster& caster, const glm::vec3& x, const glm::vec3& n, int rays,
                   uint32_t key, const SkyOpenings* op) {
  if (!o.any() || rays < 1) return glm::vec3(0.f);
  const PaddedSobol smp(hash3(key, 0x5c1u, 0x5e2u));
  const Frame frame(n), sunFrame(o.sunDirection);
  const float sunCos = o.sunCos(), sunScale = sunDiskScale(o.sunAngularRadiusDeg);
  glm::dvec3 sum(0.0);
  for (int k = 0; k < rays; ++k)
    sum += glm::dvec3(skySunSample(o, caster, x, frame, n, sunFrame, sunCos, sunScale, smp, uint32_t(k), 0, op));
  return glm::vec3(sum / double(rays));
}

}  // namespace

glm::vec3 skySunIrradianceAt(const SkySun& o, const RayCaster& caster, const glm::vec3& x, const glm::vec3& n,
                             int rays, uint32_t key) {
  return skySunAt(o, caster, x, n, rays, key, nullptr);
}

std::vector<glm::vec3> patchSkySunIrradiance(const Scene& s, const RayCaster& caster, const SkySun& o, int rays,
                                             uint32_t seed, const Progress& progress, const SkyOpenings* openings) {
  if (openings && !openings->any()) openings = nullptr;
  // The sky through the portals, as the light of luminaires (its own seeds).
  std::vector<glm::vec3> H = openings && rays >= 1 ? patchDirectIrradiance(s, caster, rays, seed ^ kPortalSalt,
                                                                           progress.sub(0.0, 0.5), nullptr, openings)
                                                   : std::vector<glm::vec3>(s.faceCount(), glm::vec3(0.f));
  if (!o.any() || rays < 1 || (openings && !openings->rest && !o.sun())) return H;
  const auto ok = usableFaceMask(s);
  const float eps = float(sceneScale(s).rayEpsilon), sunCos = o.sunCos(), sunScale = sunDiskScale(o.sunAngularRadiusDeg);
  const Frame sunFrame(o.sunDirection);
  parallelBlocks(s.faceCount(), openings ? progress.sub(0.5, 1.0) : progress, "sky and sun", [&](size_t b, size_t e) {
    for (size_t f = b; f < e; ++f) {
      if (!ok[f]) continue;
      const glm::vec3 n = glm::normalize(faceNormalUnnormalized(s, f));
      const Frame frame(n);
      // Point k on the patch (dimension 0), its sky and sun directions (1, 2).
      const PaddedSobol smp(hash3(uint32_t(f), seed, 0x5c3u));
      const FacePoints points(s, uint32_t(f), n, eps, caster);
      glm::dvec3 sum(0.0);
      for (int k = 0; k < rays; ++k) {
        const glm::vec3 x = points.at(smp(uint32_t(k), 0)) + n * eps;
        sum += glm::dvec3(skySunSample(o, caster, x, frame, n, sunFrame, sunCos, sunScale, smp, uint32_t(k), 1, openings));
      }
      H[f] += glm::vec3(sum / double(rays));
    }
  });
  return H;
}

std::vector<glm::vec3> vertexSkySunIrradiance(const Scene& s, const RayCaster& caster, const SkySun& o, int rays,
                                              uint32_t seed, const VertexPart& part, const Progress& progress,
                                              const SkyOpenings* openings) {
  if (openings && !openings->any()) openings = nullptr;
  std::vector<glm::vec3> H = openings && rays >= 1 ? vertexDirectIrradiance(s, caster, rays, seed ^ kPortalSalt,
                                                                            progress.sub(0.0, 0.5), part, openings)
                                                   : std::vector<glm::vec3>(s.vertexCount(), glm::vec3(0.f));
  if (!o.any() || rays < 1 || (openings && !openings->rest && !o.sun())) return H;
  const VertexMaterial mat = vertexMaterial(s);
  const std::vector<glm::vec3> origins = vertexRayOrigins(s, mat.n, float(sceneScale(s).rayEpsilon));
  parallelBlocks(s.vertexCount(), openings ? progress.sub(0.5, 1.0) : progress, "sky and sun at vertices",
                 [&](size_t b, size_t e) {
    for (size_t v = b; v < e; ++v)
      if (mat.valid[v] && part.contains(v, s.vertexCount()))
        H[v] += skySunAt(o, caster, origins[v], mat.n[v], rays, hash3(uint32_t(v), seed, 0x5c4u), openings);
  });
  return H;
}

std::vector<glm::vec3> seenPartSkySunIrradiance(const Scene& s, const RayCaster& caster, const SkySun& o, int rays,
                                                uint32_t seed, const std::vector<std::vector<glm::vec3>>& points,
                                                const SkyOpenings* openings) {
  if (points.size() != s.faceCount()) throw std::logic_error("seen points: one list per face");
  if (openings && !openings->any()) openings = nullptr;
  std::vector<glm::vec3> H = openings && rays >= 1
                                 ? seenPartDirectIrradiance(s, caster, rays, seed ^ kPortalSalt, points, openings)
                                 : std::vector<glm::vec3>(s.faceCount(), glm::vec3(0.f));
  if (!o.any() || rays < 1 || (openings && !openings->rest && !o.sun())) return H;
  const float eps = float(sceneScale(s).rayEpsilon);
  parallelBlocks(s.faceCount(), Progress(nullptr), "sky and sun of seen parts", [&](size_t b, size_t e) {
    for (size_t f = b; f < e; ++f) {
      const size_t m = points[f].size();
      if (m == 0) continue;
      const glm::vec3 n = glm::normalize(faceNormalUnnormalized(s, f));
      const int each = std::max(1, rays / int(m));
      glm::dvec3 sum(0.0);
      for (size_t k = 0; k < m; ++k)
        sum += glm::dvec3(skySunAt(o, caster, points[f][k] + n * eps, n, each,
                                   hash3(uint32_t(f), seed ^ uint32_t(k), 0x5c5u), openings));
      H[f] += glm::vec3(sum / double(m));
    }
  });
  return H;
}

double enteringPower(const Scene& s, const std::vector<glm::vec3>& Hout) {
  const auto ok = usableFaceMask(s);
  double P = 0;
  for (size_t f = 0; f < Hout.size() && f < s.faceCount(); ++f)
    if (ok[f]) P += faceArea(s, f) * luminance(Hout[f]);
  return P;
}

}  // namespace gi
