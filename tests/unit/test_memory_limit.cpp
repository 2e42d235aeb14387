// Runs whose memory the parameters set are refused, in one sentence, when
// they would not fit (gi/memory_limit.h): an image's pixels before anything
// is traced, the photons of a map once they pass the limit (the global map,
// each progressive pass, the caustic projection), and a radiosity budget
// above the memory available is lowered to it. A caller's own limit
// stands in for the machine's, which this machine's 24 GB would not reach
// at the tables' largest settings.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "filter_input.h"
#include "gi/memory_limit.h"
#include "gi/photon.h"
#include "gi/render.h"
#include "gi/scenes.h"

#include <sys/resource.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

using namespace gi;

namespace {

// The exception's text, or "" if `f` returned.
template <class F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

// The machine's figure is the kernel's MemAvailable (or less, in a control
// group): above zero and below MemTotal.
TEST(MemoryLimit, AvailableIsTheKernelsFigure) {
  std::ifstream f("/proc/meminfo");
  std::string key;
  double total = 0, kb = 0;
  while (f >> key >> kb) {
    if (key == "MemTotal:") total = kb * 1024.0;
    f.ignore(64, '\n');
  }
  ASSERT_GT(total, 0.0);
  const double avail = double(availableMemoryBytes());
  EXPECT_GT(avail, 16e6);
  EXPECT_LE(avail, total);
  EXPECT_EQ(memoryLimitOrAvailable(12345), 12345u);
}

// Under an address-space limit (ulimit -v) the room a run is told it has
// is there when it uses it, though its worker threads allocate too: each
// has its own malloc arena, which grows by reserving 64 MB of address space
// at a time, so a worker holding N bytes may map up to N + 64 MB (on 2
// cores a photon map checked against the room without that ended in "out
// of memory" at the worker's next 64 MB; an outside audit). Here workers
// hold photon-block-sized pieces, and the rest of the room is then taken in
// one allocation, for several amounts held (the arena's unused part varies
// with them).
TEST(MemoryLimit, AddressSpaceRoomHoldsWhileTheWorkersAllocate) {
  // Two threads whatever the machine has (one worker, even on one core);
  // under AddressSanitizer too (its shadow is mapped already: in VmSize).
  tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
  tbb::task_arena arena(2);
  std::ifstream f("/proc/self/status");
  std::string line;
  double mapped = 0;
  while (std::getline(f, line))
    if (line.rfind("VmSize:", 0) == 0) mapped = 1024.0 * std::atof(line.c_str() + 7);
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_AS, &old), 0);
  const double room = 1.5e9;
  if (old.rlim_max != RLIM_INFINITY && double(old.rlim_max) < mapped + room) GTEST_SKIP() << "a hard limit below the test's";
  rlimit lim = old;
  lim.rlim_cur = rlim_t(mapped + room);
  for (const size_t pieces : {1500u, 2400u, 3300u}) {  // of 64 KB: 98, 157 and 216 MB
    ASSERT_EQ(setrlimit(RLIMIT_AS, &lim), 0);
    size_t avail = 0;
    arena.execute([&] { avail = availableMemoryBytes(); });
    std::vector<void*> held(pieces, nullptr);
    arena.execute([&] {
      tbb::parallel_for(size_t(0), pieces, [&](size_t i) {
        if (tbb::this_task_arena::current_thread_index() > 0) held[i] = std::malloc(65536);  // the worker only
        const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(20);
        while (std::chrono::steady_clock::now() < until) {
        }
      });
    });
    size_t bytes = 0;
    for (void* p : held) bytes += p ? 65536 : 0;
    const size_t rest = avail > bytes + (16u << 20) ? avail - bytes - (16u << 20) : 0;
    void* all = std::malloc(rest);
    const bool fits = all != nullptr;
    std::free(all);
    for (void* p : held) std::free(p);
    setrlimit(RLIMIT_AS, &old);
    EXPECT_GT(bytes, 0u) << "no worker allocated";
    EXPECT_GT(double(avail), 0.5 * room);
    EXPECT_TRUE(fits) << double(avail) / 1e6 << " MB reported, " << double(bytes) / 1e6 << " MB held by workers";
  }
}

