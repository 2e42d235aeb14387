#include "gi_batch.h"
#include "gi_batch_inputs.h"

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
#include <regex>
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

namespace {

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
// parameter given, the input file (its name, size and the hash of its
// bytes) and the files the parameters name (an error map's reference: the
// same), which a copy keeping the time, or a rewrite within the file
// system's clock step, cannot hide (a reference computed anew was taken as
// done before, an outside audit; an input was compared by its size and
// time until a later one found an edited mesh of the same size, its time
// kept, taken as done). Hashing costs a read of each input (FNV-1a at
// 0.7 GB/s measured: 1.4 s a GB), beside the filter's own reading and work.
std::string jobHash(const FilterDesc& d, const Texts& params, const std::string& input) {
  std::ostringstream o;
  o << "gi " << programIdentity() << "\nfilter " << d.cliName << "\n";
  for (const auto& [k, v] : params) o << k << "=" << v << "\n";
  o << "input " << fs::path(input).filename().string() << " " << fileDigest(input) << "\n";
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

bool isBatchSummary(const json& j) { return j.is_object() && j.contains("gi_batch"); }

// Written whole or not at all: a file that exists is complete.
void writeJson(const fs::path& p, const json& j) { io::writeFileAtomically(p.string(), io::dumpJson(j, 2) + "\n"); }

// Whether a file stem is one reportName makes for some shard count.
bool isReportStem(const std::string& stem) {
  static const std::regex report("report(-only)?-[0-9]+-of-[0-9]+|report");
  return std::regex_match(stem, report);
}

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
  std::string inTheWay;  // the first file of the user's at a path the batch writes
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
    // A file at a result's or a summary's path is replaced only where a
    // batch wrote it: a summary of ours (a JSON object with "gi_batch") says
    // so for itself, its result and its layers. A file of the user's (an
    // a.ply beside a.obj where -o is the meshes' folder, a notes.json) is
    // refused before any work (it was overwritten; an outside audit).
    // (Said after the check against the inputs, whose message is clearer.)
    if (!isBatchSummary(readJson(summary)) && inTheWay.empty()) {
      std::error_code ec;
      std::vector<std::string> written{ply};
      for (const std::string& name : plan.layers) written.push_back(layerPath(ply, name));
      if (fs::exists(summary, ec)) inTheWay = summary + " is in the way: it is no summary of gi batch";
      for (const std::string& w : written)
        if (inTheWay.empty() && (fs::exists(w, ec) || fs::is_symlink(w, ec)))
          inTheWay = w + " is in the way: no summary of gi batch says a batch wrote it";
    }
    outputs.push_back({ply, "the result of " + j.input});
    outputs.push_back({summary, "the summary of " + j.input});
    for (const std::string& name : plan.layers) outputs.push_back({layerPath(ply, name), "a layer of " + j.input});
  }
  const fs::path report = fs::path(a.outDir) / reportName(a, shard, shards, explicitShard);
  outputs.push_back({report.string(), "the report"});
  files::check(inputs, outputs);
  const json old = readJson(report);  // the report likewise: one of ours holds "shard" and "meshes"
  std::error_code ec;
  if (inTheWay.empty() && fs::exists(report, ec) && !(old.is_object() && old.contains("shard") && old.contains("meshes")))
    inTheWay = report.string() + " is in the way: it is no report of gi batch";
  if (!inTheWay.empty()) throw std::invalid_argument(inTheWay + " (move it, or choose another --output-dir)");
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
                                      "array's task (SLURM_ARRAY_TASK_ID - MIN of COUNT) if set, else all")
      ->check([](const std::string& t) { return t.empty() ? std::string("expected I/N, e.g. 0/16, not an empty text") : ""; });
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
    // A summary named as a report of some shard count: refused whatever the
    // count (it clashed with the report only where the count made the same
    // name, so a collection run fine on one machine failed on a cluster).
    if (isReportStem(j.stem))
      throw std::invalid_argument(j.input + ": its summary would be " + j.stem +
                                  ".json, a name the batch's reports take (report.json, report-I-of-N.json, "
                                  "report-only-I-of-N.json): give the mesh another name");
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
    // An earlier run's result that this run may replace: its summary goes on
    // with this one's (a failed re-run keeps the result, and says whose).
    json earlier;
    if (fs::exists(ply, ec)) {
      if (text("status") == "ok") earlier = old;
      else if (old.is_object() && old.contains("earlier_run")) earlier = old["earlier_run"];
    }
    // The summary first, saying the mesh is being computed: every result
    // file in the folder then has a summary of ours beside it, even after a
    // kill between the two, and a file without one is the user's (checkFiles).
    {
      json running = s;
      running["status"] = "running";
      if (!earlier.is_null()) running["earlier_run"] = earlier;
      writeJson(sum, running);
    }
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
        if (!earlier.is_null()) s["earlier_run"] = earlier;
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
