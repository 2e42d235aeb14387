#include "mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

namespace gi::io {

namespace {

// Double points: the OBJ/OFF readers keep full precision for far-off meshes
// (OpenMesh's PLY reader itself reads coordinates as float).
struct Traits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3f;
};
using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<Traits>;

[[noreturn]] void failRead(const std::string& path, const std::string& why) {
  throw std::runtime_error("cannot read " + path + ": " + why + ".");
}
[[noreturn]] void failWrite(const std::string& path, const std::string& why) {
  throw std::runtime_error("cannot write " + path + ": " + why + ".");
}

std::string lowerExtension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  if (!e.empty() && e[0] == '.') e.erase(0, 1);
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return e;
}

int plyTypeSize(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

// OpenMesh trusts the element counts of a PLY header and allocates for them
// before reading (a huge count ends in std::bad_alloc, a truncated file reads
// garbage): check them against the file size first.
void checkPlyHeader(const std::string& path, uintmax_t fileSize) {
  std::ifstream in(path, std::ios::binary);
  std::string line, format;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0) failRead(path, "not a PLY file (no 'ply' magic)");
  uintmax_t minBytes = 0, count = 0, perElement = 0, props = 0;
  bool ended = false;
  auto closeElement = [&] {
    const uintmax_t perEntry = format == "ascii" ? 2 * props : perElement;
    if (perEntry > 0 && count > (fileSize + perEntry - 1) / perEntry) failRead(path, "the PLY header declares more data than the file holds");
    minBytes += count * perEntry;
  };
  while (std::getline(in, line)) {
    if (in.tellg() > std::streamoff(1 << 20)) break;
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key == "format") ls >> format;
    else if (key == "element") {
      closeElement();
      std::string name;
      long long c = -1;
      if (!(ls >> name >> c) || c < 0) failRead(path, "malformed PLY element line '" + line + "'");
      count = uintmax_t(c), perElement = 0, props = 0;
    } else if (key == "property") {
      std::string type;
      ls >> type;
      if (type == "list") ls >> type;  // the count type is the minimum size of a list
      const int size = plyTypeSize(type);
      if (size == 0) failRead(path, "unknown PLY property type in '" + line + "'");
      perElement += uintmax_t(size), ++props;
    } else if (key == "end_header") {
      closeElement();
      ended = true;
      break;
    }
  }
  if (!ended) failRead(path, "the PLY header has no end_header");
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
    failRead(path, "unknown PLY format '" + format + "'");
  const uintmax_t body = fileSize - std::min<uintmax_t>(fileSize, uintmax_t(std::max<std::streamoff>(0, in.tellg())));
  const uintmax_t slack = format == "ascii" ? 1 : 0;  // last line without newline
  if (minBytes > body + slack) failRead(path, "the file is shorter than its PLY header says (truncated?)");
}

// Face quality arrives as a custom property named after the PLY property, of
// the type the file declares.
template <class T>
bool readFaceQuality(PolyMesh& m, std::vector<float>& q) {
  OpenMesh::FPropHandleT<T> h;
  if (!m.get_property_handle(h, "quality")) return false;
  q.resize(m.n_faces());
  for (auto f : m.faces()) q[size_t(f.idx())] = float(m.property(h, f));
  return true;
}

// A polygon mesh as read, before triangulation (faces as index ranges).
struct Polygons {
  std::vector<glm::dvec3> points;
  std::vector<glm::vec3> normals;          // per vertex, or empty
  std::vector<glm::u8vec3> vertexColor;    // or empty
  std::vector<uint32_t> faceStart{0};      // face f: index[faceStart[f] .. faceStart[f+1])
  std::vector<uint32_t> index;
  std::vector<glm::u8vec3> faceColor;      // or empty
  std::vector<float> faceQuality;          // or empty
};

// PLY, OBJ, STL. Vertex indices are OpenMesh's: the file's, plus copies of
// non-manifold vertices appended; OpenMesh drops faces with repeated indices.
Polygons readWithOpenMesh(const std::string& path, const std::string& ext) {
  PolyMesh m;
  OpenMesh::IO::Options opt;
  // OpenMesh 9's STL reader reports colours it does not set: ask for none.
  if (ext != "stl") {
    m.request_vertex_colors();
    m.request_face_colors();
    m.request_vertex_normals();
    opt += OpenMesh::IO::Options::VertexColor;
    opt += OpenMesh::IO::Options::FaceColor;  // OBJ: from the material's Kd
    opt += OpenMesh::IO::Options::VertexNormal;
    opt += OpenMesh::IO::Options::Custom;  // PLY face "quality" (ASCII and binary)
  }
  bool ok = false;
  try {
    ok = OpenMesh::IO::read_mesh(m, path, opt);
  } catch (const std::exception& e) {
    failRead(path, std::string("the reader failed (") + e.what() + ")");
  }
  if (!ok) failRead(path, "OpenMesh could not parse it as a ." + ext + " mesh");
  const bool hasVC = ext != "stl" && opt.vertex_has_color(), hasVN = ext != "stl" && opt.vertex_has_normal();
  const bool hasFC = ext != "stl" && opt.face_has_color();

  Polygons p;
  p.points.resize(m.n_vertices());
  for (auto v : m.vertices()) {
    const auto& q = m.point(v);
    const size_t i = size_t(v.idx());
    p.points[i] = glm::dvec3(q[0], q[1], q[2]);
    if (hasVC) p.vertexColor.push_back({m.color(v)[0], m.color(v)[1], m.color(v)[2]});
    if (hasVN) p.normals.push_back({m.normal(v)[0], m.normal(v)[1], m.normal(v)[2]});
  }
  if (ext == "ply")
    (void)(readFaceQuality<float>(m, p.faceQuality) || readFaceQuality<double>(m, p.faceQuality) ||
           readFaceQuality<int>(m, p.faceQuality) || readFaceQuality<unsigned char>(m, p.faceQuality));
  p.index.reserve(m.n_faces() * 3);
  for (auto f : m.faces()) {
    for (auto v : m.fv_range(f)) p.index.push_back(uint32_t(v.idx()));
    p.faceStart.push_back(uint32_t(p.index.size()));
    if (hasFC) p.faceColor.push_back({m.color(f)[0], m.color(f)[1], m.color(f)[2]});
  }
  return p;
}

