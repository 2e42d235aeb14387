#include "gi_batch_inputs.h"

#include <fnmatch.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "json_text.h"
#include "output_files.h"

namespace gi::batch {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string oneLine(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

namespace {

// Whitespace-separated words; "double" or 'single' quotes keep spaces.
std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool in = false;
  char quote = 0;
  for (char c : line) {
    if (quote) {
      if (c == quote) quote = 0;
      else cur += c;
    } else if (c == '"' || c == '\'') {
      quote = c;
      in = true;
    } else if (c == ' ' || c == '\t' || c == '\r') {
      if (in) out.push_back(cur), cur.clear(), in = false;
    } else {
      cur += c;
      in = true;
    }
  }
  if (quote) throw std::invalid_argument("unclosed quote");
  if (in) out.push_back(cur);
  return out;
}

}  // namespace

// "--name value" and "--name=value" pairs, each name one of the filter's parameters.
Texts parameterPairs(const std::vector<std::string>& w, size_t from, const std::vector<ParamSpec>& specs,
                     const std::string& filter, const std::string& where) {
  Texts out;
  for (size_t i = from; i < w.size(); ++i) {
    std::string k = w[i];
    if (k.rfind("--", 0) != 0) throw std::invalid_argument(where + "unexpected '" + k + "' (parameters are --name value)");
    k = k.substr(2);
    std::string v;
    const size_t eq = k.find('=');
    if (eq != std::string::npos) v = k.substr(eq + 1), k = k.substr(0, eq);
    else if (i + 1 < w.size()) v = w[++i];
    else throw std::invalid_argument(where + "--" + k + " needs a value");
    const ParamSpec* p = findSpec(specs, k);
    if (!p || p->meshlabOnly) throw std::invalid_argument(where + "'" + filter + "' has no parameter --" + k);
    if (out.count(k)) throw std::invalid_argument(where + "--" + k + " is given twice");
    out[k] = v;
  }
  return out;
}

// A parameter file: {"filter": "ao" or its MeshLab name, "parameters": {name: value}};
// values as the CLI takes them ("10%", "255,255,255"), or JSON numbers, booleans and [x, y, z].
std::pair<std::string, Texts> readParamsFile(const std::string& path) {
  const std::string text = files::readTextFile(path, "parameter file", size_t(64) << 20);
  json j;
  try {
    j = gi::io::parseJson(text);
  } catch (const std::exception& e) {
    throw std::invalid_argument("the parameter file " + path + " is not JSON: " + oneLine(e.what()));
  }
  if (!j.is_object()) throw std::invalid_argument("the parameter file " + path + " must hold a JSON object");
  // A key it does not know is refused, as an unknown parameter is: a typo
  // ("paramters") dropped every parameter in silence (an outside audit).
  for (const auto& [k, v] : j.items())
    if (k != "filter" && k != "parameters")
      throw std::invalid_argument("the parameter file " + path + " has a key '" + k +
                                  "' it does not know (it takes \"filter\" and \"parameters\")");
  if (j.contains("filter") && !j["filter"].is_string())
    throw std::invalid_argument("\"filter\" in " + path + " must be a string");
  std::string filter = j.value("filter", "");
  Texts t;
  const json p = j.value("parameters", json::object());
  if (!p.is_object()) throw std::invalid_argument("\"parameters\" in " + path + " must be an object");
  for (const auto& [k, v] : p.items()) {
    if (v.is_string()) t[k] = v.get<std::string>();
    else if (v.is_boolean()) t[k] = v.get<bool>() ? "true" : "false";
    else if (v.is_number_float() && std::isfinite(v.get<double>()) && v.get<double>() == std::trunc(v.get<double>()) &&
             std::fabs(v.get<double>()) < 9.0e15)
      t[k] = std::to_string(int64_t(v.get<double>()));  // 8.0 and 1e2 are the integers JSON wrote them as
    else if (v.is_number()) t[k] = v.dump();
    else if (v.is_array() && v.size() == 3) t[k] = v[0].dump() + "," + v[1].dump() + "," + v[2].dump();
    else throw std::invalid_argument("parameter " + k + " in " + path + ": expected a string, number, boolean or [x, y, z]");
  }
  return {filter, t};
}

const FilterDesc& findFilter(const std::string& name) {
  if (const FilterDesc* d = gi::findFilter(name)) return *d;
  throw std::invalid_argument("unknown filter '" + name + "' (" + cliFilterNames() + ")");
}

std::vector<Job> readManifest(const std::string& path, const std::vector<ParamSpec>& specs, const std::string& filter) {
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw std::invalid_argument("the manifest " + path + " is a folder: give a file listing the meshes, or --dir for a folder of meshes");
  std::string text = files::readTextFile(path, "manifest", size_t(256) << 20);
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);  // a UTF-8 byte order mark is no part of a name
  std::istringstream f(text);
  const fs::path base = fs::path(path).parent_path();
  std::vector<Job> jobs;
  std::string line;
  for (int n = 1; std::getline(f, line); ++n) {
    const std::string where = "manifest " + path + " line " + std::to_string(n) + ": ";
    if (line.find('\0') != std::string::npos)  // no file name holds one: a binary file or a damaged line
      throw std::invalid_argument(where + "holds a NUL byte (is the manifest a text file?)");
    std::vector<std::string> w;
    try {
      w = words(line);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(where + e.what());
    }
    // A comment line starts with # itself; a quoted name may start with one
    // ("#1.ply" was dropped as a comment, silently; an outside audit).
    const size_t first = line.find_first_not_of(" \t\r");
    if (w.empty() || (first != std::string::npos && line[first] == '#')) continue;
    // A # where a parameter's name would come ends the line (a comment
    // after a mesh's parameters); a value may start with one (a colour
    // #ff8800).
    for (size_t k = 1; k < w.size();) {
      if (w[k][0] == '#') {
        w.resize(k);
        break;
      }
      k += w[k].rfind("--", 0) == 0 && w[k].find('=') == std::string::npos ? 2 : 1;
    }
    Job j;
    j.input = fs::path(w[0]).is_absolute() || base.empty() ? w[0] : (base / w[0]).string();
    j.overrides = parameterPairs(w, 1, specs, filter, where);
    j.base = base.string();
    j.where = where;
    jobs.push_back(j);
  }
  if (f.bad()) throw std::invalid_argument("cannot read the manifest " + path + ": " + std::strerror(errno));
  if (jobs.empty()) throw std::invalid_argument("the manifest " + path + " lists no mesh");
  return jobs;
}

