#include "gi/run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gi {

void RunStats::set(const std::string& key, double v) {
  for (auto& kv : numbers)
    if (kv.first == key) {
      kv.second = v;
      return;
    }
  add(key, v);
}

double RunStats::get(const std::string& key, double fallback) const {
  for (const auto& kv : numbers)
    if (kv.first == key) return kv.second;
  return fallback;
}

std::string RunStats::line(const std::string& title) const {
  std::string s = title + ":";
  char buf[96];
  bool first = true;
  for (const auto& kv : numbers) {
    std::snprintf(buf, sizeof buf, "%s %s=%.6g", first ? "" : ",", kv.first.c_str(), kv.second);
    s += buf;
    first = false;
  }
  for (const auto& w : warnings) s += "; WARNING: " + w;
  for (const auto& n : notes) s += "; " + n;
  return s;
}

void Progress::report(double f, const std::string& stage) const {
  if (!fn_) return;
  f = std::fmin(1.0, std::fmax(0.0, f));
  int pct = from_ + int(std::lround(f * (to_ - from_)));
  if (!fn_(pct, stage)) throw Cancelled();
}

Progress Progress::sub(double f0, double f1) const {
  int a = from_ + int(std::lround(f0 * (to_ - from_)));
  int b = from_ + int(std::lround(f1 * (to_ - from_)));
  return Progress(fn_, a, b);
}

void parallelBlocks(size_t n, const Progress& progress, const std::string& stage,
                    const std::function<void(size_t, size_t)>& body, size_t blocks) {
  if (n == 0) return;
  // Slices of at least 256 elements: each slice ends in a barrier, and small
  // slices leave threads idle while the last task finishes.
  blocks = std::max<size_t>(1, std::min(blocks, n / 256));
  const size_t step = (n + blocks - 1) / blocks;
  progress.report(0.0, stage);
  for (size_t b0 = 0; b0 < n; b0 += step) {
    const size_t b1 = std::min(n, b0 + step);
    tbb::parallel_for(tbb::blocked_range<size_t>(b0, b1, 1),
                      [&](const tbb::blocked_range<size_t>& r) { body(r.begin(), r.end()); });
    progress.report(double(b1) / double(n), stage);
  }
}

Timer::Timer() : t0_(std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count()) {}
double Timer::seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count() - t0_;
}

TimeLeft::TimeLeft(std::function<double()> clock) : clock_(std::move(clock)) {
  if (!clock_) {
    auto t = std::make_shared<Timer>();
    clock_ = [t] { return t->seconds(); };
  }
  t0_ = clock_();
}

std::string TimeLeft::text(int percent) const {
  constexpr double kQuietSeconds = 5.0;
  const double t = clock_() - t0_;
  if (percent < 1 || percent >= 100 || !(t >= kQuietSeconds)) return "";
  return "about " + roughDuration(t * double(100 - percent) / double(percent)) + " left";
}

std::string roughDuration(double seconds) {
  if (!(seconds < 1e9)) return "a very long time";
  if (seconds < 57.5) return std::to_string(std::max(1L, std::lround(seconds / 5.0)) * 5) + " s";
  if (seconds < 3600 - 30) return std::to_string(std::max(1L, std::lround(seconds / 60.0))) + " min";
  const long minutes = std::lround(seconds / 300.0) * 5;
  const long h = minutes / 60, m = minutes % 60;
  return std::to_string(h) + " h" + (m ? " " + std::to_string(m) + " min" : "");
}

}  // namespace gi
