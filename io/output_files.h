// The files one run reads and writes, checked before anything is computed
// (README, "Command-line tool"): every output can be created (its folder
// exists and takes a new file), and no output is the same file as an input
// or as another output, however it is named (in.ply, ./in.ply,
// ../dir/in.ply, a symbolic or a hard link). Every subcommand of `gi` and
// every MeshLab filter checks its files here; each output is then written
// whole or not at all (io/atomic_file.h).
#pragma once
#include <string>
#include <vector>

#include "gi/filter_files.h"

namespace gi::files {

// A file and the option that named it ("--output", "--layer"; empty for the input).
struct Named {
  std::string path;
  std::string what;
};

// Throws std::invalid_argument with one sentence if `out` cannot be written:
// an empty name, a folder, a folder that does not exist or takes no new file,
// a new file's name or path longer than the folder takes, or an existing file
// that is not writable.
void checkWritable(const Named& out);

// checkWritable for each output, then the sentence "the output X (-o) would
// overwrite the input Y" for the first output that is the same file as an
// input or an earlier output. Inputs that do not exist are left to their
// readers.
void check(const std::vector<Named>& inputs, const std::vector<Named>& outputs);

// The whole text of a file the run reads besides its meshes (a manifest, a
// parameter file, a cached result, an OBJ's material library). Throws
// std::invalid_argument "the WHAT PATH ...: WHY" (one sentence) where it is
// missing, a folder, not a regular file (a pipe or a device would block or
// never end) or larger than maxBytes.
std::string readTextFile(const std::string& path, const std::string& what, size_t maxBytes = size_t(1) << 30);

// The writer of gi::writeOutputFiles that writes each file whole or not at all.
FileWriter atomicWriter();

}  // namespace gi::files