// OFF, read line by line: OpenMesh 9's OFF reader loses the face structure
// when face lines carry a colour ("3 a b c r g b", as MeshLab writes them).
// Header [C][N]OFF; colours as 0..255 integers or 0..1 floats.
Polygons readOff(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  auto next = [&](std::istringstream& ls) {
    while (std::getline(in, line)) {
      const size_t hash = line.find('#');
      if (hash != std::string::npos) line.erase(hash);
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      ls.clear();
      ls.str(line);
      return true;
    }
    return false;
  };
  auto colour = [](const std::vector<std::string>& t, size_t first, glm::u8vec3& c) {
    if (t.size() < first + 3) return false;
    const bool isFloat = std::any_of(t.begin() + long(first), t.begin() + long(first) + 3,
                                     [](const std::string& x) { return x.find_first_of(".eE") != std::string::npos; });
    for (int k = 0; k < 3; ++k) {
      const double v = std::stod(t[first + size_t(k)]);
      c[k] = uint8_t(std::clamp(isFloat ? std::lround(v * 255.0) : std::lround(v), 0L, 255L));
    }
    return true;
  };
  std::istringstream ls;
  std::string magic;
  if (!next(ls) || !(ls >> magic) || magic.size() < 3 || magic.compare(magic.size() - 3, 3, "OFF") != 0)
    failRead(path, "not an OFF file (no OFF header)");
  const bool hasC = magic.find('C') != std::string::npos, hasN = magic.find('N') != std::string::npos;
  if (magic.find("ST") != std::string::npos || magic.find('4') != std::string::npos || (ls >> std::ws, ls.peek() == 'B'))
    failRead(path, "only ASCII [C][N]OFF is supported");
  long long nv = -1, nf = -1;
  if (!(ls >> nv) && (!next(ls) || !(ls >> nv))) failRead(path, "the OFF header has no vertex count");
  if (!(ls >> nf) || nv < 0 || nf < 0) failRead(path, "the OFF header has no valid vertex and face counts");
  // Each vertex or face line takes at least 6 bytes: counts beyond the file are lies.
  const auto bytes = std::filesystem::file_size(path);
  if (uintmax_t(nv) + uintmax_t(nf) > bytes / 6 + 1) failRead(path, "the OFF header declares more data than the file holds");
  Polygons p;
  std::vector<std::string> t;
  auto tokens = [&] {
    t.clear();
    for (std::string x; ls >> x;) t.push_back(x);
  };
  try {
    for (long long i = 0; i < nv; ++i) {
      if (!next(ls)) failRead(path, "the file ends before its " + std::to_string(nv) + " vertices");
      tokens();
      if (t.size() < 3) failRead(path, "vertex " + std::to_string(i) + " has fewer than 3 coordinates");
      p.points.push_back({std::stod(t[0]), std::stod(t[1]), std::stod(t[2])});
      size_t at = 3;
      if (hasN && t.size() >= 6) p.normals.push_back({std::stof(t[3]), std::stof(t[4]), std::stof(t[5])}), at = 6;
      glm::u8vec3 c(255);
      if (hasC && !colour(t, at, c)) failRead(path, "vertex " + std::to_string(i) + " has no colour");
      if (hasC) p.vertexColor.push_back(c);
    }
    if (p.normals.size() != p.points.size()) p.normals.clear();
    bool faceColours = true;
    for (long long f = 0; f < nf; ++f) {
      if (!next(ls)) failRead(path, "the file ends before its " + std::to_string(nf) + " faces");
      tokens();
      const long long n = t.empty() ? -1 : std::stoll(t[0]);
      if (n < 3 || t.size() < size_t(n) + 1) failRead(path, "face " + std::to_string(f) + " is malformed");
      for (long long k = 1; k <= n; ++k) {
        const long long v = std::stoll(t[size_t(k)]);
        if (v < 0 || v >= nv) failRead(path, "face " + std::to_string(f) + " uses a vertex index out of range");
        p.index.push_back(uint32_t(v));
      }
      p.faceStart.push_back(uint32_t(p.index.size()));
      glm::u8vec3 c(255);
      faceColours = colour(t, size_t(n) + 1, c) && faceColours;
      p.faceColor.push_back(c);
    }
    if (!faceColours) p.faceColor.clear();  // only when every face has one
  } catch (const std::logic_error&) {  // std::stod / std::stoll on a non-number
    failRead(path, "a number in the OFF data cannot be parsed");
  }
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
};

}  // namespace

