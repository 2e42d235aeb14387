// Strict PLY reader. The format: Turk 1994, "The PLY Polygon File Format".
// The header is checked line by line against its grammar; every element
// count, list count and the total are bounded by the bytes left; ASCII
// numbers are whole tokens, in range for their declared type; binary data is
// little or big endian. Read: vertex x y z, nx ny nz, red green blue (integer
// 0..255 or float 0..1); face vertex_indices (or vertex_index), red green
// blue, quality (any numeric type); vertex and face flags (an integer: bit
// 0x20 is vcglib's SELECTED, as MeshLab saves a selection: a light selected
// in MeshLab is an emitter for `gi` too); the vertex element's other float
// and double properties are kept by name (an earlier filter's per-vertex
// results); triangle strips (element tristrips, list vertex_indices, -1
// between strips, as vcglib and MeshLab read them) become triangles. Every
// other element and property is skipped by its size, so MeshLab's extras
// (texture coordinates) load.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_set>

#include "mesh_parts.h"

namespace gi::io::detail {

namespace {

enum class Type : uint8_t { I8, U8, I16, U16, I32, U32, F32, F64 };

bool typeFromName(std::string_view n, Type& t) {
  static const std::pair<const char*, Type> kNames[] = {
      {"char", Type::I8},    {"int8", Type::I8},     {"uchar", Type::U8},  {"uint8", Type::U8},
      {"short", Type::I16},  {"int16", Type::I16},   {"ushort", Type::U16}, {"uint16", Type::U16},
      {"int", Type::I32},    {"int32", Type::I32},   {"uint", Type::U32},  {"uint32", Type::U32},
      {"float", Type::F32},  {"float32", Type::F32}, {"double", Type::F64}, {"float64", Type::F64}};
  for (const auto& [name, type] : kNames)
    if (n == name) return t = type, true;
  return false;
}
size_t sizeOf(Type t) {
  switch (t) {
    case Type::I8: case Type::U8: return 1;
    case Type::I16: case Type::U16: return 2;
    case Type::I32: case Type::U32: case Type::F32: return 4;
    case Type::F64: return 8;
  }
  return 1;
}
bool isInteger(Type t) { return t != Type::F32 && t != Type::F64; }
std::pair<double, double> integerRange(Type t) {
  switch (t) {
    case Type::I8: return {-128.0, 127.0};
    case Type::U8: return {0.0, 255.0};
    case Type::I16: return {-32768.0, 32767.0};
    case Type::U16: return {0.0, 65535.0};
    case Type::I32: return {-2147483648.0, 2147483647.0};
    default: return {0.0, 4294967295.0};
  }
}

enum class Role : uint8_t { Skip, X, Y, Z, NX, NY, NZ, R, G, B, Quality, Indices, Flags, Keep, Strip };

struct Property {
  std::string name;
  Type type = Type::F32;  // of the value, or of a list's items
  bool list = false;
  Type countType = Type::U8;
  Role role = Role::Skip;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> props;
};

enum class Format { Ascii, BinaryLE, BinaryBE };

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  size_t bodyStart = 0;
  std::vector<std::pair<std::string, size_t>> layers;  // "comment gi_layer COUNT NAME"
};

std::vector<std::string_view> splitWords(std::string_view line) {
  std::vector<std::string_view> w;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t s = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > s) w.push_back(line.substr(s, i - s));
  }
  return w;
}

