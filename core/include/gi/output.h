// Per-vertex results into the common output convention (docs/design.md, "Conventions"):
// quality = the physical scalar, colour = its display mapping.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"
#include "gi/scene_setup.h"

namespace gi {

// Radiometric output (radiosity, irradiance): quality = luminance, colour =
// sRGB(exposure x value). exposureParam <= 0 picks the exposure that maps the
// 99th percentile of the non-emitting vertices' luminance to white (emitters
// would otherwise darken everything they light).
VertexOutput radiometricOutput(const Scene& s, const std::vector<glm::vec3>& rgb, double exposureParam);

// Ambient occlusion / obscurance: quality = value in [0,1], colour = grey
// value x 255 (the usual AO display, not sRGB-encoded).
std::vector<Rgb8> greyColors(const std::vector<float>& value);

struct FormFactorReport;
// Form factors of one face as output: face values F_ij (grey, the face red),
// vertex values (area-weighted mean of incident faces), and a log line.
struct FormFactorOutput {
  std::vector<float> faceF, vertexF;
  std::vector<Rgb8> faceColor;
  std::string summary;
};
// `number`: the face's number in the log (the front end's; default the face's own).
FormFactorOutput formFactorOutput(const Scene& s, const FormFactorReport& rep, uint32_t face,
                                  uint64_t number = UINT64_MAX);

}  // namespace gi
