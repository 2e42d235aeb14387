// Parameter descriptions shared by the MeshLab dialogs and the CLI flags: one
// table per algorithm gives name, help, default, range and validation, so the
// two front ends cannot drift apart.
#pragma once
#include <array>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <glm/glm.hpp>

namespace gi {

enum class ParamType {
  Bool,
  Int,
  Float,
  Distance,   // absolute length; default and range given as fractions of the bbox diagonal
  Enum,       // index into choices
  Color,      // sRGB in [0,1] (MeshLab colour picker / CLI "r,g,b" 0-255 or #rrggbb)
  Direction,  // a vector, normalised on use
  Point,      // a position (absolute coordinates)
  String,     // free text (e.g. layer-name patterns)
};

// A parameter that only some settings of another use: `param` (an Enum or a
// Bool of the same table) must hold one of `values` (the choices' indices; a
// Bool's 0 or 1). The two-pass view's caustic map is read in that mode only.
struct ParamUse {
  std::string param;
  std::vector<int> values;
};

struct ParamSpec {
  std::string name;   // id in .mlx scripts and --name on the CLI
  std::string label;  // short text in the MeshLab dialog
  std::string help;   // tooltip and --help text
  ParamType type = ParamType::Float;
  double def = 0.0, min = 0.0, max = 0.0;  // Distance: fractions of the diagonal
  std::vector<std::string> choices;        // Enum
  glm::vec3 defVec{0.f};                   // Color, Direction
  bool meshlabOnly = false;                // e.g. layer choice (the CLI has one scene)
  std::string defText;                     // String
  // Settings that use it, all to hold (empty: every setting). A number a
  // setting does not use is not range-checked there: a script written for
  // a 2 m room (an absolute caustic radius of 0.17) must still run a 1 cm
  // part in a mode that has no caustic map.
  std::vector<ParamUse> usedWhen;
  // String: the text's own syntax (a list of step counts), checked by
  // validate() with the ranges, so that a script, a batch or the dialog is
  // refused before any work; returns "" when the text is fine, else why not.
  std::string (*checkText)(const std::string& text) = nullptr;
};

// Colours and directions in float; positions (Point) in double, so that a
// point light or an eye among coordinates far from the origin (a scan in UTM
// metres) is not rounded to a float's step there (0.5 at 5e6: a light 3 m
// over a plane at 512,345 m read 2.6% off; an outside audit).
using ParamValue = std::variant<bool, int, double, glm::vec3, std::string, glm::dvec3>;

class ParamValues {
 public:
  void set(const std::string& name, ParamValue v) { v_[name] = v; }
  bool has(const std::string& name) const { return v_.count(name) != 0; }
  bool getBool(const std::string& n) const { return std::get<bool>(at(n)); }
  int getInt(const std::string& n) const { return std::get<int>(at(n)); }
  double getFloat(const std::string& n) const { return std::get<double>(at(n)); }
  glm::vec3 getVec(const std::string& n) const { return std::get<glm::vec3>(at(n)); }
  // A Point parameter, in double (one given in float, as a library caller
  // may, is widened).
  glm::dvec3 getPoint(const std::string& n) const {
    const ParamValue& x = at(n);
    if (const auto* d = std::get_if<glm::dvec3>(&x)) return *d;
    return glm::dvec3(std::get<glm::vec3>(x));
  }
  // A Direction parameter as a unit vector (see unitDirection); throws
  // std::invalid_argument for a zero or non-finite one.
  glm::vec3 getDirection(const std::string& n) const;
  const std::string& getString(const std::string& n) const { return std::get<std::string>(at(n)); }
  const std::map<std::string, ParamValue>& all() const { return v_; }