Header parseHeader(std::string_view b, const std::string& name) {
  if (b.substr(0, 4) != "ply\n" && b.substr(0, 5) != "ply\r\n") failRead(name, "not a PLY file (the first line is not 'ply')");
  Header h;
  size_t pos = b[3] == '\n' ? 4 : 5, lineNo = 1;
  bool formatSeen = false;
  // Hashed: a 1 MiB header of 50,000 property lines must not cost 10^9 comparisons.
  std::unordered_set<std::string> elementNames, propertyNames;
  constexpr size_t kMaxHeader = size_t(1) << 20;
  for (;;) {
    const size_t nl = b.find('\n', pos);
    if (nl == std::string_view::npos || nl > kMaxHeader)
      failRead(name, "the PLY header has no end_header line" + std::string(nl == std::string_view::npos ? "" : " in its first MiB"));
    std::string_view line = b.substr(pos, nl - pos);
    pos = nl + 1;
    ++lineNo;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::string at = "line " + std::to_string(lineNo) + " of the PLY header";
    for (const char c : line)
      if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f)
        failRead(name, at + " holds a control character: " + quoted(line));
    const auto w = splitWords(line);
    long long layerFaces = -1;
    if (w.size() >= 4 && w[0] == "comment" && w[1] == "gi_layer" && parseInt(w[2], layerFaces) && layerFaces >= 0) {
      const size_t at3 = size_t(w[3].data() - line.data());  // the name: the rest of the line
      h.layers.push_back({std::string(line.substr(at3)), size_t(layerFaces)});
      continue;
    }
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format") {
      double version = 0;
      if (formatSeen || !h.elements.empty()) failRead(name, at + ": 'format' must come once, before the elements");
      if (w.size() != 3 || !parseDouble(w[2], version) || version != 1.0)
        failRead(name, at + ": expected 'format ascii|binary_little_endian|binary_big_endian 1.0', found " + quoted(line));
      if (w[1] == "ascii") h.format = Format::Ascii;
      else if (w[1] == "binary_little_endian") h.format = Format::BinaryLE;
      else if (w[1] == "binary_big_endian") h.format = Format::BinaryBE;
      else failRead(name, at + ": unknown format " + quoted(w[1]));
      formatSeen = true;
    } else if (w[0] == "element") {
      long long count = -1;
      if (!formatSeen) failRead(name, at + ": an element before the 'format' line");
      if (w.size() != 3 || !parseInt(w[2], count) || count < 0)
        failRead(name, at + ": expected 'element NAME COUNT' with a count >= 0, found " + quoted(line));
      if (!elementNames.insert(std::string(w[1])).second) failRead(name, at + ": a second element " + quoted(w[1]));
      h.elements.push_back({std::string(w[1]), uint64_t(count), {}});
      propertyNames.clear();
    } else if (w[0] == "property") {
      if (h.elements.empty()) failRead(name, at + ": a property before any element");
      Property p;
      const bool list = w.size() >= 2 && w[1] == "list";
      if (list ? w.size() != 5 : w.size() != 3)
        failRead(name, at + ": expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME', found " + quoted(line));
      p.list = list;
      if (list && (!typeFromName(w[2], p.countType) || !isInteger(p.countType)))
        failRead(name, at + ": the list count type " + quoted(w[2]) + " is not an integer type");
      if (!typeFromName(w[list ? 3 : 1], p.type)) failRead(name, at + ": unknown type " + quoted(w[list ? 3 : 1]));
      p.name = std::string(w.back());
      Element& e = h.elements.back();
      if (!propertyNames.insert(p.name).second)
        failRead(name, at + ": element '" + e.name + "' has a second property " + quoted(p.name));
      e.props.push_back(p);
    } else if (w[0] == "end_header") {
      if (w.size() != 1) failRead(name, at + ": text after end_header");
      break;
    } else {
      failRead(name, at + ": unknown keyword " + quoted(w[0]));
    }
  }
  if (!formatSeen) failRead(name, "the PLY header has no 'format' line");
  h.bodyStart = pos;
  return h;
}

