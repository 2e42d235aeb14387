#include "gi_batch.h"

#include <fnmatch.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tbb/global_control.h>

#include "atomic_file.h"
#include "gi/filter_files.h"
#include "gi/filter_run.h"
#include "gi/filters.h"
#include "gi_cluster.h"
#include "output_files.h"
#include "gi_output.h"
#include "json_text.h"
#include "mesh_io.h"
#include "vertex_file.h"

namespace gi::batch {

namespace fs = std::filesystem;
using json = nlohmann::json;
using Texts = std::map<std::string, std::string>;  // parameter name -> value as the CLI takes it

namespace {

struct Job {
  std::string input;  // path
  Texts overrides;    // this manifest line's parameters
  std::string where;  // "manifest line 7" (for messages)
  std::string stem;   // output name: OUT/stem.ply, OUT/stem.json
  std::string base;   // the manifest's folder: files its line's parameters name are relative to it
};

std::string oneLine(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

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
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    std::error_code kind;
    if (fnmatch(pattern.c_str(), e.path().filename().c_str(), 0) == 0 && !e.is_directory(kind))
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
    if (errno == ERANGE || n > (1LL << 40) || i > (1LL << 40))
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
      if (end == v || *end != '\0' || errno == ERANGE || x < 0 || x > (1LL << 40))
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

// The result PLY's digest and its new layers' (photon mapping's photons
// beside it, listed under "layers" in the summary), "" if one cannot be read.
std::string outputDigest(const fs::path& ply, const json& layers) {
  std::string d = fileDigest(ply.string());
  if (d.empty() || layers.is_null()) return d;
  if (!layers.is_array()) return "";
  for (const json& l : layers) {
    const std::string one = l.is_string() ? fileDigest(l.get<std::string>()) : "";
    if (one.empty()) return "";
    d += ";" + one;
  }
  return d;
}

// The files a mesh's parameters name (the values as given; one that does
// not parse fails that mesh alone, when it is computed).
FilterFiles plannedFiles(const FilterDesc& d, const Texts& params) {
  const auto specs = filterSpecs(d.kind);
  ParamValues v = defaultValues(specs, 1.0);
  for (const auto& [n, t] : params) {
    try {
      v.set(n, parseValue(*findSpec(specs, n), t, 1.0));
    } catch (const std::invalid_argument&) {
    }
  }
  try {
    return filterFiles(d.kind, v);
  } catch (const std::exception&) {
    return {};
  }
}

// What decides a mesh's result: the program's version, the filter, every
// parameter given, the input file (its name, size and modification time)
// and the files the parameters name (an error map's reference: its size
// and the hash of its bytes, which a copy keeping the time, or a rewrite
// within the file system's clock step, cannot hide; a reference computed
// anew was taken as done before, an outside audit).
std::string jobHash(const FilterDesc& d, const Texts& params, const std::string& input) {
  std::ostringstream o;
  o << "gi " << programIdentity() << "\nfilter " << d.cliName << "\n";
  for (const auto& [k, v] : params) o << k << "=" << v << "\n";
  std::error_code ec;
  const auto size = fs::file_size(input, ec);
  const auto time = fs::last_write_time(input, ec).time_since_epoch().count();
  o << "input " << fs::path(input).filename().string() << " " << (ec ? 0 : size) << " " << (ec ? 0 : time) << "\n";
  for (const NamedFile& f : plannedFiles(d, params).reads) o << f.parameter << " " << fileDigest(f.path) << "\n";
  return hashText(o.str());
}

json readJson(const fs::path& p) {
  try {
    return gi::io::parseJson(files::readTextFile(p.string(), "summary"));
  } catch (const std::exception&) {  // missing, not a regular file, not JSON: no summary
    return nullptr;
  }
}

// Written whole or not at all: a file that exists is complete.
void writeJson(const fs::path& p, const json& j) { io::writeFileAtomically(p.string(), io::dumpJson(j, 2) + "\n"); }

std::string reportName(const Args& a, size_t shard, size_t shards, bool explicitShard) {
  const std::string part = std::to_string(shard) + "-of-" + std::to_string(shards) + ".json";
  return !a.reportOnly ? "report-" + part : explicitShard ? "report-only-" + part : "report.json";
}

json statsJson(const RunStats& s) {
  json j = json::object();
  for (const auto& [k, v] : s.numbers) j[k] = v;
  return j;
}

// Loads, computes, writes OUT/stem.ply; returns the summary.
json bake(const FilterDesc& d, const Texts& params, const Job& job, const fs::path& ply) {
  Timer timer;
  const auto specs = filterSpecs(d.kind);
  io::LoadedMesh mesh = io::loadMesh(job.input);
  const std::vector<glm::vec3> fileNormals = std::move(mesh.scene.vertexNormals);
  mesh.scene.vertexNormals.clear();
  const double diag = sceneDiagonal(mesh.scene);
  FilterInput in;
  in.values = defaultValues(specs, diag);
  for (const auto& [k, v] : params) in.values.set(k, parseValue(*findSpec(specs, k), v, diag));
  if (auto err = validate(specs, in.values, diag)) throw std::invalid_argument(*err);
  in.layers = io::meshLayers(mesh, fs::path(job.input).filename().string());
  in.scene = std::move(mesh.scene);
  in.attrs = mesh.attrs;
  in.attributes = std::move(mesh.attributes);
  in.readVertexFile = io::readVertexFile;
  FilterResult r = runFilter(d.kind, in);
  for (const std::string& w : mesh.warnings) r.stats.warn(w);
  // The layers first: a result PLY that exists has its layers beside it. Each file is written whole or not at all.
  const std::vector<std::string> layers = writeLayerPlys(ply.string(), r);
  writeResultPly(ply.string(), in.scene, mesh.attrs, fileNormals, r, in.layers, in.attributes, mesh.points);
  json s;
  s["scene"] = {{"vertices", r.report.vertices}, {"faces", r.report.faces}, {"usable_faces", r.report.usableFaces()}};
  s["resolved"] = describe(specs, in.values);
  s["stats"] = statsJson(r.stats);
  s["rays"] = r.stats.get("rays");
  s["warnings"] = r.stats.warnings;
  s["notes"] = r.stats.notes;
  s["log"] = r.logLines(d.meshlabName);
  if (!layers.empty()) s["layers"] = layers;
  s["seconds"] = timer.seconds();
  return s;
}

// Every output the batch may write (each mesh's PLY, summary and new layers,
// the report) against its inputs (the meshes, a reference file, the
// manifest and the parameter file) and one another, before any mesh is
// computed (io/output_files.h).
void checkFiles(const Args& a, const FilterDesc& d, const Texts& common, const std::vector<Job>& jobs, size_t shard,
                size_t shards, bool explicitShard) {
  std::vector<files::Named> inputs, outputs;
  if (!a.manifest.empty()) inputs.push_back({a.manifest, "--manifest"});
  if (!a.paramsFile.empty()) inputs.push_back({a.paramsFile, "--params"});
  for (const Job& j : jobs) {
    inputs.push_back({j.input, ""});
    Texts params = common;
    for (const auto& [n, t] : j.overrides) params[n] = t;
    const FilterFiles plan = plannedFiles(d, params);
    // A batch writes each mesh's result and summary; a file named by a
    // parameter is one path for every mesh (radiosity's residual_csv and
    // export_system were dropped without a word; an outside audit).
    if (!plan.writes.empty())
      throw std::invalid_argument(j.where + "--" + plan.writes.front().parameter + " writes a file at one path (" +
                                  plan.writes.front().path + "): run '" + d.cliName + "' per mesh for it, not in a batch");
    for (const NamedFile& f : plan.reads) inputs.push_back({f.path, "--" + f.parameter});
    const std::string ply = (fs::path(a.outDir) / (j.stem + ".ply")).string();
    const std::string summary = (fs::path(a.outDir) / (j.stem + ".json")).string();
    if (a.reportOnly) {  // read, not written: the report must not take one's place
      inputs.push_back({summary, "the summary of " + j.input});
      continue;
    }
    outputs.push_back({ply, "the result of " + j.input});
    outputs.push_back({summary, "the summary of " + j.input});
    for (const std::string& name : plan.layers) outputs.push_back({layerPath(ply, name), "a layer of " + j.input});
  }
  outputs.push_back({(fs::path(a.outDir) / reportName(a, shard, shards, explicitShard)).string(), "the report"});
  files::check(inputs, outputs);
}

}  // namespace

void addOptions(CLI::App* sub, Args& a) {
  sub->add_option("filter", a.filter, "filter subcommand name (" + cliFilterNames() + "); optional with --params naming it");
  sub->add_option("--manifest", a.manifest, "file listing one mesh a line, each optionally followed by its own "
                                            "parameters (--name value); relative paths are relative to the "
                                            "manifest; # starts a comment, on a line of its own or where a "
                                            "parameter's name would come");
  sub->add_option("--dir", a.dir, "folder whose meshes matching --glob are the batch (instead of --manifest)");
  sub->add_option("--glob", a.glob, "file-name pattern in --dir [default: *.ply]");
  sub->add_option("-o,--output-dir", a.outDir, "folder for NAME.ply, NAME.json per mesh and the report (created if "
                                               "missing)")->required();
  sub->add_option("--params", a.paramsFile, "JSON parameter file {\"filter\": \"ao\", \"parameters\": {\"rays_per_vertex\": "
                                            "64, \"max_distance\": \"5%\"}}; command-line parameters override it, a "
                                            "manifest line's override both");
  sub->add_option("--shard", a.shard, "I/N: take every N-th mesh from the I-th (0-based); default: a Slurm job "
                                      "array's task (SLURM_ARRAY_TASK_ID - MIN of COUNT) if set, else all");
  sub->add_option("--threads", a.threads, "worker threads of this process (default: SLURM_CPUS_PER_TASK if set, "
                                          "else all cores); several processes may share a node")
      ->check(CLI::Range(1, 4096));
  sub->add_flag("--report-only", a.reportOnly, "compute nothing: count the results and failures the summaries record "
                                               "(all shards unless --shard is given) and write report.json");
  sub->add_flag("--json", a.json, "print the report as JSON on stdout");
  sub->add_flag("-q,--quiet", a.quiet, "no progress lines on stderr");
  sub->allow_extras();
}

int run(const Args& a, const std::vector<std::string>& extras) {
  if (cluster::size() > 1)
    throw std::invalid_argument("gi batch is one process per shard: start it with --shard I/N or in a Slurm job array, not under mpirun");
  std::string filter = a.filter;
  Texts fileParams;
  if (!a.paramsFile.empty()) {
    auto [f, t] = readParamsFile(a.paramsFile);
    if (!f.empty() && !filter.empty() && findFilter(f).cliName != findFilter(filter).cliName)
      throw std::invalid_argument("the parameter file is for '" + f + "', not '" + filter + "'");
    if (filter.empty()) filter = f;
    fileParams = t;
  }
  if (filter.empty()) throw std::invalid_argument("name the filter (gi batch ao ...) or give it in --params");
  const FilterDesc& d = findFilter(filter);
  const auto specs = filterSpecs(d.kind);
  Texts common;  // the parameter file's, then the command line's
  for (const auto& [k, v] : fileParams) {
    const ParamSpec* p = findSpec(specs, k);
    if (!p || p->meshlabOnly) throw std::invalid_argument(a.paramsFile + ": '" + d.cliName + "' has no parameter " + k);
    common[k] = v;
  }
  for (const auto& [k, v] : parameterPairs(extras, 0, specs, d.cliName, "")) common[k] = v;
  // Every mesh takes these: a value that cannot be read is said once, before
  // any mesh is loaded (it failed each mesh in turn). Ranges that depend on
  // the mesh (percentages of its diagonal) are checked per mesh.
  // Their ranges too, but for those in shares of a mesh's diagonal: a batch
  // re-run with a typo failed every mesh in turn.
  {
    ParamValues v = defaultValues(specs, 1.0);
    for (const auto& [k, t] : common) v.set(k, parseValue(*findSpec(specs, k), t, 1.0));
    if (auto err = validate(specs, v, 0.0)) throw std::invalid_argument(*err + " (every mesh takes it)");
  }

  if (a.manifest.empty() == a.dir.empty()) throw std::invalid_argument("give either --manifest FILE or --dir DIR");
  std::vector<Job> jobs = a.manifest.empty() ? readFolder(a.dir, a.glob) : readManifest(a.manifest, specs, d.cliName);
  // A manifest line's files (an error map's reference) are relative to the
  // manifest, as its meshes are (they were relative to the working folder).
  for (Job& j : jobs) {
    if (j.base.empty()) continue;
    Texts params = common;
    for (const auto& [n, t] : j.overrides) params[n] = t;
    for (const NamedFile& f : plannedFiles(d, params).reads)
      if (auto it = j.overrides.find(f.parameter); it != j.overrides.end() && !fs::path(it->second).is_absolute())
        it->second = (fs::path(j.base) / it->second).string();
  }
  // A filter that writes an image writes it at one path, which every mesh
  // would overwrite: refused where one is asked for; without it the meshes'
  // own results (the hemicube's form factors, the view's vertex values) are
  // baked (the filters were refused whatever their parameters).
  if (d.writes & WritesImage)
    for (const Job& j : jobs) {
      Texts params = common;
      for (const auto& [n, t] : j.overrides) params[n] = t;
      if (auto it = params.find("image_path"); it != params.end() && !it->second.empty())
        throw std::invalid_argument((j.overrides.count("image_path") ? j.where : std::string()) + "'" + d.cliName +
                                    "' writes its image at one path (image_path), which every mesh would overwrite: "
                                    "run it per mesh for images, or leave image_path empty");
    }
  std::map<std::string, std::string> byStem;
  for (Job& j : jobs) {
    j.stem = fs::path(j.input).stem().string();
    auto [it, fresh] = byStem.emplace(j.stem, j.input);
    if (!fresh)
      throw std::invalid_argument(it->second + " and " + j.input + " would both write " + j.stem +
                                  ".ply: give them different names");
  }
  const bool explicitShard = !a.shard.empty();
  const auto [shard, shards] = a.reportOnly && !explicitShard ? std::pair<size_t, size_t>{0, 1} : chooseShard(a.shard);
  std::error_code ec;
  fs::create_directories(a.outDir, ec);
  if (!fs::is_directory(a.outDir)) throw std::invalid_argument("cannot create the output folder " + a.outDir);
  checkFiles(a, d, common, jobs, shard, shards, explicitShard);
  int threads = a.threads;
  if (const char* slurm = std::getenv("SLURM_CPUS_PER_TASK"); threads == 0 && slurm) {
    // As --threads: 1 to 4096 (a larger figure is no machine's and a text is none).
    char* end = nullptr;
    const long n = std::strtol(slurm, &end, 10);
    if (end == slurm || *end != '\0' || n < 1 || n > 4096)
      throw std::invalid_argument(std::string("SLURM_CPUS_PER_TASK = '") + slurm + "' is not a thread count in [1, 4096]");
    threads = int(n);
  }
  std::unique_ptr<tbb::global_control> cap;
  if (threads > 0) cap = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));

