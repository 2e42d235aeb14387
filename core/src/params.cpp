#include "gi/params.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace gi {

const ParamValue& ParamValues::at(const std::string& n) const {
  auto it = v_.find(n);
  if (it == v_.end()) throw std::invalid_argument("missing parameter '" + n + "'");
  return it->second;
}

glm::vec3 ParamValues::getDirection(const std::string& n) const {
  const auto u = unitDirection(getVec(n));
  if (!u) throw std::invalid_argument("parameter '" + n + "' must be a non-zero finite direction");
  return *u;
}

std::optional<glm::vec3> unitKeepingBits(const glm::vec3& d) {
  const double l2 = glm::dot(glm::dvec3(d), glm::dvec3(d));
  if (std::isfinite(l2) && std::fabs(l2 - 1.0) <= 1e-6) return d;
  return unitDirection(d);
}

std::optional<glm::vec3> unitDirection(const glm::vec3& d) {
  const glm::dvec3 x(d);
  if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z)) return std::nullopt;
  const double m = std::max({std::fabs(x.x), std::fabs(x.y), std::fabs(x.z)});
  if (!(m > 0.0)) return std::nullopt;
  const glm::dvec3 y = x / m;  // largest component +-1: its length is in [1, sqrt 3]
  return glm::vec3(y / glm::length(y));
}

const ParamSpec* findSpec(const std::vector<ParamSpec>& specs, const std::string& name) {
  for (const auto& s : specs)
    if (s.name == name) return &s;
  return nullptr;
}

ParamSpec seedSpec(const std::string& what) {
  return {.name = "seed", .label = "Random seed",
          .help = "Seed of the " + what + ". The same seed gives bit-identical results for any thread count.",
          .type = ParamType::Int, .def = 0, .min = 0, .max = 2147483647};
}

ParamValues defaultValues(const std::vector<ParamSpec>& specs, double diagonal) {
  ParamValues v;
  for (const auto& s : specs) {
    switch (s.type) {
      case ParamType::Bool: v.set(s.name, s.def != 0.0); break;
      case ParamType::Int:
      case ParamType::Enum: v.set(s.name, int(s.def)); break;
      case ParamType::Float: v.set(s.name, s.def); break;
      case ParamType::Distance: v.set(s.name, s.def * diagonal); break;
      case ParamType::Color:
      case ParamType::Direction: v.set(s.name, s.defVec); break;
      case ParamType::Point: v.set(s.name, glm::dvec3(s.defVec)); break;
      case ParamType::String: v.set(s.name, s.defText); break;
    }
  }
  return v;
}

// The shortest text that reads back as x (a range message rounded to six
// digits said "0.5 is outside [0, 0.5]" of 0.5000001, an outside audit).
static std::string exact(double x) {
  char b[64];
  const auto r = std::to_chars(b, b + sizeof b, x);
  return std::string(b, r.ptr);
}
static std::string exact(float x) {  // a vector's component: the shortest text of the float itself
  char b[64];
  const auto r = std::to_chars(b, b + sizeof b, x);
  return std::string(b, r.ptr);
}

std::string rangeText(const ParamSpec& s) {
  switch (s.type) {
    case ParamType::Int:
    case ParamType::Float:
      return s.min < s.max ? exact(s.min) + " to " + exact(s.max) : "";
    case ParamType::Distance:
      return s.max > 0.0 ? "0 to " + exact(s.max) + " x the bbox diagonal" : "0 or more";
    default:
      return "";
  }
}

bool isUsed(const std::vector<ParamSpec>& specs, const ParamSpec& spec, const ParamValues& v) {
  for (const ParamUse& u : spec.usedWhen) {
    const ParamSpec* c = findSpec(specs, u.param);
    if (!c || !v.has(u.param)) continue;
    const ParamValue& x = v.all().at(u.param);
    int value;
    if (const int* i = std::get_if<int>(&x); i && c->type == ParamType::Enum) value = *i;
    else if (const bool* b = std::get_if<bool>(&x); b && c->type == ParamType::Bool) value = *b ? 1 : 0;
    else continue;
    if (std::find(u.values.begin(), u.values.end(), value) == u.values.end()) return false;
  }
  return true;
}

