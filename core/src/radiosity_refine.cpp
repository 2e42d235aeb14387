// Adaptive mesh refinement around the radiosity solver: solve -> mark ->
// subdivide -> solve again (Cohen, Greenberg, Immel and Brock 1986 refine
// where B varies; Heckbert 1992 and Lischinski et al. 1992 where shadow
// boundaries cross patches).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "gi/radiosity.h"

namespace gi {

namespace {
std::string level(int k) { return "level " + std::to_string(k); }

// Memory per patch of the refined mesh besides the solver's
// (kSolverBytesPerPatch): the refiner's faces, edge and midpoint maps and the
// trial copy that checks the patch budget (measured: 790 bytes per patch in
// all at peak at 587,000 patches, the form factors apart).
constexpr double kRefinerBytesPerPatch = 624;

// The most patches refinement can reach: the budget, or every input face
// split at every level (4^depth; green closure never exceeds a full split).
double reachablePatches(size_t inputFaces, const RefineOptions& ro) {
  return std::min(double(ro.maxPatches), double(inputFaces) * std::pow(4.0, double(ro.maxDepth)));
}

// Refuses unusable limits, and at once a refinement whose mesh cannot fit
// the memory budget, not after hours of refining.
void checkRefinement(const Scene& s, const RadiosityOptions& opt) {
  const RefineOptions& ro = opt.refinement;
  if (ro.maxDepth < 0) throw std::invalid_argument("refine_max_depth must be >= 0");
  if (ro.maxPatches < 1) throw std::invalid_argument("refine_max_patches must be >= 1");
  if (!(ro.threshold > 0)) throw std::invalid_argument("refine_threshold must be > 0");
  const double MB = 1048576.0, reach = reachablePatches(s.faceCount(), ro);
  const double need = reach * kRefinerBytesPerPatch + solverBaseBytes(size_t(reach), opt);
  if (need > opt.memoryBudgetMB * MB) {
    char b[600];
    std::snprintf(b, sizeof b,
                  "adaptive refinement may reach %.0f patches (refine_max_patches %d; %zu faces x 4^%d levels), about "
                  "%.0f MB for the mesh, the refiner and the solver (the form factors apart): more than "
                  "memory_budget_mb = %g; lower refine_max_patches or refine_max_depth, or raise memory_budget_mb",
                  reach, ro.maxPatches, s.faceCount(), ro.maxDepth, need / MB, opt.memoryBudgetMB);
    throw std::invalid_argument(b);
  }
}

// How many of the marked faces (most needing first) can be refined within
// the patch budget: the prefix is shrunk until its conforming closure fits;
// 0 when not even a small one does.
size_t facesWithinBudget(const MeshRefiner& refiner, const std::vector<uint32_t>& marked, size_t budget) {
  const size_t n = refiner.mesh().scene.faceCount();
  size_t take = marked.size(), after = refiner.faceCountAfter(marked);
  for (int tries = 0; after > budget && take > 0 && tries < 40; ++tries) {
    const double room = n < budget ? double(budget - n) : 0.0;
    const size_t shrunk = size_t(double(take) * room / double(after - n) * 0.9);
    take = std::min(take - 1, shrunk);
    after = refiner.faceCountAfter({marked.begin(), marked.begin() + long(take)});
  }
  return after > budget ? 0 : take;
}

}  // namespace

std::vector<ParamSpec> RefineOptions::specs() {
  return {
      {.name = "refine_max_depth", .label = "Refinement: maximum depth",
       .help = "Levels of refinement: each level splits the marked patches once (a patch of depth d is 4^d times "
               "smaller than its original triangle) and solves again, so the cost grows with the levels.",
       .type = ParamType::Int, .def = 3, .min = 1, .max = 12},
      {.name = "refine_max_patches", .label = "Refinement: patch budget",
       .help = "Never more patches than this; when a level would exceed it, the patches that need refinement most "
               "(largest jump or visibility difference times area) are split first.",
       .type = ParamType::Int, .def = 200000, .min = 1, .max = 100000000},
      {.name = "refine_threshold", .label = "Refinement: radiosity jump",
       .help = "Split the two patches on either side of an edge when their reflected radiosity differs by more than "
               "this fraction of the larger one (ignoring differences below 1% of the scene's mean). Smaller: more "
               "patches. Edges sharper than 30 degrees are not tested: B jumps there for real.",
       .type = ParamType::Float, .def = 0.1, .min = 1e-4, .max = 100.0},
      {.name = "refine_shadow_threshold", .label = "Refinement: shadow boundary",
       .help = "Split a patch when the fraction of the lights visible from its vertices (64 shadow rays each) "
               "differs by more than this between two of its vertices: a shadow boundary crosses it. Each light "
               "apart: the emitting faces (shadow rays to points on them) and the sun (rays in its disk); the "
               "sky's soft shadows are found by the B jump test (refine_threshold). 1 turns this test off.",
       .type = ParamType::Float, .def = 0.3, .min = 0.0, .max = 1.0},
  };
}

RefineOptions RefineOptions::fromParams(const ParamValues& v) {
  RefineOptions o;
  o.maxDepth = v.getInt("refine_max_depth");
  o.maxPatches = v.getInt("refine_max_patches");
  o.threshold = v.getFloat("refine_threshold");
  o.shadowThreshold = v.getFloat("refine_shadow_threshold");
  o.seed = uint32_t(v.getInt("seed"));
  return o;
}

AdaptiveRadiosity solveRadiosityAdaptive(const Scene& s, const RadiosityOptions& opt, const Progress& progress,
                                         const CasterFactory& makeCaster) {
  const RefineOptions& ro = opt.refinement;
  checkRefinement(s, opt);
  const double MB = 1048576.0;
  const CasterFactory caster = makeCaster ? makeCaster : [](const Scene& sc) { return makeEmbreeCaster(sc); };
  Timer timer;
  MeshRefiner refiner(s);
  RadiosityOptions levelOpt = opt;
  levelOpt.vertices = VertexPart();  // where to refine depends on every vertex's value
  // Intermediate levels: direct light at the vertices, indirect interpolated (no gather rays).
  if (levelOpt.vertexOutput == RadiosityVertexOutput::FinalGather)
    levelOpt.vertexOutput = RadiosityVertexOutput::InterpolatedIndirect;
  const int levels = ro.maxDepth;
  auto stage = [&](int k) { return progress.sub(double(k) / (levels + 1), double(k + 1) / (levels + 1)); };

  std::vector<std::string> log;
  std::string why = "maximum depth " + std::to_string(ro.maxDepth) + " reached";
  RadiosityResult res;
  bool changed = true;  // since the last solve
  for (int k = 0; k < levels; ++k) {
    const Scene& sc = refiner.mesh().scene;
    auto rc = caster(sc);
    // The refiner's own memory comes out of the solver's budget.
    levelOpt.memoryBudgetMB = std::max(1.0, opt.memoryBudgetMB - double(sc.faceCount()) * kRefinerBytesPerPatch / MB);
    res = solveRadiosity(sc, *rc, levelOpt, stage(k));
    changed = false;
    std::vector<std::vector<float>> V;
    if (ro.shadowThreshold < 1.0) {
      V.push_back(emitterVisibility(sc, *rc, ro.visibilityRays, ro.seed));
      V.push_back(sunVisibility(sc, *rc, levelOpt.outside, ro.visibilityRays, ro.seed));
    }
    RefineMarks marks = markForRefinement(sc, res.B, res.Bvertex, V, refiner.mesh().depth, ro);
    const size_t n = sc.faceCount(), budget = size_t(ro.maxPatches);
    if (marks.faces.empty()) {
      why = "nothing left above the thresholds";
      break;
    }
    // Faces left out of the computation (a duplicated face's copies) are
    // no patches: never split, and not counted against the budget.
    const size_t leftOut = size_t(std::count(sc.leftOut.begin(), sc.leftOut.end(), uint8_t(1)));
    const size_t take = facesWithinBudget(refiner, marks.faces, budget + leftOut);
    if (take == 0) {
      why = "patch budget " + std::to_string(budget) + " reached (" + std::to_string(marks.faces.size()) +
            " faces still above the thresholds)";
      break;
    }
    const size_t wanted = marks.faces.size();
    marks.faces.resize(take);
    refiner.refine(marks.faces);
    changed = true;
    // The reasons count the faces marked; the budget may refine fewer (the
    // log read "10 faces refined (80 by B jump, ...)"; an outside audit).
    log.push_back(level(k + 1) + ": " + std::to_string(take) +
                  (take < wanted ? " of " + std::to_string(wanted) + " faces marked refined (" : " faces refined (") +
                  std::to_string(marks.byJump) + " marked by B jump, " + std::to_string(marks.byShadow) +
                  " by shadow boundary), " + std::to_string(n) + " -> " +
                  std::to_string(refiner.mesh().scene.faceCount()) + " patches");
    if (take < wanted) {  // the budget cut this level short: the next could add only a handful
      why = "patch budget " + std::to_string(budget) + " reached (" + std::to_string(wanted - take) +
            " faces above the thresholds left unrefined)";
      break;
    }
  }
  // The final solve on the refined mesh, with the vertex output asked for.
  const Scene& sc = refiner.mesh().scene;
  if (changed || opt.vertexOutput != levelOpt.vertexOutput) {
    auto rc = caster(sc);
    RadiosityOptions lastOpt = opt;
    lastOpt.memoryBudgetMB = std::max(1.0, opt.memoryBudgetMB - double(sc.faceCount()) * kRefinerBytesPerPatch / MB);
    res = solveRadiosity(sc, *rc, lastOpt, stage(levels));
  }
  for (const auto& l : log) res.stats.note(l);
  res.stats.note("refinement stopped: " + why);
  if (size_t(ro.maxPatches) < s.faceCount())
    res.stats.warn("refine_max_patches " + std::to_string(ro.maxPatches) + " is below the mesh's " +
                   std::to_string(s.faceCount()) + " patches: nothing can be refined (the mesh is never coarsened)");
  res.stats.add("refine_levels", double(log.size()));
  res.stats.add("input_patches", double(s.faceCount()));
  res.stats.add("refined_patches", double(sc.faceCount()));
  res.stats.add("refine_total_seconds", timer.seconds());
  return {refiner.mesh(), std::move(res)};
}

}  // namespace gi