// Gives each property we read its role and checks its kind.
void assignRoles(Header& h, const std::string& name) {
  for (Element& e : h.elements) {
    const bool vertex = e.name == "vertex", face = e.name == "face";
    for (Property& p : e.props) {
      const std::string& n = p.name;
      if (vertex) {
        if (n == "x") p.role = Role::X;
        else if (n == "y") p.role = Role::Y;
        else if (n == "z") p.role = Role::Z;
        else if (n == "nx") p.role = Role::NX;
        else if (n == "ny") p.role = Role::NY;
        else if (n == "nz") p.role = Role::NZ;
        else if (n == "flags" && !p.list && isInteger(p.type)) p.role = Role::Flags;
      }
      if (vertex || face) {
        if (n == "red" || n == "diffuse_red") p.role = Role::R;
        else if (n == "green" || n == "diffuse_green") p.role = Role::G;
        else if (n == "blue" || n == "diffuse_blue") p.role = Role::B;
      }
      if (face) {
        if (n == "quality") p.role = Role::Quality;
        else if (n == "flags" && !p.list && isInteger(p.type)) p.role = Role::Flags;
        else if (n == "vertex_indices" || n == "vertex_index") p.role = Role::Indices;
      }
      if (e.name == "tristrips" && n == "vertex_indices") {
        if (!p.list || !isInteger(p.type)) failRead(name, "the tristrips property 'vertex_indices' must be a list of integers");
        p.role = Role::Strip;
      }
      if (vertex && p.role == Role::Skip && !p.list && !isInteger(p.type)) p.role = Role::Keep;
      if (p.role == Role::Indices && (!p.list || !isInteger(p.type)))
        failRead(name, "the face property '" + n + "' must be a list of integers");
      if (p.role != Role::Skip && p.role != Role::Indices && p.role != Role::Strip && p.list)
        failRead(name, "the " + e.name + " property '" + n + "' is a list; a number was expected");
    }
    if (std::count_if(e.props.begin(), e.props.end(), [](const Property& p) { return p.role == Role::Indices; }) > 1)
      failRead(name, "the face element has two vertex index lists");
  }
}

bool has(const Element& e, Role r) {
  return std::any_of(e.props.begin(), e.props.end(), [r](const Property& p) { return p.role == r; });
}

// Where the values come from: ASCII tokens or binary bytes. Each call
// returns Ok, End (no data left) or Bad (a token that is no number of the
// declared type).
enum class Status { Ok, End, Bad };

struct AsciiSource {
  std::string_view b;
  size_t pos;
  static bool space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }
  bool token(std::string_view& t) {
    while (pos < b.size() && space(b[pos])) ++pos;
    if (pos >= b.size()) return false;
    const size_t s = pos;
    while (pos < b.size() && !space(b[pos])) ++pos;
    t = b.substr(s, pos - s);
    return true;
  }
  size_t left() const { return b.size() - pos; }
  // Strict for values we use (finite, in range for the type); a skipped
  // float may also be nan or inf (MeshLab writes undefined quality as nan).
  Status value(Type type, double& v, bool used) {
    std::string_view t;
    if (!token(t)) return Status::End;
    if (isInteger(type)) {
      long long i = 0;
      const auto [lo, hi] = integerRange(type);
      if (!parseInt(t, i) || double(i) < lo || double(i) > hi) return Status::Bad;
      v = double(i);
      return Status::Ok;
    }
    if (parseDouble(t, v)) {
      if (type != Type::F32) return Status::Ok;
      if (!fitsFloat(v)) return Status::Bad;
      v = double(float(v));  // the value the file declares: "0.1" of a float property is float 0.1, as binary gives it
      return Status::Ok;
    }
    if (used || !parseNonFinite(t)) return Status::Bad;
    v = std::numeric_limits<double>::quiet_NaN();  // a kept value says it is not a number
    return Status::Ok;
  }
  Status skip(Type type, uint64_t n) {
    double v;
    for (uint64_t k = 0; k < n; ++k)
      if (const Status s = value(type, v, false); s != Status::Ok) return s;
    return Status::Ok;
  }
  // An item takes at least two bytes (a digit and a separator) but the last.
  uint64_t maxItems(Type) const { return (left() + 1) / 2; }
  bool finished() {
    std::string_view t;
    return !token(t);
  }
};

