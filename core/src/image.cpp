#include "gi/image.h"

#include <png.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "gi/color.h"

namespace gi {

namespace {

struct FileCloser {
  void operator()(FILE* f) const { if (f) std::fclose(f); }
};
using File = std::unique_ptr<FILE, FileCloser>;

File openFile(const std::string& path, const char* mode) {
  File f(std::fopen(path.c_str(), mode));
  if (!f) throw std::runtime_error("cannot open '" + path + "': " + std::strerror(errno));
  return f;
}

bool littleEndian() {
  const uint16_t one = 1;
  uint8_t b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

uint32_t byteSwap(uint32_t x) { return (x >> 24) | ((x >> 8) & 0xff00u) | ((x << 8) & 0xff0000u) | (x << 24); }

// libpng's own handlers print on stderr ("libpng error: Write Error"), which
// would break a front end's one-line error: its error and warning go here
// instead, the error with the errno of the write that failed.
struct PngFailure {
  char message[128];
  int err;
};

[[noreturn]] void pngError(png_structp png, png_const_charp message) {
  auto* f = static_cast<PngFailure*>(png_get_error_ptr(png));
  f->err = errno;
  std::snprintf(f->message, sizeof f->message, "%s", message ? message : "");
  png_longjmp(png, 1);
}

void pngWarning(png_structp, png_const_charp) {}

}  // namespace

float imageExposure(const Image& img, double exposureParam, const std::vector<uint8_t>& mask) {
  if (exposureParam > 0.0) return float(exposureParam);
  std::vector<float> lum;
  lum.reserve(img.px.size());
  for (size_t i = 0; i < img.px.size(); ++i)
    if (mask.size() != img.px.size() || !mask[i]) lum.push_back(luminance(img.px[i]));
  // Every pixel shows an emitter (inside a furnace, where every face emits):
  // all of them, rather than the exposure of 1 an empty list gives.
  if (lum.empty())
    for (const glm::vec3& p : img.px) lum.push_back(luminance(p));
  return autoExposure(lum.data(), lum.size());
}

std::vector<uint8_t> toSrgb8(const Image& img, float exposure) {
  std::vector<uint8_t> out(img.px.size() * 3);
  for (size_t i = 0; i < img.px.size(); ++i) {
    const Rgb8 c = displayMap(img.px[i], exposure);
    out[3 * i] = c.r;
    out[3 * i + 1] = c.g;
    out[3 * i + 2] = c.b;
  }
  return out;
}

void writePng(const std::string& path, const Image& img, float exposure) {
  if (img.width < 1 || img.height < 1) throw std::runtime_error("cannot write an empty image to '" + path + "'");
  const std::vector<uint8_t> bytes = toSrgb8(img, exposure);
  File f = openFile(path, "wb");
  std::vector<png_bytep> rows(size_t(img.height));
  for (int y = 0; y < img.height; ++y)
    rows[size_t(y)] = const_cast<png_bytep>(bytes.data() + size_t(y) * size_t(img.width) * 3);
  PngFailure failure{{0}, 0};
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &failure, pngError, pngWarning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("libpng could not start writing '" + path + "'");
  }
  // libpng reports errors by longjmp: every object with a destructor is
  // built before this point, so the jump skips none.
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("could not write '" + path + "': " +
                             (failure.err != 0 ? std::string(std::strerror(failure.err)) : "libpng: " + std::string(failure.message)));
  }
  errno = 0;  // what a failing write leaves for pngError
  png_init_io(png, f.get());
  png_set_IHDR(png, info, png_uint_32(img.width), png_uint_32(img.height), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_set_rows(png, info, rows.data());
  png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fflush(f.get()) != 0) throw std::runtime_error("could not write '" + path + "': " + std::strerror(errno));
}

// PFM: "PF\n<w> <h>\n<scale>\n" then float RGB rows from the bottom up; a
// negative scale means little-endian floats.
void writePfm(const std::string& path, const Image& img) {
  if (img.width < 1 || img.height < 1) throw std::runtime_error("cannot write an empty image to '" + path + "'");
  File f = openFile(path, "wb");
  std::fprintf(f.get(), "PF\n%d %d\n%s\n", img.width, img.height, littleEndian() ? "-1.0" : "1.0");
  std::vector<float> row(size_t(img.width) * 3);
  for (int y = img.height - 1; y >= 0; --y) {
    for (int x = 0; x < img.width; ++x)
      for (int k = 0; k < 3; ++k) row[size_t(x) * 3 + size_t(k)] = img.at(x, y)[k];
    if (std::fwrite(row.data(), sizeof(float), row.size(), f.get()) != row.size())
      throw std::runtime_error("could not write '" + path + "': " + std::strerror(errno));
  }
  if (std::fflush(f.get()) != 0) throw std::runtime_error("could not write '" + path + "': " + std::strerror(errno));
}

Image readPfm(const std::string& path) {
  File f = openFile(path, "rb");
  char magic[3] = {0, 0, 0};
  int w = 0, h = 0;
  double scale = 0;
  if (std::fscanf(f.get(), "%2s %d %d %lf", magic, &w, &h, &scale) != 4 || std::strcmp(magic, "PF") != 0 || w < 1 ||
      h < 1 || scale == 0.0 || size_t(w) * size_t(h) > (size_t(1) << 31))
    throw std::runtime_error("'" + path + "' is not a colour PFM file");
  if (std::fgetc(f.get()) == EOF) throw std::runtime_error("'" + path + "' ends after its header");  // the one whitespace byte
  const bool swap = (scale < 0) != littleEndian();
  Image img(w, h);
  std::vector<uint32_t> row(size_t(w) * 3);
  for (int y = h - 1; y >= 0; --y) {
    if (std::fread(row.data(), sizeof(uint32_t), row.size(), f.get()) != row.size())
      throw std::runtime_error("'" + path + "' is shorter than its header says");
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < 3; ++k) {
        uint32_t b = row[size_t(x) * 3 + size_t(k)];
        if (swap) b = byteSwap(b);
        float v;
        std::memcpy(&v, &b, sizeof v);
        img.at(x, y)[k] = v;
      }
  }
  return img;
}

}  // namespace gi
