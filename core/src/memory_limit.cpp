// Memory available to a run (gi/memory_limit.h).
#include "gi/memory_limit.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <cstdlib>
#include <string>

#include <sys/resource.h>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

namespace gi {

namespace {

// The first number after `key` in /proc/meminfo (kB), or -1.
long long meminfoKB(const char* key) {
  std::ifstream f("/proc/meminfo");
  std::string line;
  const std::string k = std::string(key) + ":";
  while (std::getline(f, line))
    if (line.compare(0, k.size(), k) == 0) {
      std::istringstream in(line.substr(k.size()));
      long long v = -1;
      in >> v;
      return v;
    }
  return -1;
}

// The first number in a file, or -1 (missing, "max", not a number).
long long fileNumber(const std::string& path) {
  std::ifstream f(path);
  std::string v;
  if (!(f >> v) || v == "max") return -1;
  try {
    return std::stoll(v);
  } catch (...) {
    return -1;
  }
}

// The value of `key` in a memory.stat file, or 0.
long long statValue(const std::string& path, const std::string& key) {
  std::ifstream f(path);
  std::string k;
  long long v = 0;
  while (f >> k >> v)
    if (k == key) return v;
  return 0;
}

// What a memory control group still allows: its limit less what it holds
// that the kernel cannot reclaim (its usage counts the file cache, which a
// group that has read or written files fills up to its limit; the inactive
// part is reclaimed first). -1 without a limit there.
double groupRoom(const std::string& dir, const char* limitFile, const char* usageFile, const char* inactiveKey) {
  const long long limit = fileNumber(dir + "/" + limitFile);
  if (limit < 0 || limit >= (1LL << 60)) return -1;  // v1 writes "no limit" as a huge number
  const long long usage = fileNumber(dir + "/" + usageFile);
  if (usage < 0) return -1;
  const double held = std::max(0.0, double(usage) - double(statValue(dir + "/memory.stat", inactiveKey)));
  return std::max(0.0, double(limit) - held);
}

// The least room over this process's memory control group and its parents
// (cgroup v2: a container's or a job's limit is often set on a parent), or
// the v1 memory controller's group; -1 without any limit.
double cgroupRoom() {
  std::ifstream self("/proc/self/cgroup");
  std::string line, v2, v1;
  while (std::getline(self, line)) {
    if (line.compare(0, 3, "0::") == 0) v2 = line.substr(3);
    const size_t m = line.find(":memory:");
    if (m != std::string::npos) v1 = line.substr(m + 8);
  }
  double room = -1;
  auto least = [&room](double r) {
    if (r >= 0 && (room < 0 || r < room)) room = r;
  };
  if (!v1.empty()) {
    // Inside a container the group's path may not be mounted: its root is.
    const std::string base = "/sys/fs/cgroup/memory";
    const std::string dir = std::ifstream(base + v1 + "/memory.limit_in_bytes").good() ? base + v1 : base;
    least(groupRoom(dir, "memory.limit_in_bytes", "memory.usage_in_bytes", "total_inactive_file"));
  } else if (!v2.empty()) {
    for (std::string path = v2;; path = path.substr(0, path.rfind('/'))) {
      least(groupRoom("/sys/fs/cgroup" + path, "memory.max", "memory.current", "inactive_file"));
      if (path.empty() || path == "/") break;
      if (path.rfind('/') == 0) path = "/";  // the next round reads the root
    }
  }
  return room;
}

}  // namespace

// "6.4 GB", "12 GB", "75 MB", "74 KB".
std::string memoryAmount(double bytes) {
  char b[32];
  if (bytes >= 1e9) std::snprintf(b, sizeof b, bytes < 10e9 ? "%.1f GB" : "%.0f GB", bytes / 1e9);
  else if (bytes >= 1e6) std::snprintf(b, sizeof b, "%.0f MB", bytes / 1e6);
  else std::snprintf(b, sizeof b, "%.0f KB", bytes / 1e3);
  return b;
}

namespace {
std::atomic<int> g_share{1};
}  // namespace

void shareMemoryWith(int processes) { g_share = std::max(processes, 1); }
int memoryShare() { return g_share; }

int workerThreads() {
  return std::max(1, int(std::min<size_t>(size_t(tbb::this_task_arena::max_concurrency()),
                                          tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism))));
}

namespace {

// glibc's malloc arenas of threads other than the first grow by reserving
// 64 MB of address space at a time.
constexpr double kArenaBytes = 64.0 * 1048576.0;

// What the address-space limit (ulimit -v, RLIMIT_AS) leaves this process
// beyond what it maps now (VmSize), or -1 where there is none. Past it an
// allocation fails with std::bad_alloc: "out of memory" without the need
// and the parameter to lower (an outside audit, under ulimit -v).
double addressSpaceRoom() {
  rlimit r{};
  if (getrlimit(RLIMIT_AS, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return -1;
  std::ifstream f("/proc/self/status");
  std::string line;
  double mapped = 0, threads = 1;
  while (std::getline(f, line)) {
    if (line.rfind("VmSize:", 0) == 0) mapped = 1024.0 * std::atof(line.c_str() + 7);
    if (line.rfind("Threads:", 0) == 0) threads = std::atof(line.c_str() + 8);
  }
  // What the address space the worker threads take grows by beyond what
  // they hold: glibc gives each its own malloc arena, which grows by
  // reserving 64 MB at a time, so up to 64 MB a worker are mapped and not
  // yet used; a worker the run has still to start maps its stack too. On 2
  // cores the worker's next 64 MB took the room a photon map had been
  // allowed (13 million photons checked against 746 MB, then "out of
  // memory"; an outside audit). Counted for the workers the threads
  // allowed (--threads) may use.
  const double allowed = double(workerThreads());
  const double stack = double(tbb::global_control::active_value(tbb::global_control::thread_stack_size));
  const double workers = std::max(0.0, allowed - 1.0), toStart = std::max(0.0, allowed - threads);
  return std::max(0.0, double(r.rlim_cur) - mapped - workers * kArenaBytes - toStart * stack);
}

}  // namespace

size_t availableMemoryBytes() {
  const long long kb = meminfoKB("MemAvailable");
  double avail = kb >= 0 ? double(kb) * 1024.0 : 0.0;
  const double room = cgroupRoom();
  if (room >= 0) avail = avail > 0 ? std::min(avail, room) : room;
  const double space = addressSpaceRoom();
  if (space >= 0) avail = avail > 0 ? std::min(avail, space) : space;
  if (!(avail > 0) && (room >= 0 || space >= 0)) return 1;  // known, and none left (0 means unknown)
  return avail > 0 ? size_t(std::max(avail / double(g_share.load()), 1.0)) : 0;
}

size_t memoryLimitOrAvailable(size_t limit) { return limit != 0 ? limit : availableMemoryBytes(); }

void requireMemory(double bytes, size_t limit, const std::string& what, const std::string& remedy) {
  if (limit == 0 || !(bytes > double(limit))) return;
  throw std::invalid_argument(what + " needs about " + memoryAmount(bytes) + ", more than the " + memoryAmount(double(limit)) +
                              " of memory available; " + remedy);
}

}  // namespace gi