// Ranks of one run on one machine (gi_cluster_mpi.cpp tells their count)
// each see their share: a quarter for 4, within the kernel's figure moving
// between the reads (5%); the radiosity budget lowered to it says so.
TEST(MemoryLimit, RanksOnOneMachineShareIt) {
  const double whole = double(availableMemoryBytes());
  shareMemoryWith(4);
  const double quarter = double(availableMemoryBytes());
  shareMemoryWith(1);
  EXPECT_NEAR(quarter * 4.0, whole, 0.05 * whole);
  shareMemoryWith(0);  // not a count: one process
  EXPECT_EQ(memoryShare(), 1);

  const auto sf = scenes::cornellBox(100.0);
  FilterInput huge = test::filterInput(FilterKind::Radiosity, sf);
  huge.values.set("memory_budget_mb", 1e7);
  struct Share {
    Share() { shareMemoryWith(4); }
    ~Share() { shareMemoryWith(1); }  // also if the run throws
  };
  const FilterResult r = [&] {
    Share four;
    return runFilter(FilterKind::Radiosity, huge);
  }();
  ASSERT_EQ(r.stats.warnings.size(), 1u);
  EXPECT_TRUE(has(r.stats.warnings[0], " MB of memory available to each of the 4 ranks on this machine, so the budget"))
      << r.stats.warnings[0];
}

TEST(MemoryLimit, RefusalIsOneSentence) {
  EXPECT_EQ(refusal([] { requireMemory(1e9, 2000000000, "x", "y"); }), "");
  EXPECT_EQ(refusal([] { requireMemory(1e18, 0, "x", "y"); }), "");  // limit unknown: no check
  const std::string m = refusal([] { requireMemory(6.4e9, 2000000000, "an image of 16384 x 16384 pixels", "lower it"); });
  EXPECT_EQ(m, "an image of 16384 x 16384 pixels needs about 6.4 GB, more than the 2.0 GB of memory available; lower it");
  EXPECT_EQ(refusal([] { requireMemory(73728, 65536, "x", "y"); }),
            "x needs about 74 KB, more than the 66 KB of memory available; y");
}

// 64 x 48 pixels take about 74 KB: refused under 64 KB before any ray, run
// under 1 MB.
TEST(MemoryLimit, ImageRefusedBeforeTracing) {
  const Scene s = scenes::cornellBox(100.0).scene;
  auto caster = makeEmbreeCaster(s);
  RenderOptions o;
  o.mode = RenderMode::Whitted;
  o.samplesPerPixel = 1;
  o.camera = Camera::lookAt({278, 273, -800}, {278, 273, 0}, {0, 1, 0}, 40, 64, 48);
  o.memoryLimitBytes = 64 << 10;
  const std::string m = refusal([&] { render(s, *caster, o); });
  EXPECT_TRUE(has(m, "an image of 64 x 48 pixels needs about")) << m;
  EXPECT_TRUE(has(m, "lower width and height")) << m;
  int calls = 0;
  EXPECT_THROW(render(s, *caster, o, Progress([&](int, const std::string&) { return ++calls > 0; })),
               std::invalid_argument);
  EXPECT_EQ(calls, 0);  // refused before the progress of any work
  o.memoryLimitBytes = 1 << 20;
  EXPECT_EQ(render(s, *caster, o).image.px.size(), size_t(64 * 48));
}