struct BinarySource {
  std::string_view b;
  size_t pos;
  bool bigEndian;
  size_t left() const { return b.size() - pos; }
  template <class T>
  T load() {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, b.data() + pos, sizeof(T));
    if (bigEndian) std::reverse(raw, raw + sizeof(T));
    T v;
    std::memcpy(&v, raw, sizeof(T));
    pos += sizeof(T);
    return v;
  }
  Status value(Type type, double& v, bool) {
    if (left() < sizeOf(type)) return Status::End;
    switch (type) {
      case Type::I8: v = load<int8_t>(); break;
      case Type::U8: v = load<uint8_t>(); break;
      case Type::I16: v = load<int16_t>(); break;
      case Type::U16: v = load<uint16_t>(); break;
      case Type::I32: v = load<int32_t>(); break;
      case Type::U32: v = load<uint32_t>(); break;
      case Type::F32: v = load<float>(); break;
      case Type::F64: v = load<double>(); break;
    }
    return Status::Ok;
  }
  Status skip(Type type, uint64_t n) {
    if (n > left() / sizeOf(type)) return Status::End;
    pos += size_t(n) * sizeOf(type);
    return Status::Ok;
  }
  uint64_t maxItems(Type type) const { return left() / sizeOf(type); }
  bool finished() const { return pos == b.size(); }
};

// A colour channel as a byte: integers 0..255, floats 0..1; a value outside
// (by more than rounding) is refused, as the OBJ reader refuses it (an int
// 300 or a float 255 was clamped without a word; an outside audit).
uint8_t colourByte(Type t, double v, const std::string& name, const std::string& where, const std::string& channel) {
  // 16-bit colours (ushort, as some scanners write them) are 0..65535.
  const bool wide = t == Type::U16;
  const double c = wide ? v / 257.0 : isInteger(t) ? v : v * 255.0;
  uint8_t byte = 0;
  if (!colourChannel(c, byte))
    failRead(name, where + ": colour '" + channel + "' is " + shortNumber(v) + ", outside " +
                       (isInteger(t) ? "0..255 (an integer colour)" : "0..1 (a floating-point colour)"));
  return byte;
}

// The least number of body bytes one element of e takes.
uint64_t minBytes(const Element& e, Format f) {
  uint64_t n = 0;
  for (const Property& p : e.props) n += f == Format::Ascii ? 2 : sizeOf(p.list ? p.countType : p.type);
  return n;
}

// One triangle strip: triangle j of a run is (a_j, a_j+1, a_j+2), its first
// two corners swapped where j is odd so that every triangle turns as the
// first; -1 ends a run. Triangles with a repeated corner (the joins strips
// use) are left out.
template <class Source, class What>
void readStrip(Source& src, const Property& p, uint64_t n, uint64_t nv, Polygons& out, const std::string& name,
               const What& what) {
  int64_t a = -1, b = -1;
  uint64_t run = 0;  // indices in the current run
  for (uint64_t k = 0; k < n; ++k) {
    double v = 0;
    if (const Status s = src.value(p.type, v, true); s != Status::Ok)
      failRead(name, s == Status::End ? "the file ends inside " + what() + " (truncated, or a count that lies)"
                                      : what() + ": list 'vertex_indices' holds no integer of its type");
    if (v == -1) {
      run = 0;
      continue;
    }
    if (v < 0 || v >= double(nv))
      failRead(name, what() + " uses vertex index " + std::to_string(int64_t(v)) + ", outside the " +
                         std::to_string(nv) + " vertices");
    const int64_t c = int64_t(v);
    if (run >= 2 && a != b && b != c && a != c) {
      const bool odd = (run - 2) % 2 == 1;
      for (int64_t i : {odd ? b : a, odd ? a : b, c}) out.index.push_back(uint32_t(i));
      out.faceStart.push_back(uint32_t(out.index.size()));
    }
    a = b, b = c, ++run;
  }
}

