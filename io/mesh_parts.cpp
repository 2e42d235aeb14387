#include "mesh_parts.h"

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string_view>
#include <fstream>
#include <filesystem>
#include <cstring>

namespace gi::io::detail {

void failRead(const std::string& name, const std::string& why) {
  throw std::runtime_error("cannot read " + name + ": " + why + ".");
}

namespace {
// from_chars takes '-' but not '+': drop one '+' that a sign could follow.
bool stripPlus(std::string_view& t) {
  if (!t.empty() && t[0] == '+') {
    t.remove_prefix(1);
    if (!t.empty() && (t[0] == '+' || t[0] == '-')) return false;
  }
  return !t.empty();
}
}  // namespace

namespace {
// Whether a decimal number that from_chars found out of range is below the
// smallest double rather than above the largest: its leading digit's
// decimal exponent is negative. The exponent saturates (1e-99999999999).
bool belowRange(std::string_view t) {
  if (!t.empty() && t[0] == '-') t.remove_prefix(1);
  long long lead = 0;
  bool seen = false;  // a nonzero digit
  size_t i = 0;
  for (; i < t.size() && std::isdigit(static_cast<unsigned char>(t[i])); ++i)
    if (seen) ++lead;
    else if (t[i] != '0') seen = true;
  if (i < t.size() && t[i] == '.')
    for (++i; i < t.size() && std::isdigit(static_cast<unsigned char>(t[i])); ++i)
      if (!seen) {
        --lead;
        if (t[i] != '0') seen = true;
      }
  if (!seen) return false;
  long long e = 0;
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    const bool neg = i < t.size() && t[i] == '-';
    if (i < t.size() && (t[i] == '-' || t[i] == '+')) ++i;
    for (; i < t.size() && std::isdigit(static_cast<unsigned char>(t[i])); ++i) e = std::min(e * 10 + (t[i] - '0'), 1000000LL);
    if (neg) e = -e;
  }
  return lead + e < 0;
}
}  // namespace

bool parseDouble(std::string_view t, double& v) {
  if (!stripPlus(t)) return false;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (end != t.data() + t.size()) return false;
  // A number too small for a double (1e-400) is 0, as a file that wrote it
  // meant, not a value out of range.
  if (ec == std::errc::result_out_of_range && belowRange(t)) {
    v = t[0] == '-' ? -0.0 : 0.0;
    return true;
  }
  return ec == std::errc() && std::isfinite(v);
}

bool parseInt(std::string_view t, long long& v) {
  if (!stripPlus(t)) return false;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return ec == std::errc() && end == t.data() + t.size();
}

bool parseNonFinite(std::string_view t) {
  if (!t.empty() && (t[0] == '+' || t[0] == '-')) t.remove_prefix(1);
  std::string s(t);
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s == "nan" || s == "inf" || s == "infinity";
}

bool isNumber(std::string_view t) {
  if (parseNonFinite(t)) return true;
  if (!stripPlus(t)) return false;
  double v = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return ec != std::errc::invalid_argument && end == t.data() + t.size();
}

bool fitsFloat(double v) { return std::isfinite(v) && std::fabs(v) <= double(FLT_MAX); }

uint32_t repeatedIndex(const std::vector<uint32_t>& face) {
  if (face.size() <= 16) {
    for (size_t a = 0; a < face.size(); ++a)
      for (size_t b = a + 1; b < face.size(); ++b)
        if (face[a] == face[b]) return face[a];
    return kNone;
  }
  std::vector<uint32_t> s = face;
  std::sort(s.begin(), s.end());
  const auto it = std::adjacent_find(s.begin(), s.end());
  return it == s.end() ? kNone : *it;
}

void checkPolygons(const Polygons& p, const std::string& name) {
  for (size_t v = 0; v < p.points.size(); ++v) {
    const glm::dvec3& q = p.points[v];
    if (!fitsFloat(q.x) || !fitsFloat(q.y) || !fitsFloat(q.z))
      failRead(name, "vertex " + std::to_string(v) + " has a coordinate that is not a finite number within float range");
  }
  for (size_t v = 0; v < p.normals.size(); ++v)
    if (!std::isfinite(p.normals[v].x) || !std::isfinite(p.normals[v].y) || !std::isfinite(p.normals[v].z))
      failRead(name, "vertex " + std::to_string(v) + " has a normal that is not finite");
  std::vector<uint32_t> face;
  for (size_t f = 0; f + 1 < p.faceStart.size(); ++f) {
    face.assign(p.index.begin() + p.faceStart[f], p.index.begin() + p.faceStart[f + 1]);
    if (face.size() < 3) failRead(name, "face " + std::to_string(f) + " has fewer than 3 vertices");
    for (uint32_t v : face)
      if (v >= p.points.size())
        failRead(name, "face " + std::to_string(f) + " uses vertex " + std::to_string(v) + ", outside the " +
                           std::to_string(p.points.size()) + " vertices");
  }
}