std::string usedWhenText(const std::vector<ParamSpec>& specs, const ParamSpec& spec, bool byLabel) {
  std::string out;
  for (const ParamUse& u : spec.usedWhen) {
    const ParamSpec* c = findSpec(specs, u.param);
    if (!c) throw std::logic_error("parameter '" + spec.name + "' depends on '" + u.param + "', not in its table");
    std::string values;
    for (size_t k = 0; k < u.values.size(); ++k) {
      const int x = u.values[k];
      std::string name;
      if (c->type == ParamType::Bool) name = x ? "on" : "off";
      else if (c->type == ParamType::Enum && x >= 0 && size_t(x) < c->choices.size()) name = c->choices[size_t(x)];
      else throw std::logic_error("parameter '" + spec.name + "' depends on a value '" + u.param + "' cannot take");
      if (byLabel) name = "'" + name + "'";
      values += (k == 0 ? "" : k + 1 == u.values.size() ? " or " : ", ") + name;
    }
    out += (out.empty() ? "used only when " : " and ") + (byLabel ? "'" + c->label + "'" : u.param) + " is " + values;
  }
  return out;
}

void requireInRange(const std::vector<ParamSpec>& specs, const std::string& name, double value) {
  const ParamSpec* s = findSpec(specs, name);
  if (!s) throw std::logic_error("no parameter '" + name + "' in the table");
  // As validate(): a bound handed through single precision passes (MeshLab's
  // dialog holds 1e-12 as 9.99999996e-13).
  const bool below = value < s->min && float(value) < float(s->min), above = value > s->max && float(value) > float(s->max);
  if (!std::isfinite(value) || below || above)
    throw std::invalid_argument("parameter '" + name + "' = " + exact(value) + " is outside [" + exact(s->min) + ", " +
                                exact(s->max) + "]");
}

std::optional<std::string> validate(const std::vector<ParamSpec>& specs, const ParamValues& v, double diagonal) {
  for (const auto& s : specs) {
    if (!v.has(s.name)) return "parameter '" + s.name + "' is missing";
    const bool used = isUsed(specs, s, v);
    try {
      switch (s.type) {
        case ParamType::Bool: (void)v.getBool(s.name); break;
        case ParamType::Int: {
          int x = v.getInt(s.name);
          if (used && (x < s.min || x > s.max))
            return "parameter '" + s.name + "' = " + std::to_string(x) + " is outside [" + exact(s.min) + ", " + exact(s.max) + "]";
          break;
        }
        case ParamType::Float: {
          double x = v.getFloat(s.name);
          // Front ends hand values through single precision (MeshLab's
          // RichFloat, the CLI's checks): a bound given as is must pass
          // (1e-12 arrives as 9.99999996e-13).
          const bool below = x < s.min && float(x) < float(s.min), above = x > s.max && float(x) > float(s.max);
          if (used && (!std::isfinite(x) || below || above))
            return "parameter '" + s.name + "' = " + exact(x) + " is outside [" + exact(s.min) + ", " + exact(s.max) + "]";
          break;
        }
        case ParamType::Distance: {
          double x = v.getFloat(s.name);
          if (!used) break;
          if (!std::isfinite(x) || x < 0.0)
            return "parameter '" + s.name + "' = " + exact(x) + " must be a finite distance >= 0";
          if (s.max > 0.0 && diagonal > 0.0 && x > s.max * diagonal * (1.0 + 1e-6))
            return "parameter '" + s.name + "' = " + exact(x) + " exceeds " + exact(s.max) + " x the bbox diagonal (" + exact(diagonal) + ")";
          break;
        }
        case ParamType::Enum: {
          int x = v.getInt(s.name);
          if (x < 0 || x >= int(s.choices.size()))
            return "parameter '" + s.name + "' = " + std::to_string(x) + " is not one of 0.." + std::to_string(s.choices.size() - 1);
          break;
        }
        case ParamType::Color: {
          glm::vec3 c = v.getVec(s.name);
          for (int k = 0; k < 3; ++k)
            if (!(c[k] >= 0.f && c[k] <= 1.f)) return "parameter '" + s.name + "' has a channel outside 0-255";
          break;
        }
        case ParamType::Direction: {
          if (!unitDirection(v.getVec(s.name)))
            return "parameter '" + s.name + "' must be a non-zero finite direction";
          break;
        }
        case ParamType::Point: {
          const glm::dvec3 d = v.getPoint(s.name);
          if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z))
            return "parameter '" + s.name + "' must be a finite position";
          break;
        }
        case ParamType::String:
          // One line of text: a script's attribute turns a line break or a
          // tab into a space (XML attribute normalisation). The characters
          // " < > & are escaped by `gi script` and read back by MeshLab.
          for (const char c : v.getString(s.name))
            if ((static_cast<unsigned char>(c) < 0x20) || c == 0x7f)
              return "parameter '" + s.name + "' must be one line of text (no line breaks, tabs or control characters)";
          if (s.checkText)
            if (std::string why = s.checkText(v.getString(s.name)); !why.empty()) return why;
          break;
      }
    } catch (const std::bad_variant_access&) {
      return "parameter '" + s.name + "' has the wrong type";
    }
  }
  return std::nullopt;
}

