// The files a filter reads and writes besides the meshes a front end hands
// it: a reference PLY a parameter names, the images and text files its
// parameters ask for, the new layers it adds. A front end learns them from
// the parameters alone, before it computes, so that it can refuse an output
// that cannot be written or that would overwrite an input before the work
// starts (README, "Command-line tool"); and it writes them through its own
// writer (the command-line tool: to a temporary beside each file, renamed
// over it once complete).
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "gi/filter_run.h"

namespace gi {

// A file and the parameter that names it ("image_path", "reference_file").
struct NamedFile {
  std::string path;
  std::string parameter;
};

struct FilterFiles {
  std::vector<NamedFile> reads;    // besides the meshes of the scene
  std::vector<NamedFile> writes;   // every file writeOutputFiles may write for such a result
  std::vector<std::string> layers;  // names of the new layers the result may hold (FilterResult::layers)
};

// What a run of `kind` with the values `v` may read and write. A run writes
// no file outside `writes` (it may write fewer: radiosity exports its system
// only when the form-factor matrix is in memory).
FilterFiles filterFiles(FilterKind kind, const ParamValues& v);

// Where an image's linear values go: beside its PNG, the same name with .pfm.
std::string pfmPath(const std::string& imagePath);
// "dir/name.png" -> "dir/name" (a name without an extension stays whole):
// the stem the pictures beside an image are named from.
std::string imageStem(const std::string& imagePath);

// A file name's extension in lower case with its dot ("x.PLY" -> ".ply"),
// or "" where the name has none.
std::string lowerExtension(const std::string& path);
// A path-traced view's standard error per pixel goes beside its image.
std::string stdErrorImagePath(const std::string& imagePath);

// Writes the file `path` by calling `write` with the path to write to; a
// front end's writer may hand it a temporary and move that into place.
using FileWriter = std::function<void(const std::string& path, const std::function<void(const std::string& to)>& write)>;
// writeOutputFiles (gi/filter_run.h) through `writer` (empty: straight to each path).
void writeOutputFiles(const FilterResult& r, const FileWriter& writer);

}  // namespace gi
