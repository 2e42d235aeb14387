// gi: the engine on mesh files. One subcommand per filter, with the same
// parameter names, defaults and validation as the MeshLab dialogs (both come
// from gi::filterSpecs), plus `script` to write complete .mlx files.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <tbb/global_control.h>

#include "gi/filter_files.h"
#include "gi/filter_run.h"
#include "gi/filters.h"
#include "gi/refine.h"
#include "gi/scene_setup.h"
#include "atomic_file.h"
#include "gi_batch.h"
#include "gi_cluster.h"
#include "gi_course.h"
#include "output_files.h"
#include "gi_output.h"
#include "json_text.h"
#include "mesh_io.h"
#include "result_file.h"
#include "vertex_file.h"

using namespace gi;
using json = nlohmann::json;

namespace {

struct CommonArgs {
  std::string input, output, mesh, cacheDir, saveResult;
  std::vector<std::string> layers;  // more files forming one scene with the input
  bool json = false, quiet = false;
  int threads = 0;
  std::map<std::string, std::string> raw;  // parameter texts as given
  cluster::SplitOptions split;             // under mpirun
};

ProgressFn stderrProgress(bool quiet) {
  if (quiet) return nullptr;
  const bool tty = isatty(fileno(stderr));
  auto last = std::make_shared<int>(-1);
  auto lastStage = std::make_shared<std::string>();
  auto timeLeft = std::make_shared<TimeLeft>();
  return [tty, last, lastStage, timeLeft](int pct, const std::string& stage) {
    if (pct == *last && stage == *lastStage) return true;
    const std::string left = timeLeft->text(pct);
    if (tty) {
      const int w = 30, fill = pct * w / 100;
      std::fprintf(stderr, "\r[%.*s%*s] %3d%% %-28s %-22s", fill, "##############################", w - fill, "", pct,
                   stage.c_str(), left.c_str());
      if (pct >= 100) std::fputc('\n', stderr);
    } else if (pct / 10 != *last / 10 || stage != *lastStage) {
      std::fprintf(stderr, "%3d%% %s%s\n", pct, stage.c_str(), left.empty() ? "" : (" (" + left + ")").c_str());
    }
    *last = pct;
    *lastStage = stage;
    return true;
  };
}

json statsJson(const RunStats& s) {
  json j = json::object();
  for (const auto& [k, v] : s.numbers) j[k] = v;
  return j;
}

json valuesJson(const std::vector<ParamSpec>& specs, const ParamValues& v) {
  json j = json::object();
  for (const auto& p : specs) {
    if (!v.has(p.name)) continue;
    switch (p.type) {
      case ParamType::Bool: j[p.name] = v.getBool(p.name); break;
      case ParamType::Int: j[p.name] = v.getInt(p.name); break;
      case ParamType::Enum: j[p.name] = p.choices.at(size_t(v.getInt(p.name))); break;
      case ParamType::Float:
      case ParamType::Distance: j[p.name] = v.getFloat(p.name); break;
      case ParamType::Color:
      case ParamType::Direction: {
        const glm::vec3 c = v.getVec(p.name);
        j[p.name] = {c.x, c.y, c.z};
        break;
      }
      case ParamType::Point: {
        const glm::dvec3 c = v.getPoint(p.name);
        j[p.name] = {c.x, c.y, c.z};
        break;
      }
      case ParamType::String: j[p.name] = v.getString(p.name); break;
    }
  }
  return j;
}

std::string defaultText(const ParamSpec& p) {
  char b[96];
  switch (p.type) {
    case ParamType::Bool: return p.def != 0 ? "true" : "false";
    case ParamType::Int: std::snprintf(b, sizeof b, "%d", int(p.def)); return b;
    case ParamType::Float: std::snprintf(b, sizeof b, "%g", p.def); return b;
    case ParamType::Distance: std::snprintf(b, sizeof b, "%g%%", p.def * 100); return b;
    case ParamType::Enum: return p.choices.at(size_t(p.def));
    case ParamType::Color:
      std::snprintf(b, sizeof b, "%d,%d,%d", int(p.defVec.r * 255 + .5f), int(p.defVec.g * 255 + .5f), int(p.defVec.b * 255 + .5f));
      return b;
    case ParamType::Direction:
    case ParamType::Point: std::snprintf(b, sizeof b, "%g,%g,%g", p.defVec.x, p.defVec.y, p.defVec.z); return b;
    case ParamType::String: return "'" + p.defText + "'";
  }
  return "";
}

void addParamOptions(CLI::App* sub, const std::vector<ParamSpec>& specs, CommonArgs& a, bool includeMeshlabOnly) {
  for (const auto& p : specs) {
    if (p.meshlabOnly && !includeMeshlabOnly) continue;
    const std::string range = rangeText(p), used = usedWhenText(specs, p, false);
    std::string help = p.label + ". " + p.help + " [default: " + defaultText(p) + (range.empty() ? "" : "; " + range) +
                       (used.empty() ? "" : "; " + used) + "]";
    if (p.type == ParamType::Enum) {
      help += " {";
      for (size_t i = 0; i < p.choices.size(); ++i) help += (i ? ", " : "") + p.choices[i];
      help += "}";
    }
    auto* opt = sub->add_option_function<std::string>(
        "--" + p.name, [&a, name = p.name](const std::string& t) { a.raw[name] = t; }, help);
    opt->type_name(p.type == ParamType::Distance ? "LEN|PCT%" : p.type == ParamType::Bool ? "BOOL" : p.type == ParamType::String ? "TEXT" : "VALUE");
  }
}

ParamValues resolve(const std::vector<ParamSpec>& specs, const CommonArgs& a, double diag) {
  ParamValues v = defaultValues(specs, diag);
  for (const auto& [name, text] : a.raw) v.set(name, parseValue(*findSpec(specs, name), text, diag));
  if (auto err = validate(specs, v, diag)) throw std::invalid_argument(*err);
  return v;
}

// The files a run reads and writes, as its parameters name them (gi/filter_files.h).
struct RunFiles {
  std::vector<files::Named> inputs, outputs;
};

RunFiles runFiles(FilterKind kind, const CommonArgs& a, const ParamValues& v) {
  RunFiles f;
  f.inputs.push_back({a.input, ""});
  for (const std::string& l : a.layers) f.inputs.push_back({l, "--layer"});
  const FilterFiles plan = filterFiles(kind, v);
  for (const NamedFile& r : plan.reads) f.inputs.push_back({r.path, "--" + r.parameter});
  if (!a.output.empty()) {
    f.outputs.push_back({a.output, "--output"});
    for (const std::string& name : plan.layers) f.outputs.push_back({layerPath(a.output, name), "the layer " + name + " beside --output"});
  }
  if (!a.saveResult.empty()) f.outputs.push_back({a.saveResult, "--save-result"});
  for (const NamedFile& w : plan.writes) f.outputs.push_back({w.path, "--" + w.parameter});
  return f;
}

// What a computed result writes: the PLY, its new layers, the saved result,
// the files and images its parameters asked for.
std::vector<files::Named> resultOutputs(const CommonArgs& a, const FilterResult& r) {
  std::vector<files::Named> out;
  if (!a.output.empty()) {
    out.push_back({a.output, "--output"});
    for (const FilterLayer& L : r.layers) out.push_back({layerPath(a.output, L.name), "the layer " + L.name + " beside --output"});
  }
  if (!a.saveResult.empty()) out.push_back({a.saveResult, "--save-result"});
  for (const FilterFile& f : r.files) out.push_back({f.path, "a file the parameters name"});
  for (const FilterImage& img : r.images)
    if (!img.path.empty()) {
      out.push_back({img.path, "an image the parameters name"});
      out.push_back({pfmPath(img.path), "an image the parameters name"});
    }
  return out;
}

// The values runFiles needs before the mesh is loaded (strings, choices,
// switches): a text that does not parse keeps its default here, and resolve
// reports it once the mesh is loaded.
ParamValues valuesBeforeLoading(const std::vector<ParamSpec>& specs, const CommonArgs& a) {
  ParamValues v = defaultValues(specs, 1.0);
  for (const auto& [name, text] : a.raw) {
    try {
      v.set(name, parseValue(*findSpec(specs, name), text, 1.0));
    } catch (const std::invalid_argument&) {
    }
  }
  return v;
}

// Loads the input (and --layer files) as one scene, runs the filter through
// gi::runFilter (or reuses a cached result of the same prepared scene and
// parameters), writes the PLY and prints the log or the JSON summary.
int runCommand(FilterKind kind, const CommonArgs& a) {
  const auto specs = filterSpecs(kind);
  const FilterDesc& desc = filterDesc(kind);
  std::unique_ptr<tbb::global_control> threads;
  if (a.threads > 0) threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(a.threads));
  Timer timer;
  // The output is PLY whatever its name says: a name promising another
  // format (x.obj, or none) is refused before any work.
  if (!a.output.empty() && lowerExtension(a.output) != ".ply")
    throw std::invalid_argument("--output '" + a.output + "': gi writes PLY (vertex colour, quality and the layers' names, "
                                "which OBJ, OFF and STL cannot hold); give a name ending in .ply");
  std::optional<RunFiles> early;  // every file, before the mesh is loaded
  try {
    early = runFiles(kind, a, valuesBeforeLoading(specs, a));
  } catch (const std::exception&) {  // a value filterFiles cannot use: resolve reports it
  }
  if (early) files::check(early->inputs, early->outputs);
  io::LoadedMesh mesh = io::loadMesh(a.input);
  // Layers as in MeshLab: named by file name, for the mirror/glass patterns.
  auto baseName = [](const std::string& p) { const size_t k = p.find_last_of('/'); return k == std::string::npos ? p : p.substr(k + 1); };
  // A PLY this tool wrote from several layers records them: they come back.
  FilterInput in;
  in.layers = io::meshLayers(mesh, baseName(a.input));
  for (const std::string& file : a.layers) {
    const io::LoadedMesh part = io::loadMesh(file);
    for (const LayerRange& l : io::meshLayers(part, baseName(file), mesh.scene.faceCount())) in.layers.push_back(l);
    io::appendMesh(mesh, part, io::Reframing::Deferred);
  }
  if (!a.layers.empty()) io::reframe(mesh);
  const std::vector<glm::vec3> fileNormals = std::move(mesh.scene.vertexNormals);  // written back unchanged
  mesh.scene.vertexNormals.clear();
  in.values = resolve(specs, a, sceneDiagonal(mesh.scene));
  RunFiles planned = runFiles(kind, a, in.values);
  files::check(planned.inputs, planned.outputs);
  const std::vector<files::Named> inputs = planned.inputs;
  in.scene = std::move(mesh.scene);
  in.attrs = mesh.attrs;
  in.attributes = std::move(mesh.attributes);  // what an earlier run left (PLY properties), e.g. a first pass
  in.readVertexFile = io::readVertexFile;       // a reference file a parameter names