std::string describe(const std::vector<ParamSpec>& specs, const ParamValues& v) {
  std::ostringstream o;
  bool first = true;
  for (const auto& s : specs) {
    if (!v.has(s.name)) continue;
    o << (first ? "" : ", ") << s.name << '=';
    first = false;
    switch (s.type) {
      case ParamType::Bool: o << (v.getBool(s.name) ? "true" : "false"); break;
      case ParamType::Int: o << v.getInt(s.name); break;
      case ParamType::Enum: o << s.choices.at(size_t(v.getInt(s.name))); break;
      case ParamType::Float:
      case ParamType::Distance: {
        // A value MeshLab's float dialog gave (53.407f) as its float's
        // shortest text, not 53.40700149536133; distinct values stay distinct.
        const double x = v.getFloat(s.name);
        o << (double(float(x)) == x ? exact(float(x)) : exact(x));
        break;
      }
      case ParamType::Color:
      case ParamType::Direction: {
        glm::vec3 c = v.getVec(s.name);
        o << exact(c.x) << ',' << exact(c.y) << ',' << exact(c.z);
        break;
      }
      case ParamType::Point: {
        const glm::dvec3 c = v.getPoint(s.name);
        o << exact(c.x) << ',' << exact(c.y) << ',' << exact(c.z);
        break;
      }
      case ParamType::String: {  // quoted, with " and \ escaped: distinct texts stay distinct
        o << '"';
        for (const char c : v.getString(s.name)) o << (c == '"' || c == '\\' ? "\\" : "") << c;
        o << '"';
        break;
      }
    }
  }
  return o.str();
}

static std::vector<double> splitNumbers(const std::string& t) {
  std::vector<double> out;
  std::stringstream ss(t);
  std::string item;
  while (std::getline(ss, item, ',')) {
    size_t pos = 0;
    double x = std::stod(item, &pos);
    while (pos < item.size() && std::isspace(static_cast<unsigned char>(item[pos]))) ++pos;
    if (pos != item.size()) throw std::invalid_argument(item);
    out.push_back(x);
  }
  return out;
}

