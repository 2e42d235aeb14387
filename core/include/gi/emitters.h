// Sampling points on area emitters in proportion to their emitted power,
// shared by direct lighting and photon emission.
#pragma once
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/sampling.h"
#include "gi/scene.h"

namespace gi {

class EmitterSampler {
 public:
  explicit EmitterSampler(const Scene& s);
  bool empty() const { return faces_.empty(); }
  double totalPower() const { return total_; }  // sum of luminance(E) * area, W
  struct Sample {
    glm::vec3 p, n;   // point and unit normal (emitting side)
    glm::vec3 E;      // emitted radiosity of the face (RGB, W/m^2)
    float pdfArea;    // probability density per unit area of this point
    uint32_t face;
  };
  // u in [0,1)^2: u.x picks the face (power CDF) and is reused, rescaled, for the point.
  Sample sample(glm::vec2 u) const;
  size_t faceCount() const { return faces_.size(); }
  // The area density sample() uses on `face` (0 for faces that do not emit).
  float pdfArea(uint32_t face) const { return face < pdfOfFace_.size() ? pdfOfFace_[face] : 0.f; }

 private:
  const Scene& s_;
  std::vector<uint32_t> faces_;
  std::vector<double> cdf_;
  std::vector<float> area_;
  std::vector<float> pdfOfFace_;
  double total_ = 0.0;
};

class RayCaster;

// Whether the emitters' light can reach a surface: `rays` cosine-distributed
// rays from points on the emitters' fronts (in proportion to power), each
// ending where it meets a face's front (or glass, from either side: light
// passes it), a face's back, or nothing. Where fewer than 1% meet a front,
// the light is lost: a room whose faces point out of it (a box built as a
// solid), or lights turned away from everything. With `otherLights` (a
// point light, the sky or the sun light the scene anyway) emitters facing
// open space may be meant (lit windows on a façade): then only where half
// the rays or more meet backs, the sign of faces turned the wrong way.
// Returns the warning, naming the counts and the remedy, or nothing.
std::optional<std::string> emitterOrientationWarning(const Scene& s, const RayCaster& caster, bool otherLights,
                                                     int rays = 1024);

// An optional point or spot light (photon mapping and the reference).
struct PointLight {
  glm::vec3 position{0.f};          // relative to the scene origin (see pointLightInLocalUnits)
  glm::vec3 intensity{0.f};         // W/sr, linear RGB; 0 = none
  glm::vec3 spotDirection{0.f, -1.f, 0.f};
  float spotAngleDeg = 180.f;       // half angle of the cone; 180 = a point light
  bool on() const;
  // Throws std::invalid_argument when the light is on and its half angle is
  // not an angle or is below kMinSpotAngleDeg: single precision holds no
  // direction but the axis in such a cone (the cosine of 0.01 degrees
  // rounds to 1), which then carried no power and read as no light at all.
  void check() const;
  static constexpr double kMinSpotAngleDeg = 0.1;
  // The spot's cone around spotDirection (all directions for a point
  // light), tested and sampled in double precision (gi/sampling.h's Cone):
  // a single-precision cosine of a cone of 0.1 degrees is a few percent off
  // its area. Build it once outside a loop over shadow rays.
  Cone spot() const;
};
// Irradiance I cos / r^2 from the point light at the surface point x (unit
// normal n), 0 if the shadow ray is blocked or x lies outside the spot's
// cone. The shadow ray starts at `from` (x lifted off its surface, the ray
// origin), aimed at the light; r and cos are x's own: taken at the lifted
// origin they read the plane eps / h low for a light at height h (a wall
// lamp 5 cm off the wall of a 100 m site -2.8%; an outside audit).
glm::vec3 pointLightIrradiance(const PointLight& L, const RayCaster& caster, const glm::vec3& x, const glm::vec3& from,
                               const glm::vec3& n);

// One-sample estimate of the direct irradiance at x (unit normal n) from the
// emitters: a power-sampled emitter point y, E_y cos(x) cos(y) / (pi r^2 pdf)
// if the shadow ray from -> y is free, else 0 (from: x lifted off its
// surface; the geometry is x's, as for pointLightIrradiance). Points on face
// `skip` are ignored.
glm::vec3 sampleDirectIrradiance(const EmitterSampler& lights, const RayCaster& caster, const glm::vec3& x,
                                 const glm::vec3& from, const glm::vec3& n, glm::vec2 u, float eps,
                                 uint32_t skip = 0xffffffffu);

// Multiple importance sampling, power heuristic (Veach 1997): the weight of a
// sample drawn with density a against another strategy of density b.
// Densities that are infinite, overflow when squared, or are both 0 are
// weighed by their ratio (a point on an emitter's own plane sees it at a
// cosine of about 0: a light sample's density was infinite, and inf / inf
// made the sample NaN and the vertex "not a number"; an outside audit).
inline float powerHeuristic(float a, float b) {
  const float a2 = a * a, b2 = b * b;
  if (std::isfinite(a2 + b2) && a2 + b2 > 0.f) return a2 / (a2 + b2);
  if (!(a > 0.f)) return 0.f;  // this strategy cannot draw the sample (or a NaN density)
  if (!(b > 0.f)) return 1.f;
  const float r = b / a;
  if (std::isnan(r)) return 0.5f;  // both infinite
  return 1.f / (1.f + r * r);
}

// One power-sampled emitter point's irradiance at x (unit normal n),
// weighted for MIS against cosine-weighted direction sampling; 0 if the
// shadow ray is blocked. Adds the shadow rays it casts to *rays.
glm::vec3 sampleLightMIS(const EmitterSampler& lights, const RayCaster& caster, const glm::vec3& x,
                         const glm::vec3& from, const glm::vec3& n, glm::vec2 u, float eps, uint64_t* rays = nullptr);

// The same with multiple importance sampling (power heuristic): one light
// sample and one cosine-weighted direction, whose emitter hits count too.
// Bounded where the plain estimate is heavy-tailed (points on or next to an
// emitter). s is the scene the sampler was built on. The light sample's
// geometry is x's; both rays start at `from` (x lifted off its surface).
glm::vec3 sampleDirectIrradianceMIS(const EmitterSampler& lights, const Scene& s, const RayCaster& caster,
                                    const glm::vec3& x, const glm::vec3& from, const glm::vec3& n, glm::vec2 uLight,
                                    glm::vec2 uDir, float eps);

}  // namespace gi
