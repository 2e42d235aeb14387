// gi batch's inputs: the meshes of a manifest or a folder, the parameter
// file, the shard this process takes (tools/gi_batch.h says what a batch is).
#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "gi/filters.h"

namespace gi::batch {

using Texts = std::map<std::string, std::string>;  // parameter name -> value as the CLI takes it

struct Job {
  std::string input;  // path
  Texts overrides;    // this manifest line's parameters
  std::string where;  // "manifest line 7" (for messages)
  std::string stem;   // output name: OUT/stem.ply, OUT/stem.json
  std::string base;   // the manifest's folder: files its line's parameters name are relative to it
};

// One line: a message's line breaks as spaces (a report lists one reason a mesh).
std::string oneLine(std::string s);

// "--name value" and "--name=value" pairs of w from `from` on, each name one
// of the filter's parameters, none twice; `where` prefixes each message.
Texts parameterPairs(const std::vector<std::string>& w, size_t from, const std::vector<ParamSpec>& specs,
                     const std::string& filter, const std::string& where);

// {"filter": name or "", "parameters": {name: value as the CLI takes it}}.
std::pair<std::string, Texts> readParamsFile(const std::string& path);

// The filter named by its CLI or MeshLab name; throws naming the choices.
const FilterDesc& findFilter(const std::string& name);

// One job a line of the manifest (its paths relative to the manifest).
std::vector<Job> readManifest(const std::string& path, const std::vector<ParamSpec>& specs, const std::string& filter);

// One job per file of dir whose name matches the pattern (names starting
// with a dot only where the pattern starts with one, as a shell's).
std::vector<Job> readFolder(const std::string& dir, const std::string& pattern);

// (I, N) from --shard "I/N", else a Slurm job array's task, else (0, 1).
std::pair<size_t, size_t> chooseShard(const std::string& text);

}  // namespace gi::batch
