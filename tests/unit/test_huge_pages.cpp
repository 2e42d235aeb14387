// Transparent huge pages (gi/huge_pages.h): the advice reaches the kernel
// for large blocks only, not when switched off, and never touches the
// contents. The project builds on Linux only, where /proc/self/smaps shows
// each mapping's advice.
#include <gtest/gtest.h>
#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <vector>

#include "gi/huge_pages.h"

namespace {

// A mapping of its own, so that no other block shares its flags.
struct Mapping {
  explicit Mapping(size_t n) : bytes(n) {
    void* m = mmap(nullptr, n, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    p = m == MAP_FAILED ? nullptr : static_cast<uint8_t*>(m);
  }
  ~Mapping() {
    if (p) munmap(p, bytes);
  }
  size_t bytes;
  uint8_t* p = nullptr;
};

}  // namespace

TEST(HugePages, LargeBlocksAreAdvisedSmallOnesNot) {
  ASSERT_TRUE(std::ifstream("/proc/self/smaps").good());
  unsetenv("GI_NO_HUGEPAGES");  // whatever the test's environment says
  const size_t big = size_t(8) << 20;
  Mapping a(big), b(gi::kHugePageMinBytes / 2);
  ASSERT_NE(a.p, nullptr);
  ASSERT_NE(b.p, nullptr);
  EXPECT_FALSE(gi::hugePagesAdvised(a.p));
  // Advised from an unaligned start: the whole pages inside are.
  gi::adviseHugePages(a.p + 100, big - 100);
  EXPECT_TRUE(gi::hugePagesAdvised(a.p + big / 2));
  EXPECT_TRUE(gi::hugePagesAdvised(a.p + big - 1));
  EXPECT_FALSE(gi::hugePagesAdvised(a.p)) << "the partial first page is left alone";
  gi::adviseHugePages(b.p, b.bytes);
  EXPECT_FALSE(gi::hugePagesAdvised(b.p)) << "below kHugePageMinBytes nothing is advised";
}

TEST(HugePages, SwitchedOffAdvisesNothing) {
  ASSERT_TRUE(std::ifstream("/proc/self/smaps").good());
  const size_t big = size_t(8) << 20;
  Mapping a(big);
  ASSERT_NE(a.p, nullptr);
  setenv("GI_NO_HUGEPAGES", "1", 1);
  EXPECT_TRUE(gi::hugePagesSwitchedOff());
  gi::adviseHugePages(a.p, big);
  unsetenv("GI_NO_HUGEPAGES");
  EXPECT_FALSE(gi::hugePagesAdvised(a.p + big / 2));
  EXPECT_FALSE(gi::hugePagesSwitchedOff());
}

TEST(HugePages, NothingIsAdvisedWhileAPauseLives) {
  ASSERT_TRUE(std::ifstream("/proc/self/smaps").good());
  unsetenv("GI_NO_HUGEPAGES");
  const size_t big = size_t(8) << 20;
  Mapping a(big), b(big), c(big);
  ASSERT_NE(a.p, nullptr);
  ASSERT_NE(b.p, nullptr);
  ASSERT_NE(c.p, nullptr);
  {
    const gi::HugePageAdvicePause outer;
    {
      const gi::HugePageAdvicePause inner;
      gi::adviseHugePages(a.p, big);
    }
    gi::adviseHugePages(b.p, big);  // the outer pause still lives
  }
  gi::adviseHugePages(c.p, big);
  EXPECT_FALSE(gi::hugePagesAdvised(a.p + big / 2));
  EXPECT_FALSE(gi::hugePagesAdvised(b.p + big / 2));
  EXPECT_TRUE(gi::hugePagesAdvised(c.p + big / 2)) << "advice resumes when the last pause ends";
}

TEST(HugePages, AdviceKeepsTheContents) {
  std::vector<uint32_t> v(size_t(4) << 20);
  for (size_t i = 0; i < v.size(); ++i) v[i] = uint32_t(i * 2654435761u);
  gi::adviseHugePages(v.data(), v.size() * sizeof(uint32_t));
  size_t wrong = 0;
  for (size_t i = 0; i < v.size(); ++i) wrong += v[i] != uint32_t(i * 2654435761u);
  EXPECT_EQ(wrong, 0u);
  gi::adviseHugePages(nullptr, size_t(1) << 30);  // nothing to advise: no effect, no crash
}