// 100,000 photons in the Cornell box store about 186,000 (10 MB at 56 bytes):
// refused under 2 MB, as a map and as each progressive pass, and computed
// under 64 MB; the caustic projection the same.
TEST(MemoryLimit, PhotonsRefusedOncePastTheLimit) {
  const Scene s = scenes::cornellBox(100.0).scene;
  auto caster = makeEmbreeCaster(s);
  PhotonOptions o;
  o.photons = 100000;
  o.lightSamples = 4;
  o.memoryLimitBytes = 2 << 20;
  std::string m = refusal([&] { computePhotonMap(s, *caster, o); });
  EXPECT_TRUE(has(m, "the photon map of 100000 photons needs about")) << m;
  EXPECT_TRUE(has(m, "lower the photons")) << m;
  o.progressive = true;
  o.passes = 2;
  m = refusal([&] { computePhotonMap(s, *caster, o); });
  EXPECT_TRUE(has(m, "the photon map of 100000 photons needs about")) << m;
  o.memoryLimitBytes = 64 << 20;
  EXPECT_EQ(computePhotonMap(s, *caster, o).H.size(), s.vertexCount());

  const Scene c = scenes::causticCornell(50.0, 10.0, 3, 1.5f);
  auto cc = makeEmbreeCaster(c);
  PhotonOptions q;
  q.memoryLimitBytes = 256 << 10;
  PhotonTraceStats st;
  m = refusal([&] { traceCausticPhotons(c, *cc, q, 0, 200000, Progress(nullptr), st); });
  EXPECT_TRUE(has(m, "the caustic map of 200000 photons needs about")) << m;
  q.memoryLimitBytes = 64 << 20;
  EXPECT_FALSE(traceCausticPhotons(c, *cc, q, 0, 200000, Progress(nullptr), st).empty());
}

// Photon mapping's caustic projection is traced while the global photons
// are held: under a fixed limit it gets what they leave. Sizes from the
// same traces run alone (deterministic): a limit above either photon set
// but below both (the larger and half the smaller) refuses the projection,
// naming the caustic map; 10% above both runs. The projection was checked
// against the whole limit before, and ran there.
TEST(MemoryLimit, CausticProjectionGetsWhatTheGlobalPhotonsLeave) {
  const Scene c = scenes::causticCornell(50.0, 10.0, 3, 1.5f);
  auto cc = makeEmbreeCaster(c);
  PhotonOptions o;
  o.photons = 40000;
  o.lightSamples = 4;
  ASSERT_TRUE(o.causticProjection);
  PhotonTraceStats st;
  const double global = double(tracePhotons(c, *cc, o, 0, 40000, Progress(nullptr), st).size()) * 56.0;
  const double caustic = double(traceCausticPhotons(c, *cc, o, 0, 40000, Progress(nullptr), st).size()) * 56.0;
  ASSERT_GT(caustic, 0.1 * global);  // a limit between the larger and the sum exists (about 0.19 of it)
  const size_t between = size_t(std::max(global, caustic) + 0.5 * std::min(global, caustic));
  o.memoryLimitBytes = between;
  const std::string m = refusal([&] { computePhotonMap(c, *cc, o); });
  EXPECT_TRUE(has(m, "the caustic map of 40000 photons needs about")) << m;
  o.memoryLimitBytes = size_t(1.1 * (global + caustic));
  EXPECT_EQ(computePhotonMap(c, *cc, o).H.size(), c.vertexCount());
  // The same account in each progressive pass.
  o.progressive = true;
  o.passes = 2;
  o.memoryLimitBytes = between;
  EXPECT_TRUE(has(refusal([&] { computePhotonMap(c, *cc, o); }), "the caustic map of 40000 photons needs about"));
}

// whileHolding: a fixed limit less the held photons' cost, never 0 (which
// would mean the machine's figure); the machine's figure stays as it is.
TEST(MemoryLimit, WhileHoldingLeavesWhatTheHeldPhotonsDoNotTake) {
  PhotonOptions o;
  o.memoryLimitBytes = 1000000;
  EXPECT_EQ(whileHolding(o, 10000).memoryLimitBytes, size_t(1000000 - 10000 * 56));
  EXPECT_EQ(whileHolding(o, 10000, 40000.0).memoryLimitBytes, size_t(1000000 - 10000 * 56 - 40000));
  EXPECT_EQ(whileHolding(o, 20000).memoryLimitBytes, size_t(1));
  o.memoryLimitBytes = 0;
  EXPECT_EQ(whileHolding(o, 20000).memoryLimitBytes, size_t(0));
}