  const bool writer = cluster::rank() == 0;  // under mpirun only rank 0 writes and prints
  const Progress progress(stderrProgress(a.quiet || !writer));
  if (cluster::size() > 1 && !a.cacheDir.empty()) throw std::invalid_argument("--cache is for a run in one process, not under mpirun");
  FilterResult r = prepareFilter(kind, in);
  // The scene's hash only where a result file records it (a pass over every byte of the mesh).
  const bool keyed = !a.cacheDir.empty() || !a.saveResult.empty();
  // The program's identity with the parameters: a result of another build is not reused.
  const io::ResultKey key{desc.cliName, a.input, keyed ? sceneHash(in.scene) : 0,
                          "program=" + programIdentity() + " " + describe(specs, in.values)};
  const std::string cached = a.cacheDir.empty() ? "" : io::resultCachePath(a.cacheDir, key);
  bool reused = false;
  std::error_code noFile;
  std::string damaged;
  if (!cached.empty() && std::filesystem::exists(cached, noFile)) {
    FilterResult stored = r;
    io::ResultKey k;
    // A damaged cache file is computed again (and rewritten); one that is
    // not a regular file (a pipe, a device) stops the run, as before.
    const bool regular = std::filesystem::is_regular_file(cached, noFile);
    try {
      k = io::readResultFile(cached, stored);
    } catch (const std::runtime_error& e) {
      if (!regular) throw;
      damaged = e.what();
    }
    // The text files a result rewrites are those its parameters name, and
    // no others (a cache file is not trusted to choose where to write).
    const FilterFiles plan = filterFiles(kind, in.values);
    const bool filesNamed = std::all_of(stored.files.begin(), stored.files.end(), [&](const FilterFile& f) {
      return std::any_of(plan.writes.begin(), plan.writes.end(), [&](const NamedFile& w) { return w.path == f.path; });
    });
    const size_t nf = in.scene.faceCount();
    reused = damaged.empty() && k.filter == key.filter && k.sceneHash == key.sceneHash &&
             k.parameters == key.parameters && stored.vertexQuality.size() == in.scene.vertexCount() &&
             (stored.faceQuality.empty() || stored.faceQuality.size() == nf) &&
             (stored.faceColor.empty() || stored.faceColor.size() == nf) && filesNamed;
    if (reused) {
      r = std::move(stored);
      r.stats.note("reused the cached result " + cached);
    }
  }
  if (!reused && !cached.empty() && writer) {  // the cache file is written after the computation: check it now
    planned.outputs.push_back({cached, "--cache"});
    files::check(inputs, planned.outputs);
  }
  if (!reused) {
    cluster::compute(kind, in, r, progress, a.split);
    if (!writer) return 0;
    if (!damaged.empty()) r.stats.warn("the cached result could not be used, so it was computed again: " + damaged);
  }
  for (const std::string& w : mesh.warnings) r.stats.warn(w);
  // A cached result holds no geometry and no image (a view written as an
  // image would be computed again every time, each run saying "cached as":
  // an outside audit); such a run says so instead.
  const bool caching = !reused && !cached.empty() && !r.refined && r.layers.empty() && r.images.empty();
  if (!reused && !cached.empty() && !caching)
    r.stats.note(std::string("not cached: the cache keeps per-vertex and per-face results, not ") +
                 (!r.images.empty() ? "images" : r.refined ? "refined meshes" : "new layers"));
  // The files the result names, checked as the plan was before anything is written.
  std::vector<files::Named> outputs = resultOutputs(a, r);
  if (caching) outputs.push_back({cached, "--cache"});
  files::check(inputs, outputs);
  // Every output or none: each file is held back until all are written.
  io::OutputTransaction written;
  if (!a.saveResult.empty()) io::writeResultFile(a.saveResult, key, r);

