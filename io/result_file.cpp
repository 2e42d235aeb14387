#include "result_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "atomic_file.h"
#include "json_text.h"
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
  const auto f = j.get<std::vector<uint8_t>>();
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
    const json j = json::parse(text);
    if (j.at("format") != "gi-result" || j.at("version") != 1) throw std::runtime_error("not a gi result file (version 1)");
    ResultKey key{j.at("filter"), j.at("file"), std::stoull(j.at("scene_hash").get<std::string>(), nullptr, 16),
                  j.at("parameters")};
    r.vertexQuality = j.at("vertex_quality").get<std::vector<float>>();
    r.vertexColor = colors(j.at("vertex_color"));
    const auto n = j.at("vertex_normal").get<std::vector<float>>();
    r.vertexNormal.resize(n.size() / 3);
    for (size_t i = 0; i < r.vertexNormal.size(); ++i) r.vertexNormal[i] = {n[3 * i], n[3 * i + 1], n[3 * i + 2]};
    r.faceQuality = j.at("face_quality").get<std::vector<float>>();
    r.faceColor = colors(j.at("face_color"));
    r.attributes.clear();
    const size_t nv = j.at("vertices");
    for (const auto& [name, a] : j.at("attributes").items()) {
      VertexAttribute x{name, a.at("components"), a.at("values").get<std::vector<float>>()};
      if ((x.components != 1 && x.components != 3) || x.values.size() != nv * size_t(x.components))
        throw std::runtime_error("attribute " + name + " does not match the vertex count");
      r.attributes.push_back(std::move(x));
    }
    if (r.vertexQuality.size() != nv || (!r.vertexColor.empty() && r.vertexColor.size() != nv))
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
    throw std::runtime_error("cannot read " + path + ": " + e.what());
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
