// gi batch: one filter over a collection of meshes, listed in a manifest
// (one mesh a line, with that line's parameter overrides) or found in a
// folder by a file-name pattern. Each result is written next to its own
// name in the output folder (NAME.ply) with a summary (NAME.json) carrying
// the hash of everything that decides the result (filter, parameters, the
// input's name and the hash of its bytes). A rerun skips every mesh whose PLY and
// summary exist with the same hash, so a batch killed half-way loses
// nothing it had finished; a mesh that fails is reported and the others go
// on. `--shard I/N` (or a Slurm job array's task id and count) takes every
// N-th mesh, so that N processes on a cluster share the collection without
// a scheduler of our own. README, "Beyond one machine".
#pragma once
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace gi::batch {

struct Args {
  std::string filter;     // CLI name (ao, sky, ...), or taken from the parameter file
  std::string manifest;   // file: one mesh a line
  std::string dir, glob = "*.ply";
  std::string outDir;
  std::string paramsFile;  // JSON: {"filter": ..., "parameters": {name: value}}
  std::string shard;       // "I/N"
  int threads = 0;
  bool json = false, quiet = false, reportOnly = false;
};

// The subcommand's options (gi_cli.cpp adds the subcommand itself).
void addOptions(CLI::App* sub, Args& a);

// Runs the batch; `extras` are the filter's parameters (--name value).
// Returns the exit status: 0 when every mesh of the shard has its result,
// 1 when some failed (each named with its reason in the report). Throws
// std::invalid_argument for an unusable manifest, folder or option.
int run(const Args& a, const std::vector<std::string>& extras);

}  // namespace gi::batch
