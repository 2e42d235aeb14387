#include "mesh_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include <glm/gtc/constants.hpp>

#include "atomic_file.h"
#include "gi/color.h"
#include "mesh_parts.h"
#include "output_files.h"
#include "vertex_file.h"

namespace gi::io {

using detail::Counts;
using detail::failRead;
using detail::Polygons;

namespace {

// Double points: the OBJ reader keeps full precision for far-off meshes.
struct Traits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3f;
};
using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<Traits>;

[[noreturn]] void failWrite(const std::string& path, const std::string& why) {
  throw std::runtime_error("cannot write " + path + ": " + why + ".");
}

std::string lowerExtension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  if (!e.empty() && e[0] == '.') e.erase(0, 1);
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return e;
}

// OpenMesh's silence: its readers print warnings (one per skipped face or
// unknown keyword) on std::cerr, which would break the one-line error of the
// command-line tool. Our own checks say what is wrong instead.
struct QuietOpenMesh {
  QuietOpenMesh() { ::omerr().disable(), ::omlog().disable(), ::omout().disable(); }
  ~QuietOpenMesh() { ::omerr().enable(), ::omlog().enable(), ::omout().enable(); }
};

// What OpenMesh reads of an OBJ, set as the file gives it: the coordinates
// in double (OpenMesh reads them as float: a plane 0.1 wide at 1e6 came out
// 0.125 wide), each vertex OpenMesh appended for a non-manifold face taking
// the coordinates of the file's vertex at that corner (OpenMesh keeps the
// faces and their corners in the file's order: checked, else its own
// points stand); and face colours from the materials' Kd where every face
// has one. Kd is a linear reflectance (the MTL format's diffuse
// reflectivity), so it is stored as the sRGB byte whose linear value it is.
void objAsTheFileSays(const Counts& file, const std::map<std::string, glm::dvec3>& kd, Polygons& p) {
  std::vector<glm::dvec3> exact(p.points.size());
  std::vector<uint8_t> known(p.points.size(), 0);
  for (size_t i = 0; i < file.points.size() && i < exact.size(); ++i) exact[i] = file.points[i], known[i] = 1;
  bool same = p.index.size() == file.corners.size();
  for (size_t k = 0; same && k < p.index.size(); ++k) {
    const uint32_t v = p.index[k], f = file.corners[k];
    if (v < file.points.size()) same = v == f;
    else if (v < exact.size() && f < file.points.size()) exact[v] = file.points[f], known[v] = 1;
  }
  if (same && std::all_of(known.begin(), known.end(), [](uint8_t b) { return b != 0; })) p.points = exact;
  // The copies themselves become the file's vertices again, so that the
  // output's vertices are the file's, as a PLY's and an OFF's are (20
  // triangles on one edge came out as 79 vertices for the file's 22, 19 of
  // the file's with no face and their values on the copies, and an error map
  // against the same mesh read from OFF refused; an outside audit).
  const size_t nFile = file.points.size();
  if (same && p.points.size() > nFile &&
      std::all_of(file.corners.begin(), file.corners.end(), [&](uint32_t f) { return f < nFile; })) {
    p.index = file.corners;
    p.points.assign(file.points.begin(), file.points.end());
    if (p.normals.size() > nFile) p.normals.resize(nFile);
    if (p.vertexColor.size() > nFile) p.vertexColor.resize(nFile);
    if (p.vertexSelected.size() > nFile) p.vertexSelected.resize(nFile);
  }
  std::vector<glm::u8vec3> colors;
  for (const int mtl : file.faceMaterial) {
    const auto it = mtl >= 0 ? kd.find(file.materialNames[size_t(mtl)]) : kd.end();
    if (it == kd.end()) return;  // a face without a Kd: no face colours (vertex colours or the constant apply)
    glm::u8vec3 c;
    for (int k = 0; k < 3; ++k) c[k] = uint8_t(std::lround(255.0 * double(linearToSrgb(float(it->second[k])))));
    colors.push_back(c);
  }
  if (colors.size() + 1 == p.faceStart.size()) p.faceColor = std::move(colors);
}