// The two-pass mode's caustic photons and its image share one limit: an
// image and a map that each fit alone, but not together, are refused (each
// was checked alone against the whole limit before, and the kernel's figure
// does not count the image until it is allocated, after the photons); the
// refusal names both remedies. Sizes from a first run: the image is made
// as large as the photons, and the limit 1.5 times either.
TEST(MemoryLimit, TwoPassImageAndCausticPhotonsShareTheLimit) {
  const Scene c = scenes::causticCornell(50.0, 10.0, 3, 1.5f);
  auto cc = makeEmbreeCaster(c);
  RenderOptions o;
  o.mode = RenderMode::TwoPass;
  o.twoPass = TwoPassDiffuse::Caustics;
  o.samplesPerPixel = 1;
  o.causticPhotons = 20000;
  o.firstPassB.assign(c.vertexCount(), glm::vec3(0.5f));
  glm::dvec3 lo(1e30), hi(-1e30);
  for (const auto& p : c.positions) {
    lo = glm::min(lo, c.toWorld(p));
    hi = glm::max(hi, c.toWorld(p));
  }
  o.camera = Camera::frame(lo, hi, {0, 0, 1}, {0, 1, 0}, 39.3, 8, 8);
  const double photonBytes = render(c, *cc, o).stats.get("caustic_photons_stored") * 56.0;
  ASSERT_GT(photonBytes, 100e3);
  const int side = int(std::ceil(std::sqrt(photonBytes / 24.0)));
  o.camera = Camera::frame(lo, hi, {0, 0, 1}, {0, 1, 0}, 39.3, side, side);
  const double imageBytes = double(side) * side * 24.0;
  o.memoryLimitBytes = size_t(1.5 * std::max(photonBytes, imageBytes));
  ASSERT_LT(photonBytes + imageBytes, 2.2 * double(o.memoryLimitBytes) / 1.5);  // the two are alike
  const std::string m = refusal([&] { render(c, *cc, o); });
  EXPECT_TRUE(has(m, "the caustic map of 20000 photons needs about")) << m;
  EXPECT_TRUE(has(m, "lower caustic_photons, or width and height (the image takes another")) << m;
  o.memoryLimitBytes = size_t(1.1 * (photonBytes + imageBytes));
  EXPECT_EQ(render(c, *cc, o).image.px.size(), size_t(side) * side);
}

// memory_budget_mb at the table's largest (10^7 MB) is more than any machine
// here has: the run keeps to the memory available and says so, with the
// same values as at a budget of 64 MB (the matrix fits either way); a run
// refused under the lowered budget says it was lowered.
TEST(MemoryLimit, RadiosityBudgetLoweredToTheMemoryAvailable) {
  const auto sf = scenes::cornellBox(100.0);
  FilterInput base = test::filterInput(FilterKind::Radiosity, sf);
  base.values.set("memory_budget_mb", 64.0);
  FilterInput huge = base;
  huge.values.set("memory_budget_mb", 1e7);
  const FilterResult a = runFilter(FilterKind::Radiosity, base), b = runFilter(FilterKind::Radiosity, huge);
  EXPECT_TRUE(a.stats.warnings.empty());
  ASSERT_EQ(b.stats.warnings.size(), 1u);
  EXPECT_TRUE(has(b.stats.warnings[0], "memory_budget_mb = 10000000 exceeds the ")) << b.stats.warnings[0];
  ASSERT_EQ(a.attributes.size(), b.attributes.size());
  EXPECT_EQ(a.attributes[0].values, b.attributes[0].values);
  // 10^8 patches of refinement need more than any machine has.
  huge.values.set("refine", true);
  huge.values.set("refine_max_depth", 12);
  huge.values.set("refine_max_patches", 100000000);
  const std::string m = refusal([&] { runFilter(FilterKind::Radiosity, huge); });
  EXPECT_TRUE(has(m, "memory_budget_mb = 10000000 exceeds the ") && has(m, "so the budget was")) << m;
}
