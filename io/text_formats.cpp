// OFF (read here), OBJ and STL (checked here, then read by OpenMesh): strict
// line-by-line passes that name the line of the first defect. OFF: the
// Geomview format, [C][N]OFF. OBJ: Wavefront's "Object Files (.obj)"
// specification (v, vt, vn, f with 1-based or negative relative indices).
// STL: 3D Systems' stereolithography format (binary: 80-byte header, uint32
// count, 50 bytes per triangle; ASCII: solid / facet / outer loop / vertex).
#include <algorithm>
#include <cstring>

#include "mesh_parts.h"

namespace gi::io::detail {

namespace {

// Lines split into words at spaces and tabs; blank lines skipped. A control
// character (other than a tab, or a carriage return ending the line) is an
// error: OpenMesh's OBJ reader skips a line that starts with one after its
// trim, so such a line would count as a vertex here and not there, and a
// face's index would then reach past OpenMesh's vertices (found by fuzzing).
enum class Comments { Anywhere, WholeLines, None };
struct Lines {
  std::string_view b;
  const std::string& name;
  Comments comments;
  size_t pos = 0, number = 0;
  std::string_view line;
  std::vector<std::string_view> words;
  bool next() {
    while (pos < b.size()) {
      size_t nl = b.find('\n', pos);
      if (nl == std::string_view::npos) nl = b.size();
      line = b.substr(pos, nl - pos);
      pos = nl + 1;
      ++number;
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      for (const char c : line)
        if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f)
          failRead(name, at() + " holds a control character: " + quoted(line));
      const size_t first = line.find_first_not_of(" \t");
      if (first == std::string_view::npos) continue;
      if (comments == Comments::WholeLines && line[first] == '#') continue;
      if (comments == Comments::Anywhere)
        if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      words.clear();
      size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const size_t s = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > s) words.push_back(line.substr(s, i - s));
      }
      if (!words.empty()) return true;
    }
    return false;
  }
  std::string at() const { return "line " + std::to_string(number); }
};

// The rest of an OBJ or MTL line after its keyword, trimmed: what OpenMesh
// takes as one name (a material, a library file).
std::string_view restOfLine(std::string_view line, std::string_view keyword) {
  std::string_view m = line.substr(line.find(keyword) + keyword.size());
  m.remove_prefix(std::min(m.size(), m.find_first_not_of(" \t")));
  return m.substr(0, m.find_last_not_of(" \t") + 1);
}

// OFF colours: 3 or 4 numbers, 0..255 integers or 0..1 floats, decided per
// colour as Geomview's OFF specification has it ('1 1 1' is 1/255, '1.0 1.0
// 1.0' is 1). A number outside its range is refused (it was clamped without
// a word; an outside audit), as the OBJ and PLY readers refuse it.
bool offColour(const std::vector<std::string_view>& w, size_t first, glm::u8vec3& c, std::string& outside) {
  const size_t n = w.size() - first;
  if (n != 3 && n != 4) return false;
  const bool isFloat = std::any_of(w.begin() + long(first), w.begin() + long(first) + 3,
                                   [](std::string_view x) { return x.find_first_of(".eE") != std::string_view::npos; });
  for (int k = 0; k < 3; ++k) {
    double v = 0;
    if (!parseDouble(w[first + size_t(k)], v)) return false;
    if (!colourChannel(isFloat ? v * 255.0 : v, c[k])) {
      outside = "a colour channel of " + shortNumber(v) + ", outside " +
                (isFloat ? "0..1 (a colour written with a point)" : "0..255 (an integer colour)");
      return false;
    }
  }
  return true;
}

}  // namespace