// OBJ and STL through OpenMesh, after checkObj / checkStl. Vertex indices are
// OpenMesh's: the file's, plus copies of non-manifold vertices appended. An
// OBJ is read from its path when it has one, so that OpenMesh finds its
// material library (face colours from Kd).
// An ASCII STL from checkStl's corners, in double: equal corners merged
// (each new one numbered as it first appears) and triangles left with a
// repeated corner dropped, as OpenMesh does, but without its float
// coordinates (a plane 0.1 wide at 1e6 came out 0.125 wide).
Polygons asciiStl(const Counts& file) {
  Polygons p;
  std::map<std::array<double, 3>, uint32_t> id;
  uint32_t corner[3];
  for (size_t t = 0; t + 2 < file.points.size(); t += 3) {
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3& q = file.points[t + size_t(k)];
      const auto [it, fresh] = id.emplace(std::array<double, 3>{q.x, q.y, q.z}, uint32_t(p.points.size()));
      if (fresh) p.points.push_back(q);
      corner[k] = it->second;
    }
    if (corner[0] == corner[1] || corner[1] == corner[2] || corner[0] == corner[2]) continue;
    p.index.insert(p.index.end(), corner, corner + 3);
    p.faceStart.push_back(uint32_t(p.index.size()));
  }
  return p;
}

