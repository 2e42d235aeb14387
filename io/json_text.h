// JSON as text for files and stdout. File names and parameter texts are
// bytes that need not be UTF-8 (a Latin-1 name such as caf\xe9.ply), which
// nlohmann's dump refuses with an exception: such bytes become U+FFFD.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace gi::io {

inline std::string dumpJson(const nlohmann::json& j, int indent = -1) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace gi::io