  std::vector<std::string> layerFiles;
  if (!a.output.empty()) {
    writeResultPly(a.output, in.scene, mesh.attrs, fileNormals, r, in.layers, in.attributes, mesh.points);
    layerFiles = writeLayerPlys(a.output, r);
  } else if (!r.layers.empty()) {
    r.stats.note("the new layers are written only beside an output (-o)");
  }
  writeOutputFiles(r, files::atomicWriter());
  written.commit();
  // The cache last, and optional: a cache that cannot take the result (a
  // full disk) warns and loses nothing else (it threw away a 22 s reference
  // before its output was written; an outside audit).
  if (caching) {
    try {
      io::writeResultFile(cached, key, r);
      r.stats.note("cached as " + cached);
    } catch (const std::exception& e) {
      r.stats.warn(std::string("the result was not cached: ") + e.what());
    }
  }
  r.stats.add("total_seconds", timer.seconds());
  const auto lines = r.logLines(desc.meshlabName);
  if (a.json) {
    const SceneReport& rep = r.report;
    json j;
    j["filter"] = desc.meshlabName;
    j["input"] = a.input;
    if (!a.output.empty()) j["output"] = a.output;
    if (!layerFiles.empty()) j["layers"] = layerFiles;
    j["parameters"] = valuesJson(specs, in.values);
    j["scene"] = {{"vertices", rep.vertices}, {"faces", rep.faces}, {"usable_faces", rep.usableFaces()},
                  {"degenerate_faces", rep.degenerateFaces}, {"invalid_faces", rep.invalidFaces},
                  {"nonfinite_vertices", rep.nonFiniteVertices}, {"isolated_vertices", rep.isolatedVertices},
                  {"duplicated_faces_left_out", rep.leftOutFaces}, {"misoriented_edges", rep.misorientedEdges},
                  {"emitter_faces", rep.emitterFaces}, {"diagonal", rep.diagonal}};
    j["stats"] = statsJson(r.stats);
    j["notes"] = r.stats.notes;
    j["warnings"] = r.stats.warnings;
    if (!r.setupLog.empty()) j["setup"] = r.setupLog;
    j["log"] = lines;
    if (const json m = cluster::report(); !m.is_null()) j["mpi"] = m;
    std::cout << io::dumpJson(j, 2) << std::endl;
  } else if (!a.quiet) {
    for (const std::string& l : lines) std::cerr << l << "\n";
    if (!a.output.empty()) std::cerr << "wrote " << a.output << "\n";
    for (const std::string& f : layerFiles) std::cerr << "wrote " << f << " (a new layer)\n";
    for (const FilterImage& img : r.images)
      if (!img.path.empty()) std::cerr << "wrote " << img.path << " (and .pfm)\n";
  }
  return 0;
}