  Timer timer;
  size_t meshes = 0, baked = 0, before = 0, failed = 0, missing = 0;
  double rays = 0, raysAll = 0, computeAll = 0;
  json failures = json::array();
  for (size_t k = shard; k < jobs.size(); k += shards) {
    const Job& job = jobs[k];
    ++meshes;
    Texts params = common;
    for (const auto& [n, v] : job.overrides) params[n] = v;
    const std::string hash = jobHash(d, params, job.input);
    const fs::path ply = fs::path(a.outDir) / (job.stem + ".ply"), sum = fs::path(a.outDir) / (job.stem + ".json");
    const json old = readJson(sum);
    // A summary's fields read only with the type they are written with (a
    // hand-edited one of other types counts as missing: recomputed).
    const auto text = [&](const char* field) {
      const auto it = old.is_object() ? old.find(field) : old.end();
      return it != old.end() && it->is_string() ? it->get<std::string>() : std::string();
    };
    const auto number = [&](const char* field) {
      const auto it = old.is_object() ? old.find(field) : old.end();
      return it != old.end() && it->is_number() && std::isfinite(it->get<double>()) && it->get<double>() >= 0
                 ? it->get<double>()
                 : 0.0;
    };
    const bool same = text("params_hash") == hash;
    const std::string tag = "[" + std::to_string(k + 1) + "/" + std::to_string(jobs.size()) + "] " + job.input + ": ";
    const json oldLayers = old.is_object() && old.contains("layers") ? old["layers"] : json();
    if (same && text("status") == "ok" && fs::exists(ply) && !text("output_digest").empty() &&
        text("output_digest") == outputDigest(ply, oldLayers)) {
      ++before;
      raysAll += number("rays");
      computeAll += number("seconds");
      if (!a.quiet && !a.reportOnly) std::cerr << tag << "done before\n";
      continue;
    }
    if (a.reportOnly) {
      if (same && text("status") == "failed") {
        ++failed;
        failures.push_back({{"input", job.input}, {"error", text("error")}});
      } else {
        ++missing;
      }
      continue;
    }
    json s;
    s["gi_batch"] = 1;
    s["input"] = job.input;
    s["filter"] = d.meshlabName;
    s["params_hash"] = hash;
    s["parameters"] = params;
    s["shard"] = std::to_string(shard) + "/" + std::to_string(shards);
    try {
      json r = bake(d, params, job, ply);
      s.update(r);
      s["status"] = "ok";
      s["output"] = ply.string();
      s["output_digest"] = outputDigest(ply, s.contains("layers") ? s["layers"] : json());
      ++baked;
      rays += r.value("rays", 0.0);
      raysAll += r.value("rays", 0.0);
      computeAll += r.value("seconds", 0.0);
      if (!a.quiet) std::cerr << tag << "baked in " << r.value("seconds", 0.0) << " s\n";
    } catch (const std::bad_alloc&) {
      s["status"] = "failed", s["error"] = "out of memory";
    } catch (const std::exception& e) {
      s["status"] = "failed", s["error"] = oneLine(e.what());
    }
    if (s["status"] == "failed") {
      ++failed;
      // An earlier run's result stays (a failed re-run deleted finished
      // results; an outside audit); the summary says it is not this run's
      // and keeps that run's summary, so its parameters stay known.
      if (fs::exists(ply, ec)) {
        s["earlier_result"] = ply.string() + " is not this run's result: it is kept from an earlier run";
        if (text("status") == "ok") s["earlier_run"] = old;
        else if (old.is_object() && old.contains("earlier_run")) s["earlier_run"] = old["earlier_run"];
        std::string e = s["error"].get<std::string>();
        if (!e.empty() && e.back() == '.') e.pop_back();
        s["error"] = e + " (the earlier result " + ply.filename().string() + " is kept)";
      }
      failures.push_back({{"input", job.input}, {"error", s["error"]}});
      if (!a.quiet) std::cerr << tag << "FAILED: " << s["error"].get<std::string>() << "\n";
    }
    writeJson(sum, s);
  }
  json rep;
  rep["filter"] = d.meshlabName;
  rep["shard"] = std::to_string(shard) + "/" + std::to_string(shards);
  rep["meshes"] = meshes;
  if (a.reportOnly) {
    rep["done"] = before, rep["failed"] = failed, rep["missing"] = missing;
  } else {
    rep["baked"] = baked, rep["done_before"] = before, rep["failed"] = failed;
    rep["rays"] = rays;
    rep["seconds"] = timer.seconds();
  }
  rep["failures"] = failures;
  rep["rays_all"] = raysAll;
  rep["compute_seconds_all"] = computeAll;
  const std::string name = reportName(a, shard, shards, explicitShard);
  writeJson(fs::path(a.outDir) / name, rep);
  if (a.json) std::cout << io::dumpJson(rep, 2) << std::endl;
  if (!a.quiet) {
    char b[300];
    if (a.reportOnly)
      std::snprintf(b, sizeof b, "gi batch: %zu meshes: %zu done, %zu failed, %zu missing; %.4g rays in %.4g s of computing",
                    meshes, before, failed, missing, raysAll, computeAll);
    else
      std::snprintf(b, sizeof b, "gi batch: %zu meshes (shard %zu/%zu): %zu baked, %zu done before, %zu failed; %.4g rays in %.4g s",
                    meshes, shard, shards, baked, before, failed, rays, timer.seconds());
    std::cerr << b << "\n";
    for (const json& f : failures) std::cerr << "  FAILED " << f["input"].get<std::string>() << ": " << f["error"].get<std::string>() << "\n";
    std::cerr << "wrote " << (fs::path(a.outDir) / name).string() << "\n";
  } else if (failed || missing) {  // quiet, but a failed run still says why it exits 1
    std::cerr << "gi: error: " << failed << " of " << meshes << " meshes failed"
              << (missing ? ", " + std::to_string(missing) + " missing" : std::string()) << " (see "
              << (fs::path(a.outDir) / name).string() << ")\n";
  }
  return failed || missing ? 1 : 0;
}

}  // namespace gi::batch
