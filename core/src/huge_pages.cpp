// Transparent huge pages for large blocks (gi/huge_pages.h).
#include "gi/huge_pages.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace gi {

namespace {
std::atomic<int> pauses{0};  // HugePageAdvicePause objects alive
}  // namespace

HugePageAdvicePause::HugePageAdvicePause() { pauses.fetch_add(1, std::memory_order_relaxed); }
HugePageAdvicePause::~HugePageAdvicePause() { pauses.fetch_sub(1, std::memory_order_relaxed); }

bool hugePagesSwitchedOff() { return std::getenv("GI_NO_HUGEPAGES") != nullptr; }

void adviseHugePages(void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (!p || bytes < kHugePageMinBytes || pauses.load(std::memory_order_relaxed) > 0 || hugePagesSwitchedOff()) return;
  static const std::uintptr_t page = std::uintptr_t(std::max(4096L, sysconf(_SC_PAGESIZE)));
  const std::uintptr_t a = (reinterpret_cast<std::uintptr_t>(p) + page - 1) & ~(page - 1);
  const std::uintptr_t b = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(page - 1);
  if (b > a) madvise(reinterpret_cast<void*>(a), b - a, MADV_HUGEPAGE);  // advice only: its failure changes nothing
#else
  (void)p;
  (void)bytes;
#endif
}

bool hugePagesAdvised(const void* p) {
#if defined(__linux__)
  std::FILE* f = std::fopen("/proc/self/smaps", "r");
  if (!f) return false;
  const auto x = reinterpret_cast<std::uintptr_t>(p);
  char line[512];
  bool inside = false, advised = false;
  while (std::fgets(line, sizeof line, f)) {
    unsigned long lo, hi;
    if (std::sscanf(line, "%lx-%lx ", &lo, &hi) == 2) {  // a mapping's first line (field lines start with a name)
      inside = x >= lo && x < hi;
      continue;
    }
    if (inside && std::strncmp(line, "VmFlags:", 8) == 0) {
      advised = std::strstr(line, " hg") != nullptr;
      break;
    }
  }
  std::fclose(f);
  return advised;
#else
  (void)p;
  return false;
#endif
}

}  // namespace gi
