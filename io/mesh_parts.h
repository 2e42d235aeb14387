// Internal to io/: a polygon mesh as a reader returns it (before triangulation)
// and the strict number parsing every reader shares. A file is hostile until
// proven otherwise: every count is bounded by the bytes left, every number is
// a whole token and finite, every index is in range.
#pragma once
#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace gi::io::detail {

struct Polygons {
  std::vector<glm::dvec3> points;
  std::vector<glm::vec3> normals;          // per vertex, or empty
  std::vector<glm::u8vec3> vertexColor;    // or empty
  std::vector<uint8_t> vertexSelected;     // 1: selected (PLY vertex flags bit 0x20), or empty
  std::vector<uint32_t> faceStart{0};      // face f: index[faceStart[f] .. faceStart[f+1])
  std::vector<uint32_t> index;
  std::vector<glm::u8vec3> faceColor;      // or empty
  std::vector<float> faceQuality;          // or empty
  std::vector<uint8_t> faceSelected;       // 1: selected (PLY face flags bit 0x20, as MeshLab saves it), or empty
  // The vertex element's other float and double properties, by name, in
  // file order (what an earlier filter left: "Radiosity_x", "StdError"); a
  // value that is not finite in float is kept as NaN for its reader to judge.
  std::vector<std::string> vertexFloatNames;
  std::vector<std::vector<float>> vertexFloats;
  // Layers this tool wrote into one PLY: "comment gi_layer COUNT NAME"
  // header lines, in face order (PLY only; empty: none).
  std::vector<std::pair<std::string, size_t>> layers;
  // What the run's log should warn of (an OBJ's material library not found).
  std::vector<std::string> warnings;
};

// Throws std::runtime_error "cannot read NAME: WHY." (one line).
[[noreturn]] void failRead(const std::string& name, const std::string& why);

// The whole token as a number, or false: no trailing characters, no NaN or
// infinity, no overflow. A leading '+' is accepted (printf writes none, but
// some writers do).
bool parseDouble(std::string_view token, double& v);
bool parseInt(std::string_view token, long long& v);

// Accepts "nan", "inf", "-inf", "infinity" (any case): for values we skip.
bool parseNonFinite(std::string_view token);
// Whether the token is a number of any size, or nan or inf.
bool isNumber(std::string_view token);

// The first vertex a face lists twice, or kNone (sorting for long faces, so
// that a face of 10^6 indices is not 10^12 comparisons).
constexpr uint32_t kNone = 0xffffffffu;
uint32_t repeatedIndex(const std::vector<uint32_t>& face);

// The engine keeps positions as float relative to the bounding-box centre:
// a coordinate beyond float's range would become infinite there.
bool fitsFloat(double v);

// Throws unless every face has >= 3 indices below the vertex count (a face
// may list a vertex twice: parse() collapses or keeps it, see there)
// and every point and normal is finite and within float range. Messages say
// "FACE_WORD f" / "vertex v" (face numbers as the reader counts them).
void checkPolygons(const Polygons& p, const std::string& name);

// One "a b c" text in quotes for a message: control bytes shown as \xNN,
// at most 60 characters.
std::string quoted(std::string_view text);
// A number for a message, as %g writes it (300, 0.5, 1e+30).
std::string shortNumber(double v);
// A colour channel already on the 0..255 scale as a byte; false where it
// lies outside by more than rounding (the readers refuse it, not clamp it).
bool colourChannel(double scaled, uint8_t& byte);
// Why a file of `size` bytes is neither a binary STL (its count says n
// triangles) nor an ASCII one: the same sentence from the first bytes and
// from the whole file.
std::string notAnStl(uint32_t n, uint64_t size);

// A face of n vertex ids v as triangles appended to `tris` (polygon_cut.cpp:
// a fan where convex, ear clipping where concave, a face listing a vertex
// twice in its place; `once` and `corners` are scratch space). False where
// it was cut as a fan that may cover area outside it: concave with more than
// kMaxEarClipped corners, crossing itself, or through one vertex twice.
constexpr size_t kMaxEarClipped = 256;
bool cutFace(const std::vector<glm::dvec3>& pts, const uint32_t* v, size_t n, std::vector<uint32_t>& once,
             std::vector<glm::uvec3>& corners, std::vector<glm::uvec3>& tris);

// The readers (each in its own file). Every one throws std::runtime_error
// with one sentence naming `name` on any defect.
Polygons readPly(std::string_view bytes, const std::string& name);  // ply_reader.cpp
// What the first bytes `head` of a file of `size` bytes can already rule out
// for format `ext`, with the messages the readers give for the whole file.
void checkHead(std::string_view head, const std::string& ext, uintmax_t size, const std::string& name);
// The whole of an open regular file `in` of format `ext` (ply, obj, off,
// stl), its first bytes checked before the rest is read, so that a large file
// that is no such file is refused at once (mesh_io.cpp).
std::string readCheckedBytes(std::ifstream& in, const std::string& ext, const std::string& path);
Polygons readOff(std::string_view bytes, const std::string& name);  // text_formats.cpp

// OBJ and STL are parsed by OpenMesh after these strict passes, which reject
// what OpenMesh would skip, misread or crash on. They return the number of
// vertices and faces the file declares.
struct Counts {
  size_t vertices = 0, faces = 0;
  std::vector<std::string> materialFiles;  // OBJ: the mtllib names, as OpenMesh reads them
  std::vector<size_t> materialLines;       // and the byte offsets of those lines
  // OBJ, as the file gives them (OpenMesh reads coordinates as float and
  // leaves the colour of a face without a material's Kd undefined):
  std::vector<glm::dvec3> points;          // every 'v', in double
  std::vector<uint32_t> corners;           // every face's vertices (0-based), face after face
  std::vector<uint32_t> faceSize;          // OBJ: each face's corner count
  std::vector<int> cornerNormal;           // OBJ: each corner's 'vn' index (0-based), -1 where none
  std::vector<glm::vec3> normals;          // OBJ: every 'vn'
  std::vector<size_t> repeatLines;         // OBJ: byte offsets of faces listing a vertex twice
  std::vector<uint8_t> faceRepeats;        // OBJ: per face, 1 where it lists a vertex twice
  std::vector<int> faceMaterial;           // per face: index into materialNames, -1 before any usemtl
  std::vector<std::string> materialNames;  // the usemtl names, in order of first use
  size_t coloredVertices = 0;              // 'v' lines with r g b
};
Counts checkObj(std::string_view bytes, const std::string& name);  // text_formats.cpp
// An OBJ material library: every Kd must be three numbers in 0..1. Returns
// each material's Kd (newmtl name -> Kd; a material without Kd is absent).
std::map<std::string, glm::dvec3> checkMaterial(std::string_view bytes, const std::string& name);
// Binary (the size is exactly 84 + 50 n bytes, as OpenMesh decides too) or
// ASCII ("solid ..."); sets `binary`.
Counts checkStl(std::string_view bytes, const std::string& name, bool& binary);

}  // namespace gi::io::detail