int listFilters(bool asJson) {
  json all = json::array();
  for (const FilterDesc& d : allFilters()) {
    if (!asJson) {
      std::printf("%-12s '%s' (%s): %s\n", d.cliName.c_str(), d.meshlabName.c_str(), d.plugin.c_str(), d.summary.c_str());
      continue;
    }
    json params = json::array();
    const std::vector<ParamSpec> specs = filterSpecs(d.kind);
    for (const ParamSpec& p : specs)
      params.push_back({{"name", p.name}, {"label", p.label}, {"default", defaultText(p)}, {"range", rangeText(p)},
                        {"used_when", usedWhenText(specs, p, false)}, {"meshlab_only", p.meshlabOnly}});
    json writes = json::array();
    const std::pair<unsigned, const char*> bits[] = {
        {WritesVertexQuality, "vertex_quality"}, {WritesVertexColor, "vertex_color"}, {WritesVertexNormal, "vertex_normal"},
        {WritesFaceQuality, "face_quality"},     {WritesFaceColor, "face_color"},     {WritesGeometry, "geometry"},
        {WritesImage, "image"},                  {WritesLayer, "layer"}};
    for (const auto& [bit, name] : bits)
      if (d.writes & bit) writes.push_back(name);
    all.push_back({{"cli", d.cliName}, {"meshlab", d.meshlabName}, {"plugin", d.plugin}, {"summary", d.summary},
                   {"writes", writes}, {"parameters", params}});
  }
  if (asJson) std::cout << io::dumpJson(all, 2) << std::endl;
  return 0;
}

