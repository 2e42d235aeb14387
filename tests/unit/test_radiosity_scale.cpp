// Radiosity on large scenes: a memory budget too small is refused with one
// sentence before anything large is allocated (the ray-casting structure
// included), a budget that fits only part of the links finishes with a
// warning, and a hierarchical run reports progress through every stage.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "gi/filter_run.h"
#include "gi/hierarchical.h"
#include "gi/radiosity.h"
#include "gi/scan.h"
#include "gi/scenes.h"
#include "mesh_io.h"

using namespace gi;

namespace {

FilterInput radiosityInput(const scenes::SceneFile& sf, const std::string& solver, double budgetMB) {
  FilterInput in;
  in.scene = sf.scene;
  in.attrs = sf.attrs;
  in.layers.push_back({"mesh", 0, sf.scene.faceCount()});
  const auto specs = filterSpecs(FilterKind::Radiosity);
  const double diag = analyzeScene(in.scene).diagonal;
  in.values = defaultValues(specs, diag);
  in.values.set("emitter_source", int(kEmitterSources.index(EmitterSource::QualityAbove)));
  in.values.set("solver", parseValue(*findSpec(specs, "solver"), solver, diag));
  in.values.set("memory_budget_mb", budgetMB);
  return in;
}

const scenes::SceneFile& scanRoom10k() {
  static const scenes::SceneFile sf = scenes::scanRoom(
      io::loadMesh(std::string(GI_TEST_MESHES) + "/bunny.ply").scene, 10000, scenes::ScanOptions{});
  return sf;
}

}  // namespace

// 1 MB for 10k patches: the hierarchical solver needs about 900 bytes per
// patch (kSolverBytesPerPatch and two tree nodes), the flat ones 400 and a
// row per thread. The
// message names what is needed, the budget and the parameter to raise, and
// comes at once (the check precedes the ray-casting structure and the
// direct light: well under a second here even on a loaded machine).
TEST(RadiosityMemory, TinyBudgetRefusedWithOneSentenceBeforeAnyWork) {
  for (const char* solver : {"Hierarchical", "Gauss-Seidel", "Auto"}) {
    FilterInput in = radiosityInput(scanRoom10k(), solver, 1.0);
    const Timer t;
    try {
      runFilter(FilterKind::Radiosity, in);
      ADD_FAILURE() << solver << ": a 1 MB budget was accepted";
    } catch (const std::invalid_argument& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("memory_budget_mb = 1 is too small"), std::string::npos) << m;
      EXPECT_NE(m.find("raise memory_budget_mb to at least"), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
      const bool hier = std::string(solver) == "Hierarchical";
      EXPECT_NE(m.find(hier ? "cluster hierarchy" : "flat solver"), std::string::npos) << m;
      const double n = double(scanRoom10k().scene.faceCount());
      if (hier) {
        EXPECT_NE(m.find("need about " + std::to_string(int(std::ceil(n * (kSolverBytesPerPatch + 2 * kHierarchyBytesPerNode) / 1048576))) + " MB"),
                  std::string::npos) << m;
      }
    }
    EXPECT_LT(t.seconds(), 5.0) << solver;
  }
}

// A budget just above the hierarchy's fixed part: the links stop at what is
// left (give or take the pairs still pending when it is reached: at most two
// per node of the tree, the siblings' links each way), the run finishes and
// says so; later refinement rounds split links only within what the links
// still to be carried leave.
TEST(RadiosityMemory, BudgetForFewLinksFinishesWithAWarning) {
  const scenes::SceneFile sf = scenes::cornellBox(50.0);
  const double n = double(sf.scene.faceCount());
  const double fixedMB = n * (kSolverBytesPerPatch + 2 * kHierarchyBytesPerNode) / 1048576.0;
  FilterInput in = radiosityInput(sf, "Hierarchical", fixedMB + 0.5);  // about 11k links
  in.values.set("vertex_output", int(kRadiosityVertexOutputs.index(RadiosityVertexOutput::PatchAverage)));
  const FilterResult r = runFilter(FilterKind::Radiosity, in);
  const double pending = 2 * 2 * n;
  EXPECT_LE(r.stats.get("links"), 0.5 * 1048576.0 / kHierarchyBytesPerLink + pending);
  bool warned = false;
  for (const std::string& w : r.stats.warnings) warned |= w.find("stopped at the memory budget") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_LE(r.stats.get("memory_estimate_MB"), fixedMB + 0.5 + pending * kHierarchyBytesPerLink / 1048576.0);
}

// Every stage of a hierarchical run with final gather reports, in order,
// from 0 to 100%: the per-vertex stages too (at a million triangles they
// take minutes). The log gives levels, links, splits, rays and memory.
TEST(RadiosityProgress, HierarchicalRunReportsEveryStage) {
  FilterInput in = radiosityInput(scenes::cornellBox(100.0), "Hierarchical", 1024.0);
  in.values.set("gather_rays", 16);
  std::vector<std::pair<int, std::string>> seen;
  const Progress progress([&](int pct, const std::string& stage) {
    seen.push_back({pct, stage});
    return true;
  });
  const FilterResult r = runFilter(FilterKind::Radiosity, in, progress);
  ASSERT_FALSE(seen.empty());
  for (size_t k = 1; k < seen.size(); ++k) ASSERT_GE(seen[k].first, seen[k - 1].first) << seen[k].second;
  EXPECT_EQ(seen.back().first, 100);
  auto firstOf = [&](const std::string& stage) {
    for (size_t k = 0; k < seen.size(); ++k)
      if (seen[k].second == stage) return int(k);
    return -1;
  };
  const int tree = firstOf("cluster tree"), links = firstOf("refining links"), ff = firstOf("link form factors");
  const int direct = firstOf("direct light at vertices"), gather = firstOf("final gather at vertices");
  EXPECT_GE(tree, 0);
  EXPECT_GT(links, tree);
  EXPECT_GT(ff, links);
  EXPECT_GT(direct, ff);
  EXPECT_GT(gather, direct);
  EXPECT_GE(seen[size_t(gather)].first, 70);
  for (const char* key : {"hierarchy_levels", "links", "link_splits", "link_rays", "gather_rays", "hierarchy_MB",
                          "memory_estimate_MB"})
    EXPECT_GT(r.stats.get(key, -1.0), 0.0) << key;
}
