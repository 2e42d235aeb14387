// The light-path split of a vertex's radiosity, in Heckbert's regular-expression
// notation for paths from the light L to the eye E through diffuse (D) and
// specular (S) bounces (Heckbert 1990, "Adaptive radiosity textures for
// bidirectional ray tracing"):
//   B = B_emitted (L E) + B_direct (L D E) + B_caustic (L S+ D E) + B_indirect (everything else, L (D|S)* D D E),
// each part rho * H_part at the vertex, H the irradiance from those paths alone.
// S is any mirror, glass or glossy (GGX) event: a glossy lobe is not a delta
// distribution, but the photon tracer stores no photon there either, so both
// photon mapping and the path tracer count a glossy bounce as S.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "gi/params.h"

namespace gi {

enum LightPathKind : int { kPathDirect = 0, kPathCaustic = 1, kPathIndirect = 2, kPathKinds = 3 };

// Radiosity per vertex and path kind (W/m^2, RGB); all empty when the split was not asked for.
struct LightPathSplit {
  std::vector<glm::vec3> emitted, direct, caustic, indirect;
  bool empty() const { return direct.empty(); }
  void assign(size_t nv) {
    for (auto* v : {&emitted, &direct, &caustic, &indirect}) v->assign(nv, glm::vec3(0.f));
  }
};

// The boolean parameter `light_path_split` shared by the filters that can split.
ParamSpec lightPathSplitSpec();

}  // namespace gi
