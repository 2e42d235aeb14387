#include "reference.h"

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace gi::io {

using json = nlohmann::json;

static std::string hex(uint64_t v, int digits) {
  char b[32];
  std::snprintf(b, sizeof b, "%0*llx", digits, static_cast<unsigned long long>(v));
  return b;
}

void writeReference(const std::string& path, const ReferenceFile& r) {
  json j;
  j["format"] = "gi-reference";
  j["version"] = 1;
  j["mesh"] = r.mesh;
  j["scene_hash"] = hex(r.sceneHash, 16);
  j["parameters"] = r.parameters;
  j["seconds"] = r.seconds;
  j["vertices"] = r.B.size();
  auto flat = [](const std::vector<glm::vec3>& v) {
    std::vector<float> f;
    f.reserve(v.size() * 3);
    for (const auto& x : v) { f.push_back(x.r); f.push_back(x.g); f.push_back(x.b); }
    return f;
  };
  j["B"] = flat(r.B);
  j["H"] = flat(r.H);
  j["std_error_B"] = r.stdErrorB;
  j["std_error_H"] = r.stdErrorH;
  j["samples"] = r.samples;
  std::ofstream f(path);
  if (!(f << j.dump())) throw std::runtime_error("cannot write the reference " + path);
}

ReferenceFile readReference(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot read the reference " + path + ": no such file");
  try {
    const json j = json::parse(f);
    if (j.at("format") != "gi-reference" || j.at("version") != 1)
      throw std::runtime_error("not a gi reference file (version 1)");
    ReferenceFile r;
    r.mesh = j.at("mesh");
    r.sceneHash = std::stoull(j.at("scene_hash").get<std::string>(), nullptr, 16);
    r.parameters = j.at("parameters");
    r.seconds = j.at("seconds");
    auto unflat = [](const std::vector<float>& a) {
      std::vector<glm::vec3> v(a.size() / 3);
      for (size_t i = 0; i < v.size(); ++i) v[i] = {a[3 * i], a[3 * i + 1], a[3 * i + 2]};
      return v;
    };
    r.B = unflat(j.at("B").get<std::vector<float>>());
    r.H = unflat(j.at("H").get<std::vector<float>>());
    r.stdErrorB = j.at("std_error_B").get<std::vector<float>>();
    r.stdErrorH = j.at("std_error_H").get<std::vector<float>>();
    r.samples = j.at("samples").get<std::vector<int>>();
    const size_t n = j.at("vertices");
    if (r.B.size() != n || r.H.size() != n || r.stdErrorB.size() != n || r.stdErrorH.size() != n || r.samples.size() != n)
      throw std::runtime_error("array sizes do not match the vertex count");
    return r;
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read the reference " + path + ": " + e.what());
  }
}

std::string referenceCachePath(const std::string& dir, const std::string& mesh, uint64_t sceneHash,
                               const std::string& parameters) {
  std::string stem = mesh.substr(mesh.find_last_of('/') + 1);
  stem = stem.substr(0, stem.find_last_of('.'));
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : parameters) { h ^= c; h *= 1099511628211ull; }
  return dir + "/" + stem + "-" + hex(sceneHash, 16) + "-" + hex(h & 0xffffffffull, 8) + ".giref.json";
}

}  // namespace gi::io
