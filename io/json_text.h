// JSON as text for files and stdout. File names and parameter texts are
// bytes that need not be UTF-8 (a Latin-1 name such as caf\xe9.ply), which
// nlohmann's dump refuses with an exception: such bytes become U+FFFD.
// Files read back are parsed with a bound on their nesting: nlohmann's
// parser keeps its own stack, but copying or comparing a value recurses
// once per level, and a parameter file nested 200,000 deep crashed the
// batch tool (an outside audit); none of our files nests past 8.
#pragma once
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace gi::io {

inline std::string dumpJson(const nlohmann::json& j, int indent = -1) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

inline constexpr int kMaxJsonDepth = 64;

// nlohmann::json::parse, refusing text nested deeper than kMaxJsonDepth
// and an object that gives one key twice (throws std::invalid_argument
// saying so; parse errors as parse throws). nlohmann keeps the last of two
// values in silence: a parameter file giving "rays_per_vertex" twice ran
// with one of them, the user not told which (an outside audit).
inline nlohmann::json parseJson(const std::string& text) {
  std::vector<std::set<std::string>> keys;  // of each object being read, innermost last
  return nlohmann::json::parse(text, [&keys](int depth, nlohmann::json::parse_event_t e, nlohmann::json& j) {
    if (depth > kMaxJsonDepth)
      throw std::invalid_argument("JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    using E = nlohmann::json::parse_event_t;
    if (e == E::object_start) keys.emplace_back();
    else if (e == E::object_end && !keys.empty()) keys.pop_back();
    else if (e == E::key && !keys.empty() && j.is_string() && !keys.back().insert(j.get<std::string>()).second)
      throw std::invalid_argument("JSON object gives the key " + dumpJson(j).substr(0, 80) + " twice");
    return true;
  });
}

}  // namespace gi::io