std::vector<Job> readFolder(const std::string& dir, const std::string& pattern) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw std::invalid_argument("--dir " + dir + " is not a folder");
  // Every entry the pattern matches but a folder is a job: one that is no
  // regular file (a dangling link, a FIFO, a link in a loop) fails as that
  // mesh, as it does from a manifest (it was skipped in silence, and a link
  // in a loop stopped the whole batch with the library's message; an
  // outside audit). Folders are no meshes (an output folder inside --dir).
  // A name starting with a dot is matched only by a pattern starting with
  // one, as in a shell (an editor's .a.ply.swp, a copy tool's ._a.ply).
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    std::error_code kind;
    if (fnmatch(pattern.c_str(), e.path().filename().c_str(), FNM_PERIOD) == 0 && !e.is_directory(kind))
      names.push_back(e.path().filename().string());
  }
  if (ec) throw std::invalid_argument("cannot list " + dir + ": " + ec.message());
  if (names.empty()) throw std::invalid_argument("no file in " + dir + " matches --glob '" + pattern + "'");
  std::sort(names.begin(), names.end());
  std::vector<Job> jobs;
  for (const std::string& n : names) jobs.push_back({(fs::path(dir) / n).string(), {}, n + ": ", ""});
  return jobs;
}

// "I/N" from --shard, else a Slurm job array's task (id - min) / step of count, else 0/1.
std::pair<size_t, size_t> chooseShard(const std::string& text) {
  long long i = 0, n = 1;
  if (!text.empty()) {
    char slash = 0, rest = 0;
    errno = 0;
    if (std::sscanf(text.c_str(), "%lld %c %lld %c", &i, &slash, &n, &rest) != 3 || slash != '/')
      throw std::invalid_argument("--shard '" + text + "': expected I/N, e.g. 0/16");
    if (errno == ERANGE || n >= (1LL << 40) || i >= (1LL << 40))
      throw std::invalid_argument("--shard '" + text + "': I and N must be below 2^40");
  } else if (std::getenv("SLURM_ARRAY_TASK_COUNT")) {
    // Each variable an integer (a garbled one must not make every task shard
    // 0; nor an empty one, which was read as its default: an outside audit);
    // the task's index must be set, MIN and STEP may be left out.
    auto num = [](const char* name, long long fallback) {
      const char* v = std::getenv(name);
      if (!v && fallback < 0) throw std::invalid_argument(std::string(name) + " is not set, though SLURM_ARRAY_TASK_COUNT is");
      if (!v) return fallback;
      char* end = nullptr;
      errno = 0;
      const long long x = std::strtoll(v, &end, 10);
      if (end == v || *end != '\0' || errno == ERANGE || x < 0 || x >= (1LL << 40))
        throw std::invalid_argument(std::string(name) + " = '" + v + "' is not a Slurm array index or count");
      return x;
    };
    n = num("SLURM_ARRAY_TASK_COUNT", 1);
    if (n < 1) throw std::invalid_argument("SLURM_ARRAY_TASK_COUNT = 0: the job array has no task (or pass --shard I/N)");
    const long long step = std::max(1LL, num("SLURM_ARRAY_TASK_STEP", 1));
    const long long offset = num("SLURM_ARRAY_TASK_ID", -1) - num("SLURM_ARRAY_TASK_MIN", 0);
    i = offset < 0 || offset % step != 0 ? -1 : offset / step;
    if (i < 0 || i >= n)
      throw std::invalid_argument("SLURM_ARRAY_TASK_ID " + std::string(std::getenv("SLURM_ARRAY_TASK_ID") ? std::getenv("SLURM_ARRAY_TASK_ID") : "?") +
                                  " is not one of " + std::to_string(n) +
                                  " evenly spaced tasks: submit with --array=0-" + std::to_string(n - 1) + " or pass --shard I/N");
  }
  if (n < 1 || i < 0 || i >= n) throw std::invalid_argument("--shard " + text + ": needs 0 <= I < N");
  return {size_t(i), size_t(n)};
}

}  // namespace gi::batch