// MeshLab reads a script's numbers in single precision (docs/design.md,
// "Precision of parameters"): a number beyond the largest float would be
// written as inf. Each Float and Distance value, each distance's range (its
// maximum fraction of the diagonal) and each Point's coordinates must be
// finite as a float.
void checkSinglePrecision(const std::vector<ParamSpec>& specs, const ParamValues& v, double diag, const std::string& mesh) {
  const double largest = std::numeric_limits<float>::max();
  for (const ParamSpec& p : specs) {
    if (p.type == ParamType::Point) {  // written as three floats: 1e39 was written as inf (an outside audit)
      const glm::dvec3 q = v.getPoint(p.name);
      const double x = std::max({std::fabs(q.x), std::fabs(q.y), std::fabs(q.z)});
      if (x > largest) {
        char b[64];
        std::snprintf(b, sizeof b, "%g", x);
        throw std::invalid_argument("cannot write --" + p.name + " into the script: a coordinate is " + b +
                                    ", beyond the largest single-precision number (3.4e+38) that MeshLab reads");
      }
      continue;
    }
    if (p.type != ParamType::Float && p.type != ParamType::Distance) continue;
    const double x = std::fabs(v.getFloat(p.name));
    const double range = p.type == ParamType::Distance ? (p.max > 0 ? p.max : 1.0) * diag : 0.0;
    if (x <= largest && range <= largest) continue;
    auto num = [](double y) {
      char b[32];
      std::snprintf(b, sizeof b, "%g", y);
      return std::string(b);
    };
    throw std::invalid_argument("cannot write --" + p.name + " into the script: " +
                                (x > largest ? "its value is " + num(x) : "its range reaches " + num(range)) +
                                ", beyond the largest single-precision number (3.4e+38) that MeshLab reads (the "
                                "bounding-box diagonal" + (mesh.empty() ? "" : " of " + mesh) + " is " + num(diag) + ")");
  }
}

