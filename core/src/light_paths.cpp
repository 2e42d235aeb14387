#include "gi/light_paths.h"

namespace gi {

ParamSpec lightPathSplitSpec() {
  return {.name = "light_path_split", .label = "Split by light path",
          .help = "Also write the radiosity split by the path the light took, in Heckbert's notation (Heckbert 1990, "
                  "'Adaptive radiosity textures for bidirectional ray tracing'; L light, D diffuse, S specular "
                  "bounce, E eye): Radiosity_emitted (L E, the vertex's own emission), Radiosity_direct (L D E: "
                  "light reaching the vertex straight from an emitter, sky, sun or point light), Radiosity_caustic "
                  "(L S+ D E: through mirror, glass or glossy bounces only) and Radiosity_indirect (diffuse interreflection, every "
                  "path with another diffuse bounce: L D D+ E, L S D D E, ...). RGB per-vertex attributes in W/m^2 "
                  "whose sum is Radiosity (within float rounding). Costs four more attributes (48 bytes a vertex), "
                  "no extra rays.",
          .type = ParamType::Bool, .def = false};
}

}  // namespace gi