template <class Source>
void readBody(const Header& h, Source& src, Polygons& out, const std::string& name) {
  const Element* vertex = nullptr;
  for (const Element& e : h.elements)
    if (e.name == "vertex") vertex = &e;
  const uint64_t nv = vertex ? vertex->count : 0;
  std::vector<uint32_t> face;
  for (const Element& e : h.elements) {
    const bool isVertex = &e == vertex, isFace = e.name == "face";
    const bool normals = isVertex && has(e, Role::NX) && has(e, Role::NY) && has(e, Role::NZ);
    const bool colours = (isVertex || isFace) && has(e, Role::R) && has(e, Role::G) && has(e, Role::B);
    const bool quality = isFace && has(e, Role::Quality);
    if (e.props.empty()) continue;  // takes no bytes, whatever its count
    // Slot of each kept vertex property in out.vertexFloats.
    std::vector<size_t> slot(e.props.size(), 0);
    if (isVertex)
      for (size_t k = 0; k < e.props.size(); ++k)
        if (e.props[k].role == Role::Keep) {
          slot[k] = out.vertexFloats.size();
          out.vertexFloatNames.push_back(e.props[k].name);
          out.vertexFloats.emplace_back(size_t(e.count), 0.f);
        }
    if (isVertex) {
      out.points.resize(size_t(e.count));
      if (normals) out.normals.resize(size_t(e.count));
      if (colours) out.vertexColor.resize(size_t(e.count));
      if (has(e, Role::Flags)) out.vertexSelected.resize(size_t(e.count));
    }
    if (isFace) {
      out.faceStart.reserve(size_t(e.count) + 1);
      if (colours) out.faceColor.resize(size_t(e.count));
      if (quality) out.faceQuality.resize(size_t(e.count));
      if (has(e, Role::Flags)) out.faceSelected.resize(size_t(e.count));
    }
    for (uint64_t i = 0; i < e.count; ++i) {
      // Messages are built only on failure: this loop runs once per vertex and face.
      auto what = [&] { return e.name + " " + std::to_string(i); };
      auto fail = [&](Status s, const Property& p) {
        if (s == Status::End)
          failRead(name, "the file ends inside " + what() + " of " + std::to_string(e.count) + " (truncated, or a count that lies)");
        const Type t = p.list ? p.countType : p.type;
        failRead(name, what() + ": property '" + p.name + "' is not " +
                           (isInteger(t) ? "an integer within the range of its type" : "a finite number within the range of its type"));
      };
      for (size_t pi = 0; pi < e.props.size(); ++pi) {
        const Property& p = e.props[pi];
        double v = 0;
        if (p.list) {
          if (const Status s = src.value(p.countType, v, true); s != Status::Ok) fail(s, p);
          if (v < 0) failRead(name, what() + ": list '" + p.name + "' has a negative count");
          if (uint64_t(v) > src.maxItems(p.type))
            failRead(name, what() + ": list '" + p.name + "' claims " + std::to_string(uint64_t(v)) + " items, more than the file holds");
          const uint64_t n = uint64_t(v);
          if (p.role == Role::Strip) {
            readStrip(src, p, n, nv, out, name, what);
            continue;
          }
          if (p.role != Role::Indices) {
            if (const Status s = src.skip(p.type, n); s != Status::Ok) fail(s, p);
            continue;
          }
          if (n < 3) failRead(name, what() + " has " + std::to_string(n) + " vertex indices (a face needs at least 3)");
          face.clear();
          for (uint64_t k = 0; k < n; ++k) {
            if (const Status s = src.value(p.type, v, true); s != Status::Ok) fail(s, p);
            if (v < 0 || v >= double(nv))
              failRead(name, what() + " uses vertex index " + std::to_string(int64_t(v)) + ", outside the " +
                                 std::to_string(nv) + " vertices");
            face.push_back(uint32_t(v));
          }
          out.index.insert(out.index.end(), face.begin(), face.end());
          out.faceStart.push_back(uint32_t(out.index.size()));
          continue;
        }
        const bool used = p.role != Role::Skip && p.role != Role::Keep;
        if (const Status s = src.value(p.type, v, used); s != Status::Ok) fail(s, p);
        if (p.role == Role::Skip) continue;
        if (p.role == Role::Keep) {
          out.vertexFloats[slot[pi]][size_t(i)] =
              std::isfinite(v) && fitsFloat(v) ? float(v) : std::numeric_limits<float>::quiet_NaN();
          continue;
        }
        if (!std::isfinite(v) || !fitsFloat(v))
          failRead(name, what() + ": property '" + p.name + "' is not a finite number within float range");
        const size_t k = size_t(i);
        switch (p.role) {
          case Role::X: out.points[k].x = v; break;
          case Role::Y: out.points[k].y = v; break;
          case Role::Z: out.points[k].z = v; break;
          case Role::NX: if (normals) out.normals[k].x = float(v); break;
          case Role::NY: if (normals) out.normals[k].y = float(v); break;
          case Role::NZ: if (normals) out.normals[k].z = float(v); break;
          case Role::R: if (colours) (isVertex ? out.vertexColor : out.faceColor)[k].r = colourByte(p.type, v, name, what(), p.name); break;
          case Role::G: if (colours) (isVertex ? out.vertexColor : out.faceColor)[k].g = colourByte(p.type, v, name, what(), p.name); break;
          case Role::B: if (colours) (isVertex ? out.vertexColor : out.faceColor)[k].b = colourByte(p.type, v, name, what(), p.name); break;
          case Role::Quality: out.faceQuality[k] = float(v); break;
          case Role::Flags: (isVertex ? out.vertexSelected : out.faceSelected)[k] = (int64_t(v) & 0x20) ? 1 : 0; break;
          default: break;
        }
      }
    }
  }
  if (!src.finished())
    failRead(name, "data follows the last element (" + std::to_string(src.left()) + " bytes; a count that lies?)");
}

}  // namespace