int writeScript(const std::vector<FilterKind>& kinds, const CommonArgs& a) {
  const bool toFile = !a.output.empty() && a.output != "-";
  if (toFile) files::check({{a.mesh, "--mesh"}}, {{a.output, "--output"}});
  double diag = 1.0;
  if (!a.mesh.empty()) {
    diag = sceneDiagonal(io::loadMesh(a.mesh).scene);
  } else {
    // A script stores absolute values: a share of a diagonal nobody gave
    // would be written for a diagonal of 1 (10% became 0.1 mm on a box of
    // 960 mm; an outside audit).
    for (FilterKind k : kinds)
      for (const auto& p : filterSpecs(k))
        if (const auto it = a.raw.find(p.name);
            p.type == ParamType::Distance && it != a.raw.end() && !it->second.empty() && it->second.back() == '%')
          throw std::invalid_argument("--" + p.name + " " + it->second +
                                      ": a share of the mesh's diagonal needs --mesh FILE (the script stores "
                                      "absolute values)");
    for (FilterKind k : kinds)
      for (const auto& p : filterSpecs(k))
        if (p.type == ParamType::Distance && p.def > 0 && !a.raw.count(p.name))
          std::fprintf(stderr, "gi: note: --%s defaults to %g%% of a bounding-box diagonal of 1; pass --mesh FILE to scale it to your mesh\n",
                       p.name.c_str(), p.def * 100);
  }
  std::vector<ScriptStep> steps;
  for (FilterKind k : kinds) {
    steps.push_back({k, resolve(filterSpecs(k), a, diag)});
    checkSinglePrecision(filterSpecs(k), steps.back().values, diag, a.mesh);
    // An XML script is UTF-8: other bytes (a Latin-1 file name) made a file
    // no XML reader takes, and meshlabserver read another name (an outside
    // audit). The filters themselves take such names as bytes.
    for (const ParamSpec& p : filterSpecs(k)) {
      if (p.type != ParamType::String) continue;
      try {
        (void)json(steps.back().values.getString(p.name)).dump();
      } catch (const json::exception&) {
        throw std::invalid_argument("cannot write --" + p.name +
                                    " into the script: its text is not UTF-8 (MeshLab reads scripts as UTF-8); "
                                    "rename the file or layer, or run the filter with gi itself");
      }
    }
  }
  const std::string text = mlxScript(steps, diag);
  if (toFile) io::writeFileAtomically(a.output, text);
  else std::cout << text;
  return 0;
}

