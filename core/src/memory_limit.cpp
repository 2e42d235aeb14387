// Memory available to a run (gi/memory_limit.h).
#include "gi/memory_limit.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

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

// A number from a cgroup v2 file of this process's group, or -1 ("max",
// missing, v1).
long long cgroupValue(const char* file) {
  std::ifstream self("/proc/self/cgroup");
  std::string line, path;
  while (std::getline(self, line))
    if (line.compare(0, 3, "0::") == 0) path = line.substr(3);  // v2: "0::/the/group"
  if (path.empty()) return -1;
  std::ifstream f("/sys/fs/cgroup" + path + "/" + file);
  std::string v;
  if (!(f >> v) || v == "max") return -1;
  try {
    return std::stoll(v);
  } catch (...) {
    return -1;
  }
}

std::string gigabytes(double bytes) {
  char b[32];
  std::snprintf(b, sizeof b, bytes < 10e9 ? "%.1f" : "%.0f", bytes / 1e9);
  return b;
}

}  // namespace

size_t availableMemoryBytes() {
  const long long kb = meminfoKB("MemAvailable");
  double avail = kb >= 0 ? double(kb) * 1024.0 : 0.0;
  const long long max = cgroupValue("memory.max"), cur = cgroupValue("memory.current");
  if (max >= 0 && cur >= 0) {
    const double left = max > cur ? double(max - cur) : 1.0;
    avail = avail > 0 ? std::min(avail, left) : left;
  }
  return size_t(avail);
}

size_t memoryLimitOrAvailable(size_t limit) { return limit != 0 ? limit : availableMemoryBytes(); }

void requireMemory(double bytes, size_t limit, const std::string& what, const std::string& remedy) {
  if (limit == 0 || !(bytes > double(limit))) return;
  throw std::invalid_argument(what + " needs about " + gigabytes(bytes) + " GB, more than the " +
                              gigabytes(double(limit)) + " GB of memory available; " + remedy);
}

}  // namespace gi