Polygons readWithOpenMesh(std::string_view bytes, const std::string& ext, const std::string& name, const std::string& path) {
  Counts declared;
  bool stlBinary = false;
  if (ext == "obj") declared = detail::checkObj(bytes, name);
  else declared = detail::checkStl(bytes, name, stlBinary);
  if (ext == "stl" && !stlBinary) return asciiStl(declared);
  PolyMesh m;
  OpenMesh::IO::Options opt;
  // OpenMesh 9's STL reader reports colours it does not set: ask for none.
  // An OBJ's colours: a vertex's only where every vertex has one (OpenMesh
  // gives the others black), a face's from its material's Kd, read here (it
  // leaves a face without one undefined: different on every run).
  const bool objColors = ext == "obj" && declared.vertices > 0 && declared.coloredVertices == declared.vertices;
  if (ext == "obj") {
    if (objColors) {
      m.request_vertex_colors();
      opt += OpenMesh::IO::Options::VertexColor;
    }
    m.request_vertex_normals();
    opt += OpenMesh::IO::Options::VertexNormal;
  } else if (stlBinary) {
    opt += OpenMesh::IO::Options::Binary;
  }
  std::string text(bytes);
  std::map<std::string, glm::dvec3> kd;  // material -> Kd, the first library's that defines it
  std::vector<std::string> warnings;
  if (ext == "obj" && !path.empty()) {
    // Each library beside the file, or where an absolute path says (OpenMesh
    // opens only the first: an absolute one was dropped in silence whenever
    // the OBJ's own path had a folder in it; an outside audit). The faces'
    // colours are the Kd read here.
    const std::string folder = path.substr(0, path.rfind('/') + 1);
    for (const std::string& lib : declared.materialFiles) {
      const std::string file = std::filesystem::path(lib).is_absolute() ? lib : folder + lib;
      std::error_code ec;
      if (!std::filesystem::exists(file, ec)) {  // the mesh is read without it, and the log says so
        warnings.push_back(name + ": its material library " + lib +
                           " was not found (beside it, or at that absolute path): its materials' colours are not read");
        continue;
      }
      std::string material;
      try {
        // A pipe or a device would block OpenMesh or never end; 64 MB is far beyond any material library.
        material = files::readTextFile(file, "material library", size_t(64) << 20);
      } catch (const std::invalid_argument& e) {
        failRead(name, e.what());
      }
      for (const auto& [mtl, value] : detail::checkMaterial(material, file)) kd.emplace(mtl, value);
    }
  } else {
    for (size_t at : declared.materialLines) text[at] = '#';  // from memory: no library is opened
  }
  // Faces listing a vertex twice are hidden from OpenMesh (it drops or
  // rewrites them) and put back in their places below; the text is then read
  // from memory, the material libraries' Kd being ours anyway.
  for (size_t at : declared.repeatLines) text[at] = '#';
  if (!declared.repeatLines.empty())
    for (size_t at : declared.materialLines) text[at] = '#';
  bool ok = false;
  try {
    const QuietOpenMesh quiet;
    if (!path.empty() && ext == "obj" && declared.repeatLines.empty()) {
      ok = OpenMesh::IO::read_mesh(m, path, opt);
    } else {
      std::istringstream in{text};
      ok = OpenMesh::IO::read_mesh(m, in, "." + ext, opt);
    }
  } catch (const std::exception& e) {
    failRead(name, std::string("the reader failed (") + e.what() + ")");
  }
  if (!ok) failRead(name, "OpenMesh could not parse it as a ." + ext + " mesh");
  // STL: OpenMesh merges equal corners and drops triangles left with a repeated corner (no area).
  const size_t hidden = declared.repeatLines.size();
  if (ext == "obj" && (m.n_faces() + hidden != declared.faces || m.n_vertices() < declared.vertices))
    failRead(name, "OpenMesh read " + std::to_string(m.n_faces()) + " faces and " + std::to_string(m.n_vertices()) +
                       " vertices of the " + std::to_string(declared.faces - hidden) + " and " +
                       std::to_string(declared.vertices) + " in the file");
  const bool hasVC = objColors && opt.vertex_has_color(), hasVN = ext == "obj" && opt.vertex_has_normal();

  Polygons p;
  p.points.resize(m.n_vertices());
  for (auto v : m.vertices()) {
    const auto& q = m.point(v);
    p.points[size_t(v.idx())] = glm::dvec3(q[0], q[1], q[2]);
    if (hasVC) p.vertexColor.push_back({m.color(v)[0], m.color(v)[1], m.color(v)[2]});
    if (hasVN) p.normals.push_back({m.normal(v)[0], m.normal(v)[1], m.normal(v)[2]});
  }
  p.index.reserve(m.n_faces() * 3);
  size_t fileFace = 0, fileCorner = 0;
  auto hiddenFaces = [&] {  // the file's faces OpenMesh did not see, up to its next one
    for (; fileFace < declared.faceRepeats.size() && declared.faceRepeats[fileFace]; ++fileFace) {
      const uint32_t n = declared.faceSize[fileFace];
      p.index.insert(p.index.end(), declared.corners.begin() + long(fileCorner), declared.corners.begin() + long(fileCorner + n));
      p.faceStart.push_back(uint32_t(p.index.size()));
      fileCorner += n;
    }
  };
  std::vector<uint8_t> onVisible(p.points.size(), 0);  // a vertex of a face OpenMesh read
  for (auto f : m.faces()) {
    if (hidden) hiddenFaces();
    for (auto v : m.fv_range(f)) p.index.push_back(uint32_t(v.idx())), onVisible[size_t(v.idx())] = 1;
    p.faceStart.push_back(uint32_t(p.index.size()));
    if (hidden && fileFace < declared.faceSize.size()) fileCorner += declared.faceSize[fileFace++];
  }
  if (hidden) hiddenFaces();
  // OpenMesh sets a vertex's normal from the faces it reads: one on no such
  // face (only on a hidden face, or on none) kept uninitialised memory (an
  // outside review: normals of 3.85e13, different on every run). It takes
  // the 'vn' of its first corner in a hidden face, else 0 (no normal).
  if (hasVN && p.normals.size() == p.points.size()) {
    std::vector<uint8_t> set(onVisible);
    for (size_t k = 0, f = 0, end = 0; f < declared.faceSize.size(); ++f) {
      end += declared.faceSize[f];
      for (; k < end; ++k) {
        const uint32_t v = declared.corners[k];
        if (!declared.faceRepeats[f] || v >= set.size() || set[v]) continue;
        const int vn = k < declared.cornerNormal.size() ? declared.cornerNormal[k] : -1;
        if (vn < 0 || size_t(vn) >= declared.normals.size()) continue;
        p.normals[v] = declared.normals[size_t(vn)], set[v] = 1;
      }
    }
    for (size_t v = 0; v < set.size(); ++v)
      if (!set[v]) p.normals[v] = glm::vec3(0.f);
  }
  if (ext == "obj") objAsTheFileSays(declared, kd, p);
  p.warnings = std::move(warnings);
  return p;
}