// The error contract: one line on stderr, exit status 1, for every bad input
// or parameter (CLI11's own parse errors included).
int failOneLine(std::string what) {
  for (char& c : what)
    if (c == '\n' || c == '\r') c = ' ';
  while (!what.empty() && what.back() == ' ') what.pop_back();
  std::fprintf(stderr, "gi: error: %s\n", what.c_str());
  return 1;
}

int runCli(int argc, char** argv) {
  CLI::App app{"gi: global illumination on meshes (ambient occlusion, sky lighting, radiosity, photon mapping).\n"
               "Reads PLY/OBJ/OFF/STL, writes PLY with per-vertex colour and quality."};
  app.require_subcommand(1);
  CommonArgs a;
  std::map<CLI::App*, FilterKind> subs;
  std::vector<std::pair<CLI::Option*, std::string*>> outputs;  // file options to check before any work
  for (const FilterDesc& d : allFilters()) {
    CLI::App* sub = app.add_subcommand(d.cliName, "'" + d.meshlabName + "': " + d.summary);
    sub->add_option("input", a.input, "input mesh (PLY/OBJ/OFF/STL)")->required();
    outputs.push_back({sub->add_option("-o,--output", a.output, "output PLY with vertex colour and quality (all layers in one file, which records their names and faces: a later run reads them as layers again); a filter's new layers (e.g. "
                                                  "photonmap --photon_layer) go beside it as OUT.NAME.ply (OUT.Photons.ply), "
                                                  "listed under \"layers\" in --json"),
                       &a.output});
    sub->add_option("--layer", a.layers, "another mesh file in the same scene, like a visible layer in MeshLab "
                                         "(repeatable; its file name is its layer name)");
    sub->add_flag("--json", a.json, "print a machine-readable summary on stdout");
    sub->add_flag("-q,--quiet", a.quiet, "no progress bar or log on stderr");
    sub->add_option("--threads", a.threads, "worker threads (default: all cores); results do not depend on it")
        ->check(CLI::Range(1, 4096));
    addParamOptions(sub, filterSpecs(d.kind), a, false);
    sub->add_option_function<std::string>(
           "--split", [&a](const std::string& m) { a.split.interleaved = m == "interleaved"; },
           "under mpirun: which vertices each rank computes, chunks dealt round robin or one run of chunks per "
           "rank [default: interleaved]")
        ->check(CLI::IsMember({"interleaved", "contiguous"}));
    sub->add_option("--chunk", a.split.chunk, "under mpirun: vertices per chunk of the split [default: 1024]")
        ->check(CLI::Range(1, 1 << 30));
    sub->add_option("--cache", a.cacheDir, "folder of cached results: reuse one computed with the same scene and "
                                           "parameters, or store the new one there (e.g. a slow reference)");
    outputs.push_back({sub->add_option("--save-result", a.saveResult, "also write the whole result as JSON (quality, "
                                                                      "colours, attributes such as Radiosity, StdError, "
                                                                      "Paths; statistics)"),
                       &a.saveResult});
    subs[sub] = d.kind;
  }
  CLI::App* script = app.add_subcommand("script", "write a complete .mlx script for meshlabserver (every parameter, in dialog order)");
  std::string filterName;
  script->add_option("filter", filterName, "filter subcommand name (" + cliFilterNames() + ")")->required();
  CLI::Option* scriptOutput = script->add_option("-o,--output", a.output, "output .mlx (default: stdout)");
  script->add_option("--mesh", a.mesh, "mesh whose bounding box scales distance defaults");
  script->allow_extras();
  CLI::App* list = app.add_subcommand("filters", "list the filters (the catalogue MeshLab's plugins and this tool share)");
  list->add_flag("--json", a.json, "as JSON: names, plugin, description, what each writes, parameters");
  CLI::App* batch = app.add_subcommand("batch", "one filter over many meshes (a manifest, or a folder and a pattern): "
                                                "resumable, one result and summary per mesh, --shard I/N for cluster "
                                                "jobs; the filter's parameters follow as --name value (gi FILTER "
                                                "--help lists them)");
  batch::Args batchArgs;
  batch::addOptions(batch, batchArgs);
  course::TableArgs tableArgs;
  CLI::App* table = course::addFormFactorTable(app, tableArgs);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return cluster::rank() == 0 ? app.exit(e) : 0;  // --help: the help text, exit 0
    // A first word that is no subcommand: say which (CLI11 says only that one is required).
    if (argc > 1 && argv[1][0] != '-' && app.get_subcommands([&](CLI::App* c) { return c->check_name(argv[1]); }).empty()) {
      std::string names;
      for (const CLI::App* c : app.get_subcommands([](CLI::App*) { return true; }))
        names += (names.empty() ? "" : ", ") + c->get_name();
      return cluster::abandon() ? failOneLine(std::string("unknown subcommand '") + argv[1] + "' (" + names + ")") : 1;
    }
    return cluster::abandon() ? failOneLine(e.what()) : 1;
  }
  try {
    for (const auto& [opt, path] : outputs)  // an empty name given is refused here; runCommand checks the rest
      if (opt->count() > 0) files::checkWritable({*path, opt->get_name()});
    if (scriptOutput->count() > 0 && a.output != "-") files::checkWritable({a.output, "--output"});
    for (auto& [sub, kind] : subs)
      if (sub->parsed()) return runCommand(kind, a);
    if (list->parsed()) return listFilters(a.json);
    if (batch->parsed()) return batch::run(batchArgs, batch->remaining());
    if (table->parsed()) return course::formFactorTable(tableArgs);
    if (script->parsed()) {
      const FilterDesc* d = findFilter(filterName);
      if (!d) throw std::invalid_argument("unknown filter '" + filterName + "' (" + cliFilterNames() + ")");
      // Parameters after the filter name: --name value pairs, checked against the filter's table.
      const auto specs = filterSpecs(d->kind);
      const auto extras = script->remaining();
      for (size_t i = 0; i < extras.size(); ++i) {
        std::string k = extras[i];
        if (k.rfind("--", 0) != 0) throw std::invalid_argument("unexpected argument '" + k + "'");
        k = k.substr(2);
        std::string val;
        const size_t eq = k.find('=');
        if (eq != std::string::npos) { val = k.substr(eq + 1); k = k.substr(0, eq); }
        else if (i + 1 < extras.size()) val = extras[++i];
        else throw std::invalid_argument("--" + k + " needs a value");
        if (!findSpec(specs, k)) throw std::invalid_argument("'" + d->cliName + "' has no parameter --" + k);
        if (a.raw.count(k)) throw std::invalid_argument("--" + k + " is given twice");
        a.raw[k] = val;
      }
      return writeScript({d->kind}, a);
    }
  } catch (const cluster::Quiet&) {
    return 1;  // another rank failed and said why
  } catch (const std::bad_alloc&) {
    return cluster::abandon() ? failOneLine("out of memory") : 1;
  } catch (const std::exception& e) {
    return cluster::abandon() ? failOneLine(e.what()) : 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  io::removeTemporariesOnSignals();
  cluster::start(&argc, &argv);
  int status = runCli(argc, argv);
  cluster::stop();
  // What went to standard output (--json, gi script, gi filters) must have
  // arrived: a full disk or a closed pipe is an error, not exit 0 over an
  // empty or cut-off file (an outside audit: `gi script render > f.mlx` on a
  // full disk left 4,096 of 4,163 bytes and exit 0).
  std::cout.flush();
  errno = 0;
  if (std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout) {
    std::fprintf(stderr, "gi: error: cannot write to standard output: %s\n",
                 errno ? std::strerror(errno) : "write error");
    if (status == 0) status = 1;
  }
  return status;
}