std::string shortNumber(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

bool colourChannel(double scaled, uint8_t& byte) {
  if (!(scaled >= -0.5 && scaled < 255.5)) return false;
  byte = uint8_t(std::clamp(std::lround(scaled), 0L, 255L));
  return true;
}

std::string notAnStl(uint32_t n, uint64_t size) {
  return size < 84 ? "not an STL file (too short for a binary STL, and no 'solid' line)"
                   : "a binary STL whose triangle count (" + std::to_string(n) + ", so " +
                         std::to_string(84 + 50 * uint64_t(n)) + " bytes) does not match its " +
                         std::to_string(size) + " bytes, and not an ASCII STL ('solid')";
}

std::string quoted(std::string_view text) {
  std::string s = "'";
  for (size_t i = 0; i < text.size() && i < 60; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f) {
      static const char* kHex = "0123456789abcdef";
      s += "\\x";
      s += kHex[c >> 4];
      s += kHex[c & 15];
    } else {
      s += char(c);
    }
  }
  return s + (text.size() > 60 ? "...'" : "'");
}

// What the first bytes of a file of `size` bytes can already rule out, with
// the messages the readers give for the whole file.
void checkHead(std::string_view head, const std::string& ext, uintmax_t size, const std::string& name) {
  if (size == 0) failRead(name, "the file is empty (0 bytes)");
  if (ext == "ply") {
    if (head.substr(0, 4) != "ply\n" && head.substr(0, 5) != "ply\r\n")
      failRead(name, "not a PLY file (the first line is not 'ply')");
  } else if (ext == "stl") {
    uint32_t n = 0;
    if (head.size() >= 84) std::memcpy(&n, head.data() + 80, 4);
    const size_t start = head.find_first_not_of(" \t\r\n");
    // Where the head does not show the first word whole (blank, or the word
    // across its end), the reader decides (an outside review: 5,000 blank
    // lines before 'solid' were refused).
    const bool undecided = head.size() < size && (start == std::string_view::npos || start + 5 > head.size());
    const bool ascii = undecided || (start != std::string_view::npos && head.substr(start, 5) == "solid");
    if (!ascii && !(size >= 84 && size == 84 + 50 * uintmax_t(n)))
      failRead(name, detail::notAnStl(n, size));
  } else if (const size_t nul = head.find('\0'); nul != std::string_view::npos) {  // OBJ, OFF: text
    // Binary OFF says so on its first line ("OFF BINARY"): name it rather
    // than the zero bytes that follow.
    if (ext == "off" && head.substr(0, std::min(head.find('\n'), nul)).find("BINARY") != std::string_view::npos)
      failRead(name, "binary OFF is not supported (only ASCII [C][N]OFF); convert it to ASCII OFF or PLY");
    failRead(name, "not a text file (a zero byte at offset " + std::to_string(nul) + ")");
  }
}

std::string readCheckedBytes(std::ifstream& in, const std::string& ext, const std::string& path) {
  std::error_code ec;
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) failRead(path, "its size cannot be read (" + ec.message() + ")");
  // Its first bytes are looked at before the rest is read: a large file that
  // is no mesh at all (a 300 MB file of zeros took 503 MB and 2.8 s to be
  // told it is not a PLY; an outside audit) is refused at once.
  std::string bytes(size_t(std::min<uintmax_t>(size, 4096)), '\0');
  in.read(bytes.data(), std::streamsize(bytes.size()));
  if (!in) failRead(path, "the file cannot be read");
  checkHead(bytes, ext, size, path);
  bytes.resize(size_t(size));
  const size_t head = size_t(std::min<uintmax_t>(size, 4096));
  in.read(bytes.data() + head, std::streamsize(size - head));
  if (!in || in.gcount() != std::streamsize(size - head)) failRead(path, "the file cannot be read (it changed while being read?)");
  return bytes;
}

}  // namespace gi::io::detail
