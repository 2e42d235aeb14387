#include "vertex_file.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "mesh_parts.h"

namespace gi::io {

namespace detail {

// The kept vertex properties as named attributes, as writePly writes them:
// NAME_x, NAME_y, NAME_z (all three present, no scalar NAME) make the vector
// NAME; every other one is the scalar of its name.
std::vector<VertexAttribute> vertexAttributes(const Polygons& p) {
  const std::vector<std::string>& names = p.vertexFloatNames;
  auto find = [&](const std::string& n) {
    return size_t(std::find(names.begin(), names.end(), n) - names.begin());
  };
  std::vector<VertexAttribute> out;
  std::vector<uint8_t> used(names.size(), 0);
  const size_t nv = p.points.size();
  for (size_t k = 0; k < names.size(); ++k) {
    if (used[k]) continue;
    const std::string& n = names[k];
    if (n.size() > 2 && n.compare(n.size() - 2, 2, "_x") == 0) {
      const std::string base = n.substr(0, n.size() - 2);
      const size_t y = find(base + "_y"), z = find(base + "_z");
      if (y < names.size() && z < names.size() && find(base) == names.size()) {
        VertexAttribute a{base, 3, std::vector<float>(3 * nv)};
        for (size_t i = 0; i < nv; ++i) {
          a.values[3 * i] = p.vertexFloats[k][i];
          a.values[3 * i + 1] = p.vertexFloats[y][i];
          a.values[3 * i + 2] = p.vertexFloats[z][i];
        }
        used[k] = used[y] = used[z] = 1;
        out.push_back(std::move(a));
        continue;
      }
    }
  }
  for (size_t k = 0; k < names.size(); ++k)
    if (!used[k]) out.push_back({names[k], 1, p.vertexFloats[k]});
  return out;
}

}  // namespace detail

VertexFile readVertexFile(const std::string& path) {
  namespace fs = std::filesystem;
  using detail::failRead;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (path.empty()) failRead("''", "no file name given");
  if (!fs::exists(st)) failRead(path, "no such file");
  if (!fs::is_regular_file(st)) failRead(path, "not a regular file");
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".ply") failRead(path, "a reference must be a PLY file (per-vertex values are read from PLY only)");
  std::ifstream in(path, std::ios::binary);
  if (!in) failRead(path, "the file cannot be opened (" + std::string(std::strerror(errno)) + ")");
  // Its head checked first, as a mesh's (a 500 MB file of zeros took 4.5 s
  // and 994 MB to be told it is not a PLY; an outside audit).
  const std::string bytes = detail::readCheckedBytes(in, "ply", path);
  const detail::Polygons p = detail::readPly(bytes, path);
  detail::checkPolygons(p, path);
  return {p.points.size(), detail::vertexAttributes(p), p.points};
}

}  // namespace gi::io