 private:
  const ParamValue& at(const std::string& n) const;
  std::map<std::string, ParamValue> v_;
};

// The unit vector along d, normalised in double after dividing by its
// largest component, so that components of 1e20 (whose squares overflow a
// float) or 1e-30 (whose squares underflow) keep their direction; nothing for
// a zero or non-finite d.
std::optional<glm::vec3> unitDirection(const glm::vec3& d);
// unitDirection for a vector that is usually of unit length already (a
// caller's normal or direction): one whose squared length is within 1e-6 of
// 1 keeps its bits.
std::optional<glm::vec3> unitKeepingBits(const glm::vec3& d);

// Defaults of a table for a scene of the given bbox diagonal.
ParamValues defaultValues(const std::vector<ParamSpec>& specs, double diagonal);
// Whether the values' settings use `spec` (its usedWhen all hold; a setting
// missing from v or of another type counts as holding).
bool isUsed(const std::vector<ParamSpec>& specs, const ParamSpec& spec, const ParamValues& v);
// "used only when mode is Two-pass and two_pass_diffuse is A or B" (byLabel:
// the dialog's labels, 'Rendering method' is 'Two-pass'); empty where always used.
std::string usedWhenText(const std::vector<ParamSpec>& specs, const ParamSpec& spec, bool byLabel);
// Checks presence, types and ranges (of a number only where isUsed); returns
// an error sentence or nothing.
std::optional<std::string> validate(const std::vector<ParamSpec>& specs, const ParamValues& v, double diagonal);
// "name=value, ..." for logs, JSON-free summaries and the key of a cached
// result: every number as the shortest text that reads back as itself (six
// digits let two point lights 278 mm apart at 5.56e8 share a cache entry; an
// outside audit).
std::string describe(const std::vector<ParamSpec>& specs, const ParamValues& v);
// Parses a CLI value ("12.5", "10%" for Distance, "r,g,b" or "#rrggbb" for Color,
// an enum's name or index). Throws std::invalid_argument with a sentence.
ParamValue parseValue(const ParamSpec& spec, const std::string& text, double diagonal);
const ParamSpec* findSpec(const std::vector<ParamSpec>& specs, const std::string& name);
// The range validate() enforces, for the help texts ("1 to 4096", "at most
// 10 x the bbox diagonal"); empty where any value of the type is taken.
// MeshLab 2020.09's number fields have no limits to show it (an outside
// audit found the ranges stated nowhere).
std::string rangeText(const ParamSpec& spec);
// A library caller fills the options structs directly, past the table's
// checks: each filter's entry point refuses a number outside the table's
// range for `name` (or not finite) with std::invalid_argument, in the words
// validate() uses.
void requireInRange(const std::vector<ParamSpec>& specs, const std::string& name, double value);

// One table per enumeration: each value with the choice the dialog shows (and
// scripts and the CLI accept) and the short name the log uses, so that the
// three cannot drift apart. A value's dialog index is its place in the table,
// which .mlx scripts store: append new values, never reorder.
template <class E>
struct EnumChoice {
  E value;
  const char* choice;  // dialog, .mlx and CLI
  const char* log;     // log lines
};
template <class E, size_t N>
struct EnumTable {
  std::array<EnumChoice<E>, N> entries;
  std::vector<std::string> choices() const {
    std::vector<std::string> c;
    for (const auto& e : entries) c.push_back(e.choice);
    return c;
  }
  constexpr int index(E v) const {
    for (size_t i = 0; i < N; ++i)
      if (entries[i].value == v) return int(i);
    throw std::logic_error("enumeration value missing from its table");
  }
  E at(int i) const {
    if (i < 0 || size_t(i) >= N) throw std::invalid_argument("choice " + std::to_string(i) + " does not exist");
    return entries[size_t(i)].value;
  }
  const char* logName(E v) const { return entries[size_t(index(v))].log; }
  // The value of enumeration parameter `name` in v.
  E get(const ParamValues& v, const std::string& name) const { return at(v.getInt(name)); }
};
template <class E, class... C>
constexpr EnumTable<E, sizeof...(C)> makeEnumTable(C... c) {
  return {{{c...}}};
}
namespace detail {
template <class E, size_t N, size_t... I>
constexpr EnumTable<E, N> enumTableFromArray(const EnumChoice<E> (&c)[N], std::index_sequence<I...>) {
  return {{{c[I]...}}};
}
}  // namespace detail
// The same from a braced list: makeEnumTable<E>({{E::A, "A", "a"}, {E::B, "B", "b"}}).
template <class E, size_t N>
constexpr EnumTable<E, N> makeEnumTable(const EnumChoice<E> (&c)[N]) {
  return detail::enumTableFromArray(c, std::make_index_sequence<N>{});
}
// The "seed" parameter every stochastic filter has; `what` names what it seeds.
ParamSpec seedSpec(const std::string& what);

}  // namespace gi