Polygons readOff(std::string_view bytes, const std::string& name) {
  Lines in{bytes, name, Comments::Anywhere};
  if (!in.next() || in.words[0].size() < 3 || in.words[0].substr(in.words[0].size() - 3) != "OFF")
    failRead(name, "not an OFF file (no OFF header)");
  const std::string_view magic = in.words[0];
  const bool hasC = magic.find('C') != std::string_view::npos, hasN = magic.find('N') != std::string_view::npos;
  if (magic.find("ST") != std::string_view::npos || magic.find('4') != std::string_view::npos ||
      (in.words.size() > 1 && in.words[1] == "BINARY"))
    failRead(name, "only ASCII [C][N]OFF is supported");
  std::vector<std::string_view> counts(in.words.begin() + 1, in.words.end());
  if (counts.empty() && in.next()) counts = in.words;
  long long nv = -1, nf = -1, ne = 0;
  if ((counts.size() != 2 && counts.size() != 3) || !parseInt(counts[0], nv) || !parseInt(counts[1], nf) ||
      (counts.size() == 3 && !parseInt(counts[2], ne)) || nv < 0 || nf < 0)
    failRead(name, in.at() + ": expected the vertex, face and edge counts");
  // A vertex line takes at least 6 bytes ("0 0 0\n"), a face line 8: counts beyond the file are lies.
  const uint64_t left = bytes.size() - std::min(bytes.size(), in.pos);
  if (uint64_t(nv) > left / 6 || uint64_t(nf) > left / 8 || uint64_t(nv) * 6 + uint64_t(nf) * 8 > left + 1)
    failRead(name, "the OFF header declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                       " faces, more than the file holds (a count that lies?)");
  Polygons p;
  p.points.reserve(size_t(nv));
  const size_t want = 3 + (hasN ? 3 : 0);
  for (long long i = 0; i < nv; ++i) {
    if (!in.next()) failRead(name, "the file ends before its " + std::to_string(nv) + " vertices (truncated, or a count that lies)");
    const auto& w = in.words;
    double x[6] = {};
    const size_t extra = w.size() - std::min(w.size(), want);
    if (w.size() < want || (hasC ? extra != 3 && extra != 4 : extra != 0))
      failRead(name, in.at() + ": vertex " + std::to_string(i) + " should have " + std::to_string(want) + " numbers" +
                         (hasC ? " and a colour" : ""));
    for (size_t k = 0; k < want; ++k)
      if (!parseDouble(w[k], x[k]) || !fitsFloat(x[k]))
        failRead(name, in.at() + ": " + quoted(w[k]) + " is not a finite number within float range");
    p.points.push_back({x[0], x[1], x[2]});
    if (hasN) p.normals.push_back({float(x[3]), float(x[4]), float(x[5])});
    glm::u8vec3 c(255);
    std::string outside;
    if (hasC && !offColour(w, want, c, outside))
      failRead(name, in.at() + ": vertex " + std::to_string(i) + (outside.empty() ? " has no valid colour" : " has " + outside));
    if (hasC) p.vertexColor.push_back(c);
  }
  bool faceColours = true;
  std::vector<uint32_t> face;
  for (long long f = 0; f < nf; ++f) {
    if (!in.next()) failRead(name, "the file ends before its " + std::to_string(nf) + " faces (truncated, or a count that lies)");
    const auto& w = in.words;
    long long n = -1;
    if (!parseInt(w[0], n) || n < 3 || w.size() < size_t(n) + 1)
      failRead(name, in.at() + ": face " + std::to_string(f) + " should be 'n i1 ... in' with n >= 3");
    face.clear();
    for (long long k = 1; k <= n; ++k) {
      long long v = -1;
      if (!parseInt(w[size_t(k)], v) || v < 0 || v >= nv)
        failRead(name, in.at() + ": face " + std::to_string(f) + " uses vertex " + quoted(w[size_t(k)]) + ", not an index below " +
                           std::to_string(nv));
      face.push_back(uint32_t(v));
    }
    p.index.insert(p.index.end(), face.begin(), face.end());
    p.faceStart.push_back(uint32_t(p.index.size()));
    glm::u8vec3 c(255);
    std::string outside;
    if (w.size() == size_t(n) + 1) faceColours = false;
    else if (!offColour(w, size_t(n) + 1, c, outside))
      failRead(name, in.at() + ": face " + std::to_string(f) + (outside.empty() ? " has a malformed colour" : " has " + outside));
    p.faceColor.push_back(c);
  }
  if (!faceColours) p.faceColor.clear();  // only when every face has one
  if (in.next()) failRead(name, in.at() + ": data after the last face (a count that lies?)");
  return p;
}

// OpenMesh reads OBJ in two passes (vertices, then faces), and sets a face
// corner's normal or colour on its vertex before it checks the index: every
// reference must be valid here, counted exactly as OpenMesh counts. Comments
// are whole lines only: OpenMesh does not cut a line at '#', so "f 1 2 3#4 5"
// is a face of four vertices to it.
Counts checkObj(std::string_view bytes, const std::string& name) {
  Lines in{bytes, name, Comments::WholeLines};
  Counts c;
  size_t nvt = 0, nvn = 0;
  int material = -1;  // the current usemtl
  std::vector<uint32_t> face;
  std::vector<int> cornerNormal;  // this face's corners' vn, -1 where none
  auto numbers = [&](size_t lo, size_t hi, const char* what) {
    const size_t n = in.words.size() - 1;
    if (n < lo || n > hi)
      failRead(name, in.at() + ": '" + std::string(in.words[0]) + "' needs " + what + ", found " + quoted(in.line));
    for (size_t k = 1; k <= n; ++k) {
      double v = 0;
      if (!parseDouble(in.words[k], v) || !fitsFloat(v))
        failRead(name, in.at() + ": " + quoted(in.words[k]) + " is not a finite number within float range");
    }
  };
  // A reference: 1-based, or negative = relative to the end so far.
  auto resolve = [&](std::string_view t, size_t count, const char* what) -> uint32_t {
    long long i = 0;
    if (!parseInt(t, i) || i == 0 || (i > 0 && uint64_t(i) > count) || (i < 0 && uint64_t(-i) > count))
      failRead(name, in.at() + ": " + what + " index " + quoted(t) + " is not in 1.." + std::to_string(count) +
                         " (or -1..-" + std::to_string(count) + ")");
    return uint32_t(i > 0 ? i - 1 : static_cast<long long>(count) + i);
  };
  while (in.next()) {
    const std::string_view key = in.words[0];
    const bool numeric = key == "v" || key == "vt" || key == "vn" || key == "f";  // names may hold '#'
    for (size_t k = 1; numeric && k < in.words.size(); ++k)
      if (in.words[k].find('#') != std::string_view::npos)
        failRead(name, in.at() + ": a comment after the data (" + quoted(in.words[k]) +
                           "); the OBJ reader takes '#' only at the start of a line: move the comment to a line of its own");
    if (key == "v") {
      numbers(3, 6, "3 coordinates (and an optional w or r g b)");
      if (in.words.size() == 6) failRead(name, in.at() + ": 'v' with 5 numbers");
      for (size_t k = 4; in.words.size() == 7 && k < 7; ++k) {  // OpenMesh converts r g b to bytes unchecked
        double rgb = 0;
        if (parseDouble(in.words[k], rgb) && (rgb < 0 || rgb > 1)) failRead(name, in.at() + ": a vertex colour outside 0..1");
      }
      glm::dvec3 q(0.0);
      for (int k = 0; k < 3; ++k) parseDouble(in.words[size_t(k) + 1], q[k]);
      c.points.push_back(q);
      c.coloredVertices += in.words.size() == 7;
      ++c.vertices;
    } else if (key == "vt") {
      numbers(2, 3, "2 or 3 texture coordinates");
      ++nvt;
    } else if (key == "vn") {
      numbers(3, 3, "3 normal components");
      glm::vec3 nrm(0.f);
      for (int k = 0; k < 3; ++k) {
        double x = 0;
        parseDouble(in.words[size_t(k) + 1], x);
        nrm[k] = float(x);
      }
      c.normals.push_back(nrm);
      ++nvn;
    } else if (key == "vp") {
      numbers(1, 3, "1 to 3 parameters");
    } else if (key == "f") {
      if (in.words.size() < 4) failRead(name, in.at() + ": a face needs at least 3 vertices, found " + quoted(in.line));
      face.clear();
      cornerNormal.clear();
      size_t shape = 0;  // slashes and texture index of the first reference: all must match
      for (size_t k = 1; k < in.words.size(); ++k) {
        const std::string_view r = in.words[k];
        const size_t s1 = r.find('/'), s2 = s1 == std::string_view::npos ? s1 : r.find('/', s1 + 1);
        if (s2 != std::string_view::npos && r.find('/', s2 + 1) != std::string_view::npos)
          failRead(name, in.at() + ": malformed vertex reference " + quoted(r));
        face.push_back(resolve(r.substr(0, s1), c.vertices, "vertex"));
        const std::string_view t = s1 == std::string_view::npos ? "" : r.substr(s1 + 1, s2 == std::string_view::npos ? s2 : s2 - s1 - 1);
        const std::string_view n = s2 == std::string_view::npos ? "" : r.substr(s2 + 1);
        if (!t.empty()) resolve(t, nvt, "texture");
        cornerNormal.push_back(s2 != std::string_view::npos ? int(resolve(n, nvn, "normal")) : -1);
        const size_t myShape = (s1 != std::string_view::npos) + (s2 != std::string_view::npos) + 4 * !t.empty();
        if (k == 1) shape = myShape;
        else if (myShape != shape) failRead(name, in.at() + ": the face mixes vertex reference forms (v, v/t, v//n, v/t/n)");
      }
      // OpenMesh drops or rewrites a face listing a vertex twice: such a face
      // is hidden from it and taken as the file gives it (see mesh_io.cpp).
      const bool repeats = repeatedIndex(face) != kNone;
      if (repeats) c.repeatLines.push_back(size_t(in.line.data() - bytes.data()));
      c.faceRepeats.push_back(uint8_t(repeats));
      c.faceSize.push_back(uint32_t(face.size()));
      c.corners.insert(c.corners.end(), face.begin(), face.end());
      c.cornerNormal.insert(c.cornerNormal.end(), cornerNormal.begin(), cornerNormal.end());
      c.faceMaterial.push_back(material);
      ++c.faces;
    } else if (key == "usemtl") {
      const std::string_view m = restOfLine(in.line, "usemtl");
      const auto at = std::find(c.materialNames.begin(), c.materialNames.end(), m);
      material = int(at - c.materialNames.begin());
      if (at == c.materialNames.end()) c.materialNames.emplace_back(m);
    } else if (key == "mtllib") {
      c.materialFiles.emplace_back(restOfLine(in.line, "mtllib"));
      c.materialLines.push_back(size_t(in.line.data() - bytes.data()));
    } else if (key == "o" || key == "g" || key == "s" || key == "l" || key == "p") {
      // Names, groups and materials (OpenMesh reads the material's Kd as face colour); lines and points are ignored.
    } else {
      failRead(name, in.at() + ": unsupported OBJ statement " + quoted(in.line));
    }
  }
  return c;
}

std::map<std::string, glm::dvec3> checkMaterial(std::string_view bytes, const std::string& name) {
  Lines in{bytes, name, Comments::WholeLines};
  std::map<std::string, glm::dvec3> kd;
  std::string current;
  bool named = false;
  while (in.next()) {
    if (in.words[0] == "newmtl") {
      current = std::string(restOfLine(in.line, "newmtl"));
      named = true;
      continue;
    }
    if (in.words[0] != "Kd") continue;
    glm::dvec3 v(0.0);
    bool ok = in.words.size() == 4;
    for (size_t k = 1; ok && k < 4; ++k) ok = parseDouble(in.words[k], v[int(k) - 1]) && v[int(k) - 1] >= 0 && v[int(k) - 1] <= 1;
    // OpenMesh converts Kd to colour bytes unchecked.
    if (!ok) failRead(name, in.at() + ": 'Kd' needs 3 numbers in 0..1, found " + quoted(in.line));
    if (named) kd[current] = v;
  }
  return kd;
}

Counts checkStl(std::string_view bytes, const std::string& name, bool& binary) {
  Counts c;
  if (bytes.size() >= 84) {
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);  // little endian (x86 and ARM hosts)
    binary = uint64_t(bytes.size()) == 84 + 50 * uint64_t(n);
    if (binary) {
      for (uint32_t t = 0; t < n; ++t)
        for (int k = 3; k < 12; ++k) {  // the three corners; the stored normal is not read
          float v = 0;
          std::memcpy(&v, bytes.data() + 84 + 50 * size_t(t) + 4 * size_t(k), 4);
          if (!fitsFloat(v)) failRead(name, "triangle " + std::to_string(t) + " has a coordinate that is not finite");
        }
      c.faces = n;
      c.vertices = 3 * size_t(n);
      return c;
    }
  }
  binary = false;
  const size_t start = bytes.find_first_not_of(" \t\r\n");
  if (start == std::string_view::npos || bytes.substr(start, 5) != "solid") {
    const uint32_t n = [&] {
      uint32_t v = 0;
      if (bytes.size() >= 84) std::memcpy(&v, bytes.data() + 80, 4);
      return v;
    }();
    failRead(name, notAnStl(n, bytes.size()));
  }
  // Some exporters begin a binary STL's header with "solid" too: one whose
  // count does not match its size (truncated) is no ASCII STL either, and
  // read as one it was "line 1 holds a control character" (an outside
  // audit). Its NUL bytes tell it: no text holds them.
  if (bytes.size() >= 84 && bytes.find('\0') != std::string_view::npos) {
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);
    failRead(name, notAnStl(n, bytes.size()) + ", though its header begins with 'solid' (as some exporters write; it "
                   "holds NUL bytes, which no ASCII STL does)");
  }
  Lines in{bytes, name, Comments::None};
  in.next();  // solid NAME
  // solid NAME / { facet normal a b c / outer loop / vertex x y z (x3) / endloop / endfacet } / endsolid [NAME]
  // The facet normal is not read (the normals come from the corners), so it
  // may be any number: exporters write "nan" for a degenerate facet, and a
  // binary STL's are taken as they come.
  auto check = [&](std::initializer_list<const char*> words, size_t numbers, bool unread = false) {
    size_t k = 0;
    for (const char* w : words)
      if (k >= in.words.size() || in.words[k++] != w)
        failRead(name, in.at() + ": expected '" + std::string(*words.begin()) + " ...', found " + quoted(in.line));
    if (in.words.size() != k + numbers)
      failRead(name, in.at() + ": expected " + std::to_string(numbers) + " numbers, found " + quoted(in.line));
    for (; k < in.words.size(); ++k) {
      double v = 0;
      if (unread && isNumber(in.words[k])) continue;
      if (!parseDouble(in.words[k], v) || !fitsFloat(v))
        failRead(name, in.at() + ": " + quoted(in.words[k]) + " is not a finite number within float range");
    }
  };
  auto next = [&] {
    if (!in.next()) failRead(name, "the ASCII STL ends without 'endsolid' (truncated?)");
  };
  for (next(); in.words[0] != "endsolid"; next()) {
    check({"facet", "normal"}, 3, true);
    next(), check({"outer", "loop"}, 0);
    for (int k = 0; k < 3; ++k) {
      next(), check({"vertex"}, 3);
      glm::dvec3 q(0.0);
      for (int d = 0; d < 3; ++d) parseDouble(in.words[size_t(d) + 1], q[d]);
      c.points.push_back(q);  // in double (OpenMesh reads them as float)
    }
    next(), check({"endloop"}, 0);
    next(), check({"endfacet"}, 0);
    ++c.faces;
  }
  if (in.next()) failRead(name, in.at() + ": data after 'endsolid'");
  c.vertices = 3 * c.faces;
  return c;
}

}  // namespace gi::io::detail
