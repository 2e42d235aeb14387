#include "result_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "atomic_file.h"
#include "json_text.h"
#include "mesh_io.h"
#include "output_files.h"

namespace gi::io {

using json = nlohmann::json;

namespace {

std::string hex(uint64_t v, int digits) {
  char b[32];
  std::snprintf(b, sizeof b, "%0*llx", digits, static_cast<unsigned long long>(v));
  return b;
}

std::vector<uint8_t> flatColors(const std::vector<Rgb8>& c) {
  std::vector<uint8_t> f;
  f.reserve(c.size() * 3);
  for (const Rgb8& x : c) f.insert(f.end(), {x.r, x.g, x.b});
  return f;
}

std::vector<Rgb8> colors(const json& j) {
  if (!j.is_array()) throw std::runtime_error("a colour array is not an array");
  std::vector<uint8_t> f;
  f.reserve(j.size());
  for (const json& v : j) {
    if (!v.is_number_unsigned() || v.get<uint64_t>() > 255) throw std::runtime_error("a colour is not an integer 0..255");
    f.push_back(uint8_t(v.get<unsigned>()));
  }
  if (f.size() % 3) throw std::runtime_error("a colour array is not a multiple of 3 long");
  std::vector<Rgb8> c(f.size() / 3);
  for (size_t i = 0; i < c.size(); ++i) c[i] = {f[3 * i], f[3 * i + 1], f[3 * i + 2]};
  return c;
}

std::vector<float> flatVectors(const std::vector<glm::vec3>& v) {
  std::vector<float> f;
  f.reserve(v.size() * 3);
  for (const glm::vec3& x : v) f.insert(f.end(), {x.x, x.y, x.z});
  return f;
}

// A per-vertex attribute's name as a PLY property: a letter, then letters,
// digits and underscores, and none of the properties the writer puts there itself.
bool plyAttributeName(const std::string& name) {
  if (name.empty() || name.size() > 64 || !std::isalpha(static_cast<unsigned char>(name[0]))) return false;
  if (!std::all_of(name.begin(), name.end(), [](unsigned char c) { return std::isalnum(c) || c == '_'; })) return false;
  return !plyVertexPropertyOfItsOwn(name);
}

}  // namespace

void writeResultFile(const std::string& path, const ResultKey& key, const FilterResult& r) {
  json j;
  j["format"] = "gi-result";
  j["version"] = 1;
  j["filter"] = key.filter;
  j["file"] = key.mesh;
  j["scene_hash"] = hex(key.sceneHash, 16);
  j["parameters"] = key.parameters;
  j["seconds"] = r.stats.get("seconds");
  j["vertices"] = r.vertexQuality.size();
  j["vertex_quality"] = r.vertexQuality;
  j["vertex_color"] = flatColors(r.vertexColor);
  j["vertex_normal"] = flatVectors(r.vertexNormal);
  j["face_quality"] = r.faceQuality;
  j["face_color"] = flatColors(r.faceColor);
  json attrs = json::object();
  for (const VertexAttribute& a : r.attributes) attrs[a.name] = {{"components", a.components}, {"values", a.values}};
  j["attributes"] = attrs;
  json files = json::array();  // text outputs (radiosity's residual CSV, exported system): rewritten on reuse
  for (const FilterFile& x : r.files) files.push_back({{"path", x.path}, {"text", x.text}});
  j["files"] = files;
  json numbers = json::object();
  for (const auto& [k, v] : r.stats.numbers) numbers[k] = v;
  j["stats"] = numbers;
  j["notes"] = r.stats.notes;
  j["warnings"] = r.stats.warnings;
  writeFileAtomically(path, dumpJson(j));
}

ResultKey readResultFile(const std::string& path, FilterResult& r) {
  std::string text;
  try {
    text = files::readTextFile(path, "cached result");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
  try {
    const json j = parseJson(text);
    if (j.at("format") != "gi-result" || j.at("version") != 1) throw std::runtime_error("not a gi result file (version 1)");
    const std::string hash = j.at("scene_hash").get<std::string>();
    if (hash.empty() || hash.size() > 16 ||
        !std::all_of(hash.begin(), hash.end(), [](unsigned char c) { return std::isxdigit(c) != 0; }))
      throw std::runtime_error("its scene hash is not 1 to 16 hex digits");
    ResultKey key{j.at("filter"), j.at("file"), std::stoull(hash, nullptr, 16), j.at("parameters")};
    r.vertexQuality = j.at("vertex_quality").get<std::vector<float>>();
    r.vertexColor = colors(j.at("vertex_color"));
    const auto n = j.at("vertex_normal").get<std::vector<float>>();
    if (n.size() % 3) throw std::runtime_error("vertex_normal is not a multiple of 3 long");
    r.vertexNormal.resize(n.size() / 3);
    for (size_t i = 0; i < r.vertexNormal.size(); ++i) r.vertexNormal[i] = {n[3 * i], n[3 * i + 1], n[3 * i + 2]};
    r.faceQuality = j.at("face_quality").get<std::vector<float>>();
    r.faceColor = colors(j.at("face_color"));
    r.attributes.clear();
    const size_t nv = j.at("vertices");
    for (const auto& [name, a] : j.at("attributes").items()) {
      if (!plyAttributeName(name)) throw std::runtime_error("attribute '" + name + "' is not a PLY property name of its own");
      if (!a.at("components").is_number_integer()) throw std::runtime_error("attribute " + name + ": components is not 1 or 3");
      VertexAttribute x{name, a.at("components"), a.at("values").get<std::vector<float>>()};
      if ((x.components != 1 && x.components != 3) || x.values.size() != nv * size_t(x.components))
        throw std::runtime_error("attribute " + name + " does not match the vertex count");
      r.attributes.push_back(std::move(x));
    }
    if (r.vertexQuality.size() != nv || (!r.vertexColor.empty() && r.vertexColor.size() != nv) ||
        (!r.vertexNormal.empty() && r.vertexNormal.size() != nv))
      throw std::runtime_error("array sizes do not match the vertex count");
    // JSON numbers beyond float range become infinities: no result holds one.
    auto finite = [](const std::vector<float>& v) {
      return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x); });
    };
    bool allFinite = finite(r.vertexQuality) && finite(r.faceQuality) && finite(n);
    for (const VertexAttribute& a : r.attributes) allFinite = allFinite && finite(a.values);
    if (!allFinite) throw std::runtime_error("it holds a value that is not a finite number in float range");
    r.files.clear();
    if (j.contains("files"))
      for (const auto& x : j.at("files")) r.files.push_back({x.at("path"), x.at("text")});
    r.stats = RunStats();
    for (const auto& [k, v] : j.at("stats").items()) r.stats.add(k, v.get<double>());
    r.stats.notes = j.at("notes").get<std::vector<std::string>>();
    r.stats.warnings = j.at("warnings").get<std::vector<std::string>>();
    return key;
  } catch (const std::exception& e) {
    // The JSON library's messages begin "[json.exception.type_error.302] ": said without it.
    std::string what = e.what();
    if (what.rfind("[json.exception.", 0) == 0 && what.find("] ") != std::string::npos) what = what.substr(what.find("] ") + 2);
    throw std::runtime_error("cannot read " + path + ": " + what);
  }
}

std::string resultCachePath(const std::string& dir, const ResultKey& key) {
  std::string stem = key.mesh.substr(key.mesh.find_last_of('/') + 1);
  stem = stem.substr(0, stem.find_last_of('.'));
  uint64_t h = 1469598103934665603ull;  // FNV-1a of the parameters
  for (unsigned char c : key.parameters) { h ^= c; h *= 1099511628211ull; }
  return dir + "/" + stem + "-" + key.filter + "-" + hex(key.sceneHash, 16) + "-" + hex(h & 0xffffffffull, 8) +
         ".giresult.json";
}

}  // namespace gi::io
