// Transparent huge pages for the large arrays of a run.
// A ray's way through a BVH of a million triangles, a link's reads of its
// two nodes and a gather hit's read of its face each land on a page the
// processor has likely not translated recently: with 4 KiB pages a table of
// 16 MB spans 4,096 of them, more than the translation cache holds, so most
// such reads also walk the page table. Backed by 2 MiB pages the same table
// spans 8 (Linux: madvise(MADV_HUGEPAGE), honoured where the system's
// transparent huge pages are set to "always" or "madvise", the default of
// most distributions). Measured on the 1M-triangle scan room at 96 gather
// rays and 6M links (README, five runs each way): the whole run 53.5 ->
// 46.7 s (medians), the same bits; at the defaults one pair showed no
// difference in time, and the peak memory fell by a quarter.
#pragma once
#include <cstddef>

namespace gi {

// Blocks at least this large are advised. Smaller than a huge page: large
// blocks get mappings of their own, placed side by side, and neighbouring
// mappings with the same advice merge into one area that huge pages can
// span (on the 1M room 256 KiB gained more than 2 MiB, within the noise).
inline constexpr std::size_t kHugePageMinBytes = std::size_t(256) << 10;

// Whether GI_NO_HUGEPAGES is set in the environment: then nothing is
// advised (to measure what the advice gains). Read on every call.
bool hugePagesSwitchedOff();

// While one lives, nothing is advised, in the whole process (they nest).
// For a phase that writes large arrays once and then reads them in order
// or near where it last read: the kernel zeroes a 2 MiB page at its first
// touch, which on the machine of the measurements cost 2.7 to 4.2 times as
// much per byte as 4 KiB pages (512 MB written once: 0.28 to 0.29 s against
// 0.78 to 1.22 s), and such reads gain little from fewer translations
// (the shared AO estimator's pooling on a 1.9M-vertex scan, README: 3.4 ->
// 2.7 s).
class HugePageAdvicePause {
 public:
  HugePageAdvicePause();
  ~HugePageAdvicePause();
  HugePageAdvicePause(const HugePageAdvicePause&) = delete;
  HugePageAdvicePause& operator=(const HugePageAdvicePause&) = delete;
};

// Asks the kernel to back the whole pages of [p, p + bytes) with huge
// pages as they are first touched. Best effort: a no-op off Linux, where
// the system forbids it, below kHugePageMinBytes, when switched off or
// while a HugePageAdvicePause lives.
// Never changes the memory's contents.
void adviseHugePages(void* p, std::size_t bytes);

// Whether the kernel was asked to back the page holding p with huge pages
// (the "hg" flag of its mapping in /proc/self/smaps; false off Linux). For
// tests.
bool hugePagesAdvised(const void* p);

}  // namespace gi