ParamValue parseValue(const ParamSpec& s, const std::string& text, double diagonal) {
  auto bad = [&](const std::string& why) {
    return std::invalid_argument("--" + s.name + " '" + text + "': " + why);
  };
  // The engine and MeshLab keep these values in single precision (docs/design.md,
  // "Precision of parameters"): a value that is not 0 must not become 0 there
  // (for a distance, 0 means no limit) nor overflow to infinity.
  auto single = [&](double x) {
    const float f = float(x);
    if (x != 0.0 && std::isfinite(x) && f == 0.f) throw bad("rounds to 0 in single precision (smallest: 1.4e-45)");
    if (std::isfinite(x) && !std::isfinite(f)) throw bad("beyond the largest single-precision number (3.4e+38)");
    return x;
  };
  try {
    switch (s.type) {
      case ParamType::Bool:
        if (text == "1" || text == "true" || text == "on" || text == "yes") return true;
        if (text == "0" || text == "false" || text == "off" || text == "no") return false;
        throw bad("expected true or false");
      case ParamType::Int: {
        size_t pos = 0;
        long x = std::stol(text, &pos);
        if (pos != text.size()) throw bad("expected an integer");
        if (x < -2147483647L - 1 || x > 2147483647L) throw bad("out of range");
        return int(x);
      }
      case ParamType::Float: {
        size_t pos = 0;
        double x = std::stod(text, &pos);
        if (pos != text.size()) throw bad("expected a number");
        return single(x);
      }
      case ParamType::Distance: {
        size_t pos = 0;
        double x = std::stod(text, &pos);
        if (pos + 1 == text.size() && text[pos] == '%') return single(x * 0.01 * diagonal);
        if (pos != text.size()) throw bad("expected a length or a percentage of the bbox diagonal like 10%");
        return single(x);
      }
      case ParamType::Enum: {
        for (size_t i = 0; i < s.choices.size(); ++i)
          if (s.choices[i] == text) return int(i);
        size_t pos = 0;
        long x = std::stol(text, &pos);
        if (pos != text.size() || x < -2147483647L - 1 || x > 2147483647L) throw std::invalid_argument("");
        return int(x);
      }
      case ParamType::Color: {
        if (text.size() == 7 && text[0] == '#') {
          if (text.find_first_not_of("0123456789abcdefABCDEF", 1) != std::string::npos) throw bad("expected #rrggbb");
          unsigned r, g, b;
          if (std::sscanf(text.c_str() + 1, "%2x%2x%2x", &r, &g, &b) != 3) throw bad("expected #rrggbb");
          return glm::vec3(r / 255.f, g / 255.f, b / 255.f);
        }
        auto n = splitNumbers(text);
        if (n.size() != 3) throw bad("expected r,g,b (0-255) or #rrggbb");
        // Whole channels, as MeshLab's colour dialog and a script hold them: a
        // fraction (100.4) was used here but rounded in the script, so the
        // two gave different results; 0.5,0.5,0.5 meant as 0-1 read as
        // nearly black (an outside audit).
        for (double c : n)
          if (!(c >= 0.0 && c <= 255.0) || c != std::floor(c))
            throw bad("each channel of r,g,b is a whole number in 0-255 (not a 0-1 fraction)");
        return glm::vec3(float(n[0] / 255.0), float(n[1] / 255.0), float(n[2] / 255.0));
      }
      case ParamType::Direction:
      case ParamType::Point: {
        auto n = splitNumbers(text);
        if (n.size() != 3) throw bad("expected x,y,z");
        if (s.type == ParamType::Point) return glm::dvec3(n[0], n[1], n[2]);
        return glm::vec3(float(n[0]), float(n[1]), float(n[2]));
      }
      case ParamType::String: return text;
    }
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).rfind("--", 0) == 0) throw;
    std::string choices;
    for (const auto& c : s.choices) choices += (choices.empty() ? "" : ", ") + c;
    throw bad(s.type == ParamType::Enum ? "expected one of: " + choices : "not a valid value");
  } catch (const std::out_of_range&) {
    throw bad("out of range");
  }
  throw bad("unknown type");
}

}  // namespace gi