Polygons readPly(std::string_view bytes, const std::string& name) {
  Header h = parseHeader(bytes, name);
  assignRoles(h, name);
  const Element* vertex = nullptr;
  const Element* face = nullptr;
  for (const Element& e : h.elements) {
    if (e.name == "vertex") vertex = &e;
    if (e.name == "face") face = &e;
  }
  if (!vertex || !has(*vertex, Role::X) || !has(*vertex, Role::Y) || !has(*vertex, Role::Z))
    failRead(name, "the PLY header declares no vertex element with x, y and z");
  if (face && face->count > 0 && !has(*face, Role::Indices))
    failRead(name, "the face element has no vertex_indices list");
  // Every element's least size times its count must fit in the body: checked
  // before anything is allocated, so a count of 2^40 costs nothing.
  const uint64_t body = bytes.size() - h.bodyStart;
  const uint64_t slack = h.format == Format::Ascii ? 1 : 0;  // the last token needs no separator
  uint64_t need = 0;
  for (const Element& e : h.elements) {
    const uint64_t per = minBytes(e, h.format);
    if (per == 0) continue;
    if (e.count > (body + slack) / per || need + e.count * per > body + slack)
      failRead(name, "the PLY header declares more data than the file holds (" + std::to_string(e.count) + " " + e.name +
                         " elements in " + std::to_string(body) + " bytes; truncated, or a count that lies)");
    need += e.count * per;
  }
  if (vertex->count > std::numeric_limits<uint32_t>::max()) failRead(name, "more vertices than 32-bit indices address");
  Polygons out;
  if (h.format == Format::Ascii) {
    AsciiSource src{bytes, h.bodyStart};
    readBody(h, src, out, name);
  } else {
    BinarySource src{bytes, h.bodyStart, h.format == Format::BinaryBE};
    readBody(h, src, out, name);
  }
  const size_t faces = out.faceStart.size() - 1;
  for (size_t n : {out.faceColor.size(), out.faceQuality.size(), out.faceSelected.size()})
    if (n != 0 && n != faces)  // a strip's triangles have none of the face element's properties
      failRead(name, "the file holds both triangle strips and faces with colours, quality or flags; save it with "
                     "faces only");
  out.layers = std::move(h.layers);
  return out;
}

}  // namespace gi::io::detail