// Little-endian bytes whatever the host.
struct ByteWriter {
  std::vector<char> buf;
  void u8(uint8_t v) { buf.push_back(char(v)); }
  void u32(uint32_t v) {
    for (int k = 0; k < 4; ++k) buf.push_back(char((v >> (8 * k)) & 0xffu));
  }
  void i32(int32_t v) { u32(uint32_t(v)); }
  void f32(float v) {
    uint32_t u;
    std::memcpy(&u, &v, 4);
    u32(u);
  }
  void f64(double v) {
    uint64_t u;
    std::memcpy(&u, &v, 8);
    u32(uint32_t(u & 0xffffffffu)), u32(uint32_t(u >> 32));
  }
};

}  // namespace

namespace {

LoadedMesh parse(std::string_view bytes, const std::string& ext, const std::string& name, const std::string& path) {
  if (ext != "ply" && ext != "obj" && ext != "off" && ext != "stl")
    failRead(name, "unsupported format '" + ext + "' (expected ply, obj, off or stl)");
  if (bytes.empty()) failRead(name, "the file is empty (0 bytes)");
  const Polygons p = ext == "ply"   ? detail::readPly(bytes, name)
                     : ext == "off" ? detail::readOff(bytes, name)
                                    : readWithOpenMesh(bytes, ext, name, path);
  detail::checkPolygons(p, name);  // the readers check as they go; this guards what OpenMesh returns
  if (p.faceStart.size() < 2) failRead(name, "the file has no faces");

  LoadedMesh out;  // triangleToFace: index of the polygon as read
  out.warnings = p.warnings;
  const size_t nf = p.faceStart.size() - 1;
  std::vector<glm::uvec3> tris;
  tris.reserve(p.index.size());
  std::vector<glm::uvec3> corners;
  size_t fanned = 0, largest = 0;
  std::vector<uint32_t> once;
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t* v = p.index.data() + p.faceStart[f];
    const size_t n = p.faceStart[f + 1] - p.faceStart[f];
    const size_t before = tris.size();
    if (!detail::cutFace(p.points, v, n, once, corners, tris)) ++fanned, largest = std::max(largest, n);
    for (size_t t = before; t < tris.size(); ++t) {
      out.triangleToFace.push_back(uint32_t(f));
      if (!p.faceColor.empty()) out.attrs.faceColor.push_back(p.faceColor[f]);
      if (!p.faceQuality.empty()) out.attrs.faceQuality.push_back(p.faceQuality[f]);
      if (!p.faceSelected.empty()) out.attrs.faceSelected.push_back(p.faceSelected[f]);
    }
  }
  if (fanned)
    out.warnings.push_back(name + ": " + std::to_string(fanned) + " polygon" + (fanned == 1 ? " is" : "s are") +
                           " concave with more than " + std::to_string(detail::kMaxEarClipped) +
                           " corners, cross" + (fanned == 1 ? "es itself" : " themselves") +
                           " or pass a corner twice (the largest has " +
                           std::to_string(largest) + "): split as a fan from the first corner, whose triangles "
                           "cover area outside the polygon and may face the other way; triangulate it before "
                           "loading");
  out.scene = Scene::fromAbsolute(p.points, std::move(tris));
  out.points = p.points;
  if (auto far = coarseFloatsWarning(p.points))  // gi/scene.h
    out.warnings.push_back(name + ": " + *far + "; write the file with double coordinates, or move the mesh near the origin");
  out.scene.vertexNormals = p.normals;
  out.attrs.vertexColor = p.vertexColor;
  out.attrs.vertexSelected = p.vertexSelected;
  out.attributes = detail::vertexAttributes(p);
  // Recorded layers hold only while they cover the faces, all triangles.
  // (Each count bounded first: counts a hostile header chose to wrap round
  // to the face count would give ranges beyond the faces.)
  size_t layered = 0;
  bool fits = true;
  for (const auto& l : p.layers) {
    fits = fits && l.second <= nf - layered;
    if (fits) layered += l.second;
  }
  if (p.layers.size() > 1 && fits && layered == nf && out.triangleToFace.size() == nf) out.layers = p.layers;
  return out;
}

}  // namespace


