// Output files written whole or not at all: the bytes go to a temporary file
// beside the target, which is flushed, synced and checked, then renamed over
// the target; on any failure the temporary is removed and the target keeps
// what it held (README, "Command-line tool": a failed write never leaves a
// partial file in place of a good one).
#pragma once
#include <functional>
#include <string>
#include <string_view>

namespace gi::io {

// Writes `path` by calling `write` with the temporary to fill (a file that
// exists, empty, with the target's permissions). Throws std::runtime_error
// "cannot write PATH: WHY" naming `path`, not the temporary. A target that
// is a symbolic link is written where the link points; one that exists and
// is not a regular file (/dev/null, a pipe) is written in place.
void writeAtomically(const std::string& path, const std::function<void(const std::string& temp)>& write);
void writeFileAtomically(const std::string& path, std::string_view bytes);

// The outputs of one run as one change: while one is open, every file
// writeAtomically writes is held back as its synced temporary, and commit()
// renames them all into place; destroyed without commit (the run failed on
// a later file: a full disk), it removes them and no target has changed. A
// run whose image failed to write left its new PLY over the old one and a
// PNG without its PFM (an outside audit). One at a time, in one thread.
class OutputTransaction {
 public:
  OutputTransaction();
  ~OutputTransaction();
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  // Throws std::runtime_error "cannot write PATH: WHY" if a rename fails
  // (the temporaries not yet renamed are removed).
  void commit();
};

// Why a file cannot be created beside `path` (the strerror text; empty: it
// can): a temporary there is created and removed, which also finds a folder
// that refuses new files to root (/proc) or a read-only file system.
std::string cannotCreateBeside(const std::string& path);

// `path` followed through symbolic links (the file a write lands in).
std::string linkTarget(const std::string& path);

// For a program (the CLI): SIGINT, SIGTERM and SIGHUP remove the temporaries
// being written, then end the process as the signal would. Interrupted
// while writing its output, `gi` left hidden partial files (a 38 MB PLY's
// first 4-6 MB) that no later run removed (an outside audit).
void removeTemporariesOnSignals();

}  // namespace gi::io
