// The glossy material: a rough metal-like reflector, the GGX (Trowbridge and
// Reitz 1975) microfacet BRDF of Walter, Marschner, Li and Torrance 2007,
// "Microfacet Models for Refraction through Rough Surfaces":
//   f(wo, wi) = F(wi . h) D(h) G2(wo, wi) / (4 |n . wo| |n . wi|),   h = (wo + wi) / |wo + wi|,
//   D(h)  = alpha^2 / (pi ((n . h)^2 (alpha^2 - 1) + 1)^2),
//   G2    = 1 / (1 + Lambda(wo) + Lambda(wi))   (Smith, height-correlated; Heitz 2014,
//           "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs"),
//   Lambda(w) = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2,   G1 = 1 / (1 + Lambda),
//   F     = F0 + (1 - F0)(1 - wi . h)^5   (Schlick 1994; F0 = the specular colour).
// Why this model: it is reciprocal (h, G2 and F are symmetric in wo and wi),
// energy conserving (single scattering loses, never gains, energy: the
// directional albedo is <= 1, approaching 1 for a white F0 as alpha -> 0),
// and it is importance-sampled exactly by its distribution of visible
// normals (Heitz 2018, "Sampling the GGX Distribution of Visible Normals"):
//   pdf(wi) = G1(wo) D(h) / (4 |n . wo|),   weight f cos(theta_i) / pdf = F G2 / G1(wo),
// a weight bounded by 1 — low noise at every roughness. Its normalisation is
// the "weak white furnace" identity  integral over the sphere of
// D(h) G1(wo) / (4 |n . wo|) dwi = 1  (Heitz 2014), tested in the unit tests.
// Directions are in the local frame of the surface (z = the normal).
#pragma once
#include <glm/glm.hpp>

namespace gi {

struct GgxLobe {
  float alpha = 0.2f;         // GGX width (roughness^2 in the Disney convention); clamped to [1e-3, 1]
  glm::vec3 F0{1.f};          // reflectance at normal incidence, linear RGB in [0, 1]

  GgxLobe() = default;
  GgxLobe(float a, const glm::vec3& f0);

  float D(const glm::vec3& h) const;
  float lambda(const glm::vec3& w) const;
  float G1(const glm::vec3& w) const { return 1.f / (1.f + lambda(w)); }
  float G2(const glm::vec3& wo, const glm::vec3& wi) const { return 1.f / (1.f + lambda(wo) + lambda(wi)); }
  glm::vec3 fresnel(float cosH) const;

  // BRDF value; 0 unless both directions are above the surface.
  glm::vec3 eval(const glm::vec3& wo, const glm::vec3& wi) const;
  // Solid-angle density with which sample() returns wi (0 below the surface).
  float pdf(const glm::vec3& wo, const glm::vec3& wi) const;

  struct Sample {
    glm::vec3 wi{0.f};
    glm::vec3 weight{0.f};  // f cos(theta_i) / pdf
    float pdf = 0.f;
    bool valid = false;     // false: the reflected direction fell below the surface (the sample is lost: weight 0)
  };
  // Visible-normal sampling for wo above the surface; u in [0,1)^2.
  Sample sample(const glm::vec3& wo, glm::vec2 u) const;
};

}  // namespace gi
