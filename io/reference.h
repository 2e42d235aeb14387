// Reference solutions on disk (JSON): per-vertex radiosity B and incident
// irradiance H with their standard errors and path counts, keyed by the
// scene's hash and the parameters, so a reference is computed once and the
// benchmarks reuse it.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace gi::io {

struct ReferenceFile {
  std::string mesh;          // source file name, informative
  uint64_t sceneHash = 0;    // gi::sceneHash of the scene it was computed on
  std::string parameters;    // gi::describe(...) of every parameter
  double seconds = 0;
  std::vector<glm::vec3> B, H;
  std::vector<float> stdErrorB, stdErrorH;
  std::vector<int> samples;
};

void writeReference(const std::string& path, const ReferenceFile& r);
// Throws std::runtime_error naming the file if it is missing or malformed.
ReferenceFile readReference(const std::string& path);
// "<dir>/<mesh stem>-<16 hex of the scene hash>-<8 hex of the parameters>.giref.json"
std::string referenceCachePath(const std::string& dir, const std::string& mesh, uint64_t sceneHash,
                               const std::string& parameters);

}  // namespace gi::io
