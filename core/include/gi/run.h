// What every algorithm shares: progress reporting with cancellation, a log
// summary of what was computed, and block-parallel loops that report progress
// from the calling thread only (MeshLab's callback is not thread-safe).
#pragma once
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace gi {

// Returns false to ask for cancellation.
using ProgressFn = std::function<bool(int percent, const std::string& stage)>;

struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("cancelled by the user") {}
};

struct RunStats {
  std::vector<std::pair<std::string, double>> numbers;  // in insertion order
  std::vector<std::string> notes;                        // what was skipped and why, etc.
  // A parameter or a scene that makes the result unreliable (not converged,
  // a gather radius below the photon spacing, ...): shown first in the log
  // line as "WARNING: ..." and listed apart in the CLI's JSON.
  std::vector<std::string> warnings;
  void add(const std::string& key, double v) { numbers.emplace_back(key, v); }
  void set(const std::string& key, double v);  // replaces key's value (or adds it)
  void note(const std::string& s) { notes.push_back(s); }
  void warn(const std::string& s) { warnings.push_back(s); }
  double get(const std::string& key, double fallback = 0.0) const;
  std::string line(const std::string& title) const;  // "title: k=v, ...; notes"
};

class Progress {
 public:
  explicit Progress(ProgressFn fn, int from = 0, int to = 100) : fn_(std::move(fn)), from_(from), to_(to) {}
  // Reports fraction f in [0,1] of this stage; throws Cancelled if asked to stop.
  void report(double f, const std::string& stage) const;
  Progress sub(double f0, double f1) const;  // a sub-range of this one

 private:
  ProgressFn fn_;
  int from_, to_;
};

// Runs body(begin, end) over [0, n) in parallel (oneTBB), in about `blocks`
// sequential slices, reporting progress between slices from this thread.
void parallelBlocks(size_t n, const Progress& progress, const std::string& stage,
                    const std::function<void(size_t, size_t)>& body, size_t blocks = 64);

// Wall-clock seconds since construction.
class Timer {
 public:
  Timer();
  double seconds() const;
 private:
  double t0_;
};

// The time a run still needs, extrapolated from its overall progress: the
// elapsed time t times (100 - p) / p at p percent. Stages of unequal cost
// per percent make it a rough guide, so it is rounded (roughDuration) and
// said only once the run has taken a few seconds and done 1% of its work.
// The front ends append it to the stage they show.
class TimeLeft {
 public:
  // clock: seconds from any origin (tests pass their own); default: wall clock.
  explicit TimeLeft(std::function<double()> clock = {});
  // "about 3 min left", or "" while no estimate is worth showing.
  std::string text(int percent) const;

 private:
  std::function<double()> clock_;
  double t0_;
};

// A duration as a person reads it: "45 s" (to 5 s), "12 min", "2 h 5 min"
// (to 5 min beyond an hour).
std::string roughDuration(double seconds);

}  // namespace gi
