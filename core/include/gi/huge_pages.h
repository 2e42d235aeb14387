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

// Asks the kernel to back the whole pages of [p, p + bytes) with huge
// pages as they are first touched. Best effort: a no-op off Linux, where
// the system forbids it, below kHugePageMinBytes or when switched off.
// Never changes the memory's contents.
void adviseHugePages(void* p, std::size_t bytes);

// Whether the kernel was asked to back the page holding p with huge pages
// (the "hg" flag of its mapping in /proc/self/smaps; false off Linux). For
// tests.
bool hugePagesAdvised(const void* p);

}  // namespace gi
