// The tool's global operator new: large blocks are advised for transparent
// huge pages (gi/huge_pages.h) before anything touches them, so every large
// array of a run (the scene, the hierarchy's nodes and links, the gather's
// tables) is backed by 2 MiB pages where the system allows. A replacement
// of operator new is the program's to make, so the tool makes it; the
// MeshLab plugins run inside MeshLab's process and leave its allocator as
// it is. Deletion is the standard library's (free). GI_NO_HUGEPAGES=1 in
// the environment turns it off (to measure what it gains).
#include <algorithm>
#include <cstdlib>
#include <new>

#include "gi/huge_pages.h"

// The sanitizers pair their own operator new with their operator delete
// (a malloc'd block given to their delete is an error): tools/CMakeLists.txt
// leaves this file out of a GI_SANITIZE build, and the test below keeps it
// out of any other sanitized one (GCC's macros, Clang's __has_feature).
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define GI_HUGE_NEW 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define GI_HUGE_NEW 0
#endif
#endif
#ifndef GI_HUGE_NEW
#define GI_HUGE_NEW 1
#endif

#if GI_HUGE_NEW

#if defined(__GLIBC__)
#include <malloc.h>
namespace {
// glibc serves blocks below its mmap threshold from the heap, whose pages
// an earlier block may already have touched (too late for the advice), and
// raises that threshold up to 32 MB as large blocks are freed. A fixed
// threshold at the advised size gives every advised block fresh pages.
[[maybe_unused]] const int kFixedMmapThreshold =
    gi::hugePagesSwitchedOff() ? 0 : mallopt(M_MMAP_THRESHOLD, int(gi::kHugePageMinBytes));
}  // namespace
#endif

namespace {
// malloc (align 0) or posix_memalign, the new_handler loop of the standard,
// then the advice for a large block.
void* allocate(std::size_t n, std::size_t align) {
  if (n == 0) n = 1;
  for (;;) {
    void* p = nullptr;
    if (align == 0 ? (p = std::malloc(n)) != nullptr : posix_memalign(&p, align, n) == 0) {
      if (n >= gi::kHugePageMinBytes) gi::adviseHugePages(p, n);  // most blocks are small: no call
      return p;
    }
    const std::new_handler h = std::get_new_handler();
    if (!h) throw std::bad_alloc();
    h();
  }
}
}  // namespace

void* operator new(std::size_t n) { return allocate(n, 0); }
void* operator new[](std::size_t n) { return allocate(n, 0); }
void* operator new(std::size_t n, std::align_val_t al) {
  return allocate(n, std::max(sizeof(void*), std::size_t(al)));
}
void* operator new[](std::size_t n, std::align_val_t al) {
  return allocate(n, std::max(sizeof(void*), std::size_t(al)));
}

#endif