LoadedMesh loadMesh(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) failRead(path, "no such file");
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || !std::ifstream(path, std::ios::binary)) failRead(path, "the file cannot be opened");
  const std::string ext = lowerExtension(path);
  if (ext != "ply" && ext != "obj" && ext != "off" && ext != "stl")
    failRead(path, "unsupported format '" + ext + "' (expected ply, obj, off or stl)");
  if (ext == "ply") checkPlyHeader(path, size);
  const Polygons p = ext == "off" ? readOff(path) : readWithOpenMesh(path, ext);
  if (p.faceStart.size() < 2) failRead(path, "the file has no faces");

  LoadedMesh out;  // triangleToFace: index of the polygon as read (OpenMesh's, for PLY/OBJ/STL)
  const size_t nf = p.faceStart.size() - 1;
  std::vector<glm::uvec3> tris;
  tris.reserve(p.index.size());
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t* v = p.index.data() + p.faceStart[f];
    const size_t n = p.faceStart[f + 1] - p.faceStart[f];
    for (size_t k = 1; k + 1 < n; ++k) {  // fan
      tris.push_back({v[0], v[k], v[k + 1]});
      out.triangleToFace.push_back(uint32_t(f));
      if (!p.faceColor.empty()) out.attrs.faceColor.push_back(p.faceColor[f]);
      if (!p.faceQuality.empty()) out.attrs.faceQuality.push_back(p.faceQuality[f]);
    }
  }
  if (tris.empty()) failRead(path, "the file has no faces with three or more vertices");
  out.scene = Scene::fromAbsolute(p.points, std::move(tris));
  out.scene.vertexNormals = p.normals;
  out.attrs.vertexColor = p.vertexColor;
  return out;
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

  const bool hasN = !extras.normals.empty(), hasQ = !vertexQuality.empty();
  const bool hasC = !vertexColor.empty() || !attrs.vertexColor.empty();
  const bool hasFC = !attrs.faceColor.empty(), hasFQ = !attrs.faceQuality.empty();
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment written by meshlab-gi\n";
  h << "element vertex " << nv << "\nproperty float x\nproperty float y\nproperty float z\n";
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
    const glm::vec3 p(s.toWorld(s.positions[i]));  // absolute coordinates
    w.f32(p.x), w.f32(p.y), w.f32(p.z);
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
  std::ofstream os(path, std::ios::binary | std::ios::trunc);
  if (!os) failWrite(path, "the file cannot be created");
  os.write(w.buf.data(), std::streamsize(w.buf.size()));
  os.close();
  if (!os) failWrite(path, "writing failed (disk full?)");
}

void appendMesh(LoadedMesh& into, const LoadedMesh& other) {
  const size_t nf0 = into.scene.faceCount(), nv0 = into.scene.vertexCount();
  const size_t nf1 = other.scene.faceCount(), nv1 = other.scene.vertexCount();
  auto merge = [](auto& a, const auto& b, size_t n0, size_t n1, auto fill) {
    if (a.empty() && b.empty()) return;
    a.resize(n0, fill);
    if (b.empty()) a.insert(a.end(), n1, fill);
    else a.insert(a.end(), b.begin(), b.end());
  };
  merge(into.attrs.faceColor, other.attrs.faceColor, nf0, nf1, glm::u8vec3(188));
  merge(into.attrs.vertexColor, other.attrs.vertexColor, nv0, nv1, glm::u8vec3(188));
  merge(into.attrs.faceQuality, other.attrs.faceQuality, nf0, nf1, 0.f);
  merge(into.attrs.faceSelected, other.attrs.faceSelected, nf0, nf1, uint8_t(0));
  const bool normals = !into.scene.vertexNormals.empty() || !other.scene.vertexNormals.empty();
  if (normals) {
    // Missing normals of one part: computed from its faces.
    if (into.scene.vertexNormals.empty()) into.scene.vertexNormals = computeVertexNormals(into.scene);
  }
  std::vector<glm::vec3> otherNormals = other.scene.vertexNormals;
  if (normals && otherNormals.empty()) otherNormals = computeVertexNormals(other.scene);
  const size_t tri0 = into.triangleToFace.empty() ? 0 : into.triangleToFace.back() + 1;
  into.scene.append(other.scene);
  if (normals) {
    into.scene.vertexNormals.resize(nv0);
    into.scene.vertexNormals.insert(into.scene.vertexNormals.end(), otherNormals.begin(), otherNormals.end());
  }
  for (uint32_t t : other.triangleToFace) into.triangleToFace.push_back(uint32_t(tri0 + t));
}

}  // namespace gi::io
