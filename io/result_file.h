// A filter's result on disk (JSON): every per-vertex and per-face array, the
// named attributes and the statistics, keyed by the filter, the scene's hash
// (after the conventions: geometry and materials) and the parameters. The
// command-line tool caches results with it (`--cache DIR`: an expensive run,
// such as a 1% path-traced reference, is computed once and reused by the
// benchmarks) and saves them (`--save-result FILE`).
#pragma once
#include <cstdint>
#include <string>

#include "gi/filter_run.h"

namespace gi::io {

struct ResultKey {
  std::string filter;      // CLI name of the filter
  std::string mesh;        // source file name, informative
  uint64_t sceneHash = 0;  // gi::sceneHash of the prepared scene
  std::string parameters;  // gi::describe(...) of every parameter
};

// Written whole or not at all (atomic_file.h); bytes of names that are not
// UTF-8 become U+FFFD (json_text.h).
void writeResultFile(const std::string& path, const ResultKey& key, const FilterResult& r);
// Reads the arrays, attributes and statistics into r (which keeps its scene
// report and set-up log) and returns the file's key. Throws
// std::runtime_error naming the file if it is missing or malformed.
ResultKey readResultFile(const std::string& path, FilterResult& r);
// "<dir>/<mesh stem>-<filter>-<16 hex of the scene hash>-<8 hex of the parameters>.giresult.json"
std::string resultCachePath(const std::string& dir, const ResultKey& key);

}  // namespace gi::io
