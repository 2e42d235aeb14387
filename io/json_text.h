// JSON as text for files and stdout. File names and parameter texts are
// bytes that need not be UTF-8 (a Latin-1 name such as caf\xe9.ply), which
// nlohmann's dump refuses with an exception: such bytes become U+FFFD.
// Files read back are parsed with a bound on their nesting: nlohmann's
// parser keeps its own stack, but copying or comparing a value recurses
// once per level, and a parameter file nested 200,000 deep crashed the
// batch tool (an outside audit); none of our files nests past 8.
#pragma once
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace gi::io {

inline std::string dumpJson(const nlohmann::json& j, int indent = -1) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

inline constexpr int kMaxJsonDepth = 64;

// nlohmann::json::parse, refusing text nested deeper than kMaxJsonDepth
// (throws std::invalid_argument saying so; parse errors as parse throws).
inline nlohmann::json parseJson(const std::string& text) {
  return nlohmann::json::parse(text, [](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
    if (depth > kMaxJsonDepth)
      throw std::invalid_argument("JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    return true;
  });
}

}  // namespace gi::io
