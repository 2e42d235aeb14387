// Perfectly specular surfaces: a mirror (reflection, R = the face's colour)
// and glass (a smooth dielectric with the exact unpolarised Fresnel
// reflectance, refraction by Snell's law and total internal reflection).
// Face normals point from the glass into the air; a glass object must be a
// closed mesh. Both interactions are sampled: glass reflects with probability
// F and refracts with 1 - F, so the weight of either choice is the tint.
#pragma once
#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi {

inline glm::vec3 reflectDir(const glm::vec3& d, const glm::vec3& n) { return d - 2.f * glm::dot(d, n) * n; }

// Fresnel reflectance of unpolarised light (Born and Wolf; pbrt-v4
// FrDielectric) for an incident cosine cosI > 0 and eta = n_incident /
// n_transmitted. Returns 1 beyond the critical angle (total internal reflection).
float fresnelDielectric(float cosI, float eta);

struct SpecularEvent {
  glm::vec3 d{0.f};         // new direction (unit)
  glm::vec3 weight{0.f};    // throughput factor of this choice (flux; see radianceScale)
  bool transmitted = false; // refracted into the other medium
  bool totalInternal = false;
  float radianceScale = 1.f;  // eta^2 for radiance carried against the light (1 for flux)
};

// The interaction of a ray of direction d (unit) with a mirror or glass face
// of unit normal n (the face's outside), tint the face's specular colour and
// ior its index of refraction; u in [0,1) picks reflection or refraction.
SpecularEvent scatterSpecular(Material m, const glm::vec3& d, const glm::vec3& n, const glm::vec3& tint, float ior, float u);

inline bool isSpecular(Material m) { return m == Material::Mirror || m == Material::Glass; }
// The surfaces a caustic path L S+ D passes through: mirror and glass, and
// glossy faces (gi/glossy.h), counted as S; photons are stored, and radiosity
// lives, on the other (diffuse) faces only.
inline bool isCausticSurface(Material m) { return m != Material::Diffuse; }
// Whether any face of the scene has a material `test` accepts (isSpecular,
// isCausticSurface): one pass over the faces.
template <class Test>
bool anyFaceMaterial(const Scene& s, Test test) {
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (test(s.faceMaterial(f))) return true;
  return false;
}

}  // namespace gi
