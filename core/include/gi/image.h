// Linear RGB float images (radiance, W / (m^2 sr)) and their files:
//   - PNG: 8-bit sRGB for viewing, with the filters' exposure convention
//     (gi/color.h: value x exposure, hue-preserving clamp, sRGB; exposure 0 =
//     automatic, the 99th percentile of the luminance maps to white);
//   - PFM (portable float map): the linear values themselves, 32-bit floats,
//     for comparing renders numerically (readable by ImageMagick, GIMP, HDR tools).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace gi {

struct Image {
  int width = 0, height = 0;
  std::vector<glm::vec3> px;  // row-major, row 0 at the top
  Image() = default;
  Image(int w, int h) : width(w), height(h), px(size_t(w) * size_t(h), glm::vec3(0.f)) {}
  glm::vec3& at(int x, int y) { return px[size_t(y) * size_t(width) + size_t(x)]; }
  const glm::vec3& at(int x, int y) const { return px[size_t(y) * size_t(width) + size_t(x)]; }
};

// The exposure for display: exposureParam > 0 is used as is; otherwise the
// 99th percentile of the luminance of the pixels not masked out (mask[i] = 1:
// the pixel shows an emitter, which would darken everything else) maps to 1;
// where every pixel is masked, the percentile of all of them.
float imageExposure(const Image& img, double exposureParam, const std::vector<uint8_t>& mask = {});

// Display bytes (sRGB, RGB interleaved, row 0 at the top).
std::vector<uint8_t> toSrgb8(const Image& img, float exposure);

// Files. Each throws std::runtime_error with one sentence on failure.
void writePng(const std::string& path, const Image& img, float exposure);
void writePfm(const std::string& path, const Image& img);
Image readPfm(const std::string& path);

}  // namespace gi
