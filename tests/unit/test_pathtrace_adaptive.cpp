// The reference adaptive to a target relative error: the counts a pilot
// sizes (gi/sampling.h), how close they come to the target, and what the
// log says of the vertices above it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gi/color.h"
#include "gi/pathtrace.h"
#include "gi/raycaster.h"
#include "gi/scenes.h"
#include "test_helpers.h"

using namespace gi;

// Adaptive: each vertex's count is fixed from a pilot that the estimate
// leaves out (unbiased: WindowRoom.AdaptiveReferenceIsUnbiased), with a
// margin of 1.25 for the pilot's error; so the target holds at most
// vertices, not all: the error bar over the target (relative to the
// vertex's B, or to a tenth of the scene's mean for dark ones) has a median
// of 0.89, a 90th percentile of 1.05 and a largest of 1.34 here (a pilot of
// 64 paths and rounds to twice the target). Bounds: 1, 1.25 and 2 (a pilot
// that misread its variance by 4 times).
TEST(PathTracer, AdaptiveReachesTarget) {
  auto sf = scenes::cornellBox(150.0);
  auto caster = makeEmbreeCaster(sf.scene);
  PathTraceOptions o;
  o.targetRelativeError = 0.05;
  o.minSamples = 64;
  o.maxSamples = 4096;
  const auto r = pathTrace(sf.scene, *caster, o);
  const double floorB = 0.1 * r.stats.get("mean_luminance_B");
  std::vector<double> ratio;
  size_t stopped = 0;
  for (size_t i = 0; i < r.B.size(); ++i) {
    const double q = r.stdError[i] / (0.05 * std::max(double(luminance(r.B[i])), floorB));
    if (r.samples[i] >= o.maxSamples) stopped += q > 1;
    else ratio.push_back(q);
  }
  const test::OverTarget over = test::overTarget(ratio);
  EXPECT_LT(over.median, 1.0);
  EXPECT_LT(over.p90, 1.25);
  EXPECT_LT(over.largest, 2.0);
  // The ratios average below 1: 0.884 over 40 seeds (sd 0.019, the largest
  // 0.933; the largest single ratio 1.74). The log's mean relative error is
  // the mean of se / B over the traced vertices: vertices darker than the
  // floor count relative to their own B, so it has no bound of its own (a
  // fixed 0.06 was exceeded at 16 of 40 seeds, mean 0.0594): recomputed.
  double sumRatio = 0, rel = 0;
  size_t nearOne = 0, traced = 0;
  for (const double q : ratio) sumRatio += q, nearOne += std::fabs(q - 1.0) < 1e-3;
  for (size_t i = 0; i < r.B.size(); ++i) {
    if (!r.traced[i]) continue;
    const double b = luminance(r.B[i]);
    if (b > 0) rel += r.stdError[i] / b;
    ++traced;
  }
  EXPECT_LT(sumRatio / double(ratio.size()), 1.0);
  EXPECT_NEAR(r.stats.get("mean_relative_std_error"), rel / double(traced), 1e-9);
  // The engine counts in double what the test reads in float: a ratio within
  // 1e-3 of 1 may fall on either side (about one vertex a seed).
  const size_t above = size_t(r.stats.get("vertices_above_target"));
  EXPECT_LE(std::max(above, over.above) - std::min(above, over.above), nearOne);
  EXPECT_GE(r.stats.get("pilot_paths"), 64.0 * double(r.B.size()));
  // The vertices above the target are noted with their count; those that
  // stopped at max_samples above it are warned of (this ran in silence until
  // 5 December 2026): all of them with a target of 1e-6 at 64.
  ASSERT_EQ(r.stats.warnings.size(), stopped ? 1u : 0u);
  if (stopped) {
    EXPECT_EQ(r.stats.warnings[0].rfind(std::to_string(stopped) + " of ", 0), 0u) << r.stats.warnings[0];
  }
  const bool noted = std::any_of(r.stats.notes.begin(), r.stats.notes.end(), [&](const std::string& n) {
    return n.rfind(std::to_string(above) + " of ", 0) == 0 && n.find("above target_relative_error") != std::string::npos;
  });
  EXPECT_EQ(noted, above > 0);
  o.targetRelativeError = 1e-6;
  o.maxSamples = 64;
  const auto unmet = pathTrace(sf.scene, *caster, o);
  ASSERT_EQ(unmet.stats.warnings.size(), 1u);
  EXPECT_EQ(unmet.stats.warnings[0].rfind(std::to_string(r.B.size()) + " of " + std::to_string(r.B.size()) +
                                              " traced vertices stopped at max_samples",
                                          0),
            0u)
      << unmet.stats.warnings[0];
}

// Found by an outside review of the pilot (5 December 2026): a vertex whose
// pilot and ring saw no light (a closed box under the sky) has no variance
// and keeps min_samples paths (it took max_samples: 4,096 a vertex, 256
// times the cost); the paths cut at max_depth and the depth warning count
// the kept paths only, as "paths" does (the pilot's were counted too: "cut
// 36248 of 19672 paths"); and with max_samples = min_samples there is no
// pilot (the count cannot vary).
TEST(PathTracer, AdaptivePilotEdgeCases) {
  auto box = scenes::closedBox(1.0, 3, true);
  scenes::setUniform(box, glm::vec3(0.5f), glm::vec3(0.f));
  auto caster = makeEmbreeCaster(box.scene);
  PathTraceOptions o;
  o.skyRadiance = glm::vec3(1.f);
  o.targetRelativeError = 0.1;
  o.minSamples = 16;
  o.maxSamples = 4096;
  const PathTraceResult dark = pathTrace(box.scene, *caster, o);
  const double nv = double(box.scene.vertexCount());
  EXPECT_EQ(dark.stats.get("paths"), 16.0 * nv);
  EXPECT_EQ(dark.stats.get("pilot_paths"), 16.0 * nv);
  for (const glm::vec3& b : dark.B) EXPECT_EQ(b, glm::vec3(0.f));

  auto sf = scenes::cornellBox(150.0);
  auto cc = makeEmbreeCaster(sf.scene);
  PathTraceOptions d;
  d.maxDepth = 0;
  d.targetRelativeError = 0.2;
  d.minSamples = 16;
  d.maxSamples = 256;
  const PathTraceResult cut = pathTrace(sf.scene, *cc, d);
  EXPECT_GT(cut.stats.get("paths_cut_at_max_depth"), 0.0);
  EXPECT_LE(cut.stats.get("paths_cut_at_max_depth"), cut.stats.get("paths"));

  d.minSamples = d.maxSamples = 64;
  const PathTraceResult fixed = pathTrace(sf.scene, *cc, d);
  EXPECT_EQ(fixed.stats.get("pilot_paths"), 0.0);
  EXPECT_EQ(fixed.stats.get("paths"), 64.0 * double(sf.scene.vertexCount()));
}
