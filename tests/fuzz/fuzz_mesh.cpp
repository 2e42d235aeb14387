// libFuzzer target of the mesh readers: every input is given to the PLY, OFF,
// OBJ and STL readers (gi::io::parseMesh). A reader may only return a mesh
// that holds together or throw std::runtime_error; anything else (a crash, a
// sanitizer report, another exception, a broken mesh, a memory or time bomb)
// is a finding.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include "mesh_io.h"

namespace {

[[noreturn]] void broken(const char* what, const char* format) {
  std::fprintf(stderr, "gi_fuzz_mesh: the %s reader returned a mesh with %s\n", format, what);
  std::abort();
}

// What the engine relies on after loading: indices in range (a triangle
// listing a vertex twice is an invalid face every filter leaves out), finite positions,
// attribute arrays of the right lengths.
void checkMesh(const gi::io::LoadedMesh& m, const char* format) {
  const gi::Scene& s = m.scene;
  if (s.faceCount() == 0) broken("no faces", format);
  for (const auto& t : s.triangles)
    if (t.x >= s.vertexCount() || t.y >= s.vertexCount() || t.z >= s.vertexCount())
      broken("a triangle index out of range", format);  // a repeated one is read in its place: filters leave it out
  for (const auto& p : s.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) broken("a non-finite position", format);
  if (m.triangleToFace.size() != s.faceCount()) broken("triangleToFace of the wrong length", format);
  if (!m.attrs.faceColor.empty() && m.attrs.faceColor.size() != s.faceCount()) broken("face colours of the wrong length", format);
  if (!m.attrs.faceQuality.empty() && m.attrs.faceQuality.size() != s.faceCount())
    broken("face qualities of the wrong length", format);
  if (!m.attrs.vertexColor.empty() && m.attrs.vertexColor.size() != s.vertexCount())
    broken("vertex colours of the wrong length", format);
  if (!s.vertexNormals.empty() && s.vertexNormals.size() != s.vertexCount()) broken("normals of the wrong length", format);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  for (const char* format : {"ply", "off", "obj", "stl"}) {
    try {
      checkMesh(gi::io::parseMesh(bytes, format, "input"), format);
    } catch (const std::runtime_error&) {
      // the documented way to refuse a file
    }
  }
  return 0;
}