LoadedMesh loadMesh(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (path.empty()) failRead("''", "no file name given");
  if (!fs::exists(st)) failRead(path, "no such file");
  if (fs::is_directory(st)) failRead(path, "it is a directory, not a mesh file");
  if (!fs::is_regular_file(st)) failRead(path, "not a regular file");
  const std::string ext = lowerExtension(path);
  if (ext != "ply" && ext != "obj" && ext != "off" && ext != "stl")
    failRead(path, "unsupported format '" + ext + "' (expected ply, obj, off or stl)");
  std::ifstream in(path, std::ios::binary);
  if (!in) failRead(path, "the file cannot be opened (" + std::string(std::strerror(errno)) + ")");
  return parse(detail::readCheckedBytes(in, ext, path), ext, path, path);
}



LoadedMesh parseMesh(std::string_view bytes, const std::string& format, const std::string& name) {
  return parse(bytes, format, name, "");
}

bool plyVertexPropertyOfItsOwn(const std::string& name) {
  static const char* own[] = {"x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "alpha", "quality"};
  return std::any_of(std::begin(own), std::end(own), [&](const char* o) { return name == o; });
}

void writePly(const std::string& path, const Scene& s, const MeshAttributes& attrs,
              const std::vector<float>& vertexQuality, const std::vector<Rgb8>& vertexColor,
              const PlyExtras& extras) {
  // Each optional property is written when its array is not empty (vertex
  // colour falls back to attrs.vertexColor); a wrong size is an error.
  const size_t nv = s.vertexCount(), nf = s.faceCount();
  auto check = [&](size_t n, size_t want, const char* what) {
    if (n != 0 && n != want)
      failWrite(path, std::to_string(n) + " " + what + " for " + std::to_string(want) + " elements");
  };
  check(vertexQuality.size(), nv, "vertex qualities");
  check(vertexColor.size(), nv, "vertex colours");
  check(extras.normals.size(), nv, "vertex normals");
  check(attrs.faceColor.size(), nf, "face colours");
  check(attrs.faceQuality.size(), nf, "face qualities");
  if (vertexColor.empty()) check(attrs.vertexColor.size(), nv, "vertex colours");
  for (const VertexAttribute& a : extras.attributes) check(a.values.size(), nv * size_t(a.components), a.name.c_str());
  if (nv > uint32_t(INT32_MAX)) failWrite(path, "too many vertices for int indices");
  // Every property a name the reader takes back: one token, no name twice.
  std::set<std::string> names;
  for (const VertexAttribute& a : extras.attributes) {
    const bool token = !a.name.empty() && std::all_of(a.name.begin(), a.name.end(), [](unsigned char c) {
      return c > 0x20 && c < 0x7f;
    });
    if (!token) failWrite(path, "an attribute's name is not one word of printable characters");
    for (const std::string& n : a.components == 1 ? std::vector<std::string>{a.name}
                                                  : std::vector<std::string>{a.name + "_x", a.name + "_y", a.name + "_z"})
      if (plyVertexPropertyOfItsOwn(n) || !names.insert(n).second)
        failWrite(path, "the property '" + n + "' would be written twice");
  }

  const bool hasN = !extras.normals.empty(), hasQ = !vertexQuality.empty();
  const bool hasC = !vertexColor.empty() || !attrs.vertexColor.empty();
  const bool hasFC = !attrs.faceColor.empty(), hasFQ = !attrs.faceQuality.empty();
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment written by meshlab-gi\n";
  size_t layered = 0;
  for (const auto& l : extras.layers) layered += l.second;
  if (extras.layers.size() > 1 && layered == nf)
    for (const auto& [layerName, faces] : extras.layers) {
      std::string clean = layerName.empty() ? std::string("layer") : layerName;  // one header line, one token start
      for (char& c : clean)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '_';
      if (clean[0] == ' ' || clean[0] == '\t') clean[0] = '_';
      h << "comment gi_layer " << faces << " " << clean << "\n";
    }
  const bool exact = extras.positions.size() == nv;
  const bool asDouble = exact && std::any_of(extras.positions.begin(), extras.positions.end(), [](const glm::dvec3& q) {
    return double(float(q.x)) != q.x || double(float(q.y)) != q.y || double(float(q.z)) != q.z;
  });
  const char* coord = asDouble ? "double" : "float";
  h << "element vertex " << nv << "\nproperty " << coord << " x\nproperty " << coord << " y\nproperty " << coord << " z\n";
  if (hasN) h << "property float nx\nproperty float ny\nproperty float nz\n";
  if (hasC) h << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (hasQ) h << "property float quality\n";
  for (const VertexAttribute& a : extras.attributes) {
    if (a.components == 1) h << "property float " << a.name << "\n";
    else
      for (const char* c : {"_x", "_y", "_z"}) h << "property float " << a.name << c << "\n";
  }
  h << "element face " << nf << "\nproperty list uchar int vertex_indices\n";
  if (hasFC) h << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (hasFQ) h << "property float quality\n";
  h << "end_header\n";

  ByteWriter w;
  const std::string header = h.str();
  w.buf.assign(header.begin(), header.end());
  w.buf.reserve(header.size() + nv * 28 + nf * 20);
  for (size_t i = 0; i < nv; ++i) {
    if (asDouble) {
      w.f64(extras.positions[i].x), w.f64(extras.positions[i].y), w.f64(extras.positions[i].z);
    } else {
      const glm::vec3 p = exact ? glm::vec3(extras.positions[i]) : glm::vec3(s.toWorld(s.positions[i]));  // absolute
      w.f32(p.x), w.f32(p.y), w.f32(p.z);
    }
    if (hasN) w.f32(extras.normals[i].x), w.f32(extras.normals[i].y), w.f32(extras.normals[i].z);
    if (hasC) {
      if (!vertexColor.empty()) w.u8(vertexColor[i].r), w.u8(vertexColor[i].g), w.u8(vertexColor[i].b);
      else w.u8(attrs.vertexColor[i].r), w.u8(attrs.vertexColor[i].g), w.u8(attrs.vertexColor[i].b);
    }
    if (hasQ) w.f32(vertexQuality[i]);
    for (const VertexAttribute& a : extras.attributes)
      for (int c = 0; c < a.components; ++c) w.f32(a.values[i * size_t(a.components) + size_t(c)]);
  }
  for (size_t f = 0; f < nf; ++f) {
    const auto& t = s.triangles[f];
    w.u8(3), w.i32(int32_t(t.x)), w.i32(int32_t(t.y)), w.i32(int32_t(t.z));
    if (hasFC) w.u8(attrs.faceColor[f].r), w.u8(attrs.faceColor[f].g), w.u8(attrs.faceColor[f].b);
    if (hasFQ) w.f32(attrs.faceQuality[f]);
  }
  writeAtomically(path, [&](const std::string& temp) {
    std::ofstream os(temp, std::ios::binary | std::ios::trunc);
    if (!os) failWrite(path, std::string("the file cannot be created (") + std::strerror(errno) + ")");
    os.write(w.buf.data(), std::streamsize(w.buf.size()));
    os.close();
    if (!os) failWrite(path, std::string("writing failed (") + std::strerror(errno) + ")");
  });
}

std::vector<LayerRange> meshLayers(const LoadedMesh& m, const std::string& fileName, size_t faceOffset) {
  if (m.layers.empty()) return {{fileName, faceOffset, m.scene.faceCount()}};
  std::vector<LayerRange> out;
  for (const auto& [name, faces] : m.layers) {
    out.push_back({name, faceOffset, faces});
    faceOffset += faces;
  }
  return out;
}

void reframe(LoadedMesh& m) {
  if (m.points.size() != m.scene.vertexCount()) return;  // a part without its file's coordinates: as appended
  // The whole scene's frame from the files' own coordinates, as MeshLab's
  // layers get theirs (one rounding to float about the union's centre):
  // Scene::append keeps the first part's centre and rounds the others'
  // floats a second time, one float step off where the union's box differs
  // from the first part's (the caustic Cornell box with its glossy block
  // below the floor's lowest vertex: photon paths through the glass
  // flipped, up to 87% on dark vertices against the same layers in
  // meshlabserver; an outside audit).
  Scene frame = Scene::fromAbsolute(m.points, m.scene.triangles);
  m.scene.origin = frame.origin;
  m.scene.unit = frame.unit;
  m.scene.positions = std::move(frame.positions);
}

void appendMesh(LoadedMesh& into, const LoadedMesh& other, Reframing when) {
  into.layers.clear();
  into.warnings.insert(into.warnings.end(), other.warnings.begin(), other.warnings.end());
  const size_t nf0 = into.scene.faceCount(), nv0 = into.scene.vertexCount();
  const size_t nf1 = other.scene.faceCount(), nv1 = other.scene.vertexCount();
  auto merge = [](auto& a, const auto& b, size_t n0, size_t n1, auto fill) {
    if (a.empty() && b.empty()) return;
    a.resize(n0, fill);
    if (b.empty()) a.insert(a.end(), n1, fill);
    else a.insert(a.end(), b.begin(), b.end());
  };
  // Colours with the masks of which parts gave them (the reflectance rule
  // then holds per part); a part whose vertex colours display a result
  // (its attribute, which the merge below may drop as not common) gives none.
  auto shows = [](const LoadedMesh& m) -> std::string {
    for (const char* name : kResultAttributes)
      for (const VertexAttribute& a : m.attributes)
        if (a.name == name && colorsDisplay(name, m.attrs.vertexColor)) return name;
    return "";
  };
  if (into.attrs.vertexColorShows.empty() && into.attrs.vertexColorGiven.empty())
    into.attrs.vertexColorShows = shows(into);
  appendColors(into.attrs, nf0, nv0, other.attrs, nf1, nv1, shows(other));
  merge(into.attrs.faceQuality, other.attrs.faceQuality, nf0, nf1, 0.f);
  merge(into.attrs.faceSelected, other.attrs.faceSelected, nf0, nf1, uint8_t(0));
  merge(into.attrs.vertexSelected, other.attrs.vertexSelected, nv0, nv1, uint8_t(0));
  const bool normals = !into.scene.vertexNormals.empty() || !other.scene.vertexNormals.empty();
  if (normals && into.scene.vertexNormals.empty()) {
    // Missing normals of one part: computed from its faces, in the frame
    // re-framing at each part would have given (the same bits either way).
    if (when == Reframing::Deferred) reframe(into);
    into.scene.vertexNormals = computeVertexNormals(into.scene);
  }
  std::vector<glm::vec3> otherNormals = other.scene.vertexNormals;
  if (normals && otherNormals.empty()) otherNormals = computeVertexNormals(other.scene);
  const size_t tri0 = into.triangleToFace.empty() ? 0 : into.triangleToFace.back() + 1;
  into.scene.append(other.scene);
  if (into.points.size() == nv0 && other.points.size() == nv1) {
    into.points.insert(into.points.end(), other.points.begin(), other.points.end());
    if (when == Reframing::Now) reframe(into);
  } else {
    into.points.clear();
  }
  if (normals) {
    into.scene.vertexNormals.resize(nv0);
    into.scene.vertexNormals.insert(into.scene.vertexNormals.end(), otherNormals.begin(), otherNormals.end());
  }
  for (uint32_t t : other.triangleToFace) into.triangleToFace.push_back(uint32_t(tri0 + t));
  // Attributes every part has (as MeshLab's layers give a filter those all
  // of them carry); the others are dropped.
  std::vector<VertexAttribute> kept;
  for (VertexAttribute& a : into.attributes)
    for (const VertexAttribute& b : other.attributes)
      if (a.name == b.name && a.components == b.components) {
        a.values.insert(a.values.end(), b.values.begin(), b.values.end());
        kept.push_back(std::move(a));
        break;
      }
  into.attributes = std::move(kept);
}

}  // namespace gi::io
