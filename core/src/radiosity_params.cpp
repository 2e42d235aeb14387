// Parameter table of GI: Radiosity (MeshLab dialog, meshlabserver scripts and
// CLI flags), the options read from it once, and the memory check they allow
// before any work.
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "gi/form_factors.h"
#include "gi/hierarchical.h"
#include "gi/radiosity.h"
#include "radiosity_course.h"

namespace gi {

std::vector<ParamSpec> RadiosityOptions::specs() {
  std::vector<ParamSpec> s = formFactorSpecs();
  const std::vector<ParamSpec> more = {
      {.name = "light_samples", .label = "Shadow rays per patch",
       .help = "Direct light is computed apart from the form factors, so small lights stay noise-free. Coplanar, "
               "edge-connected emitter faces of one emission are grouped into luminaires (polygons); with up to 256 "
               "of them, the exact point-to-polygon form factor from points on the patch (one per 64 rays) and at "
               "each vertex to every luminaire, times its visible fraction from 16 shadow rays stratified over it, "
               "and where they disagree (penumbra) up to this many per patch and per vertex (Wallace et al. 1989); "
               "with more luminaires, points on the emitters sampled in proportion to power with a shadow ray each. "
               "With a sky or a sun, this many rays again for each (cosine-weighted to the sky, uniform in the sun's "
               "disk: soft shadows).",
       .type = ParamType::Int, .def = 256, .min = 1, .max = 1 << 20},
  };
  s.insert(s.end(), more.begin(), more.end());
  // The sky and the sun light each patch from outside the scene: rho times
  // their irradiance (light_samples rays each per patch and per vertex)
  // enters as emission before the solve.
  for (const ParamSpec& p : SkySun::specs()) s.push_back(p);
  const std::vector<ParamSpec> solverSpecs = {
      {.name = "solver", .label = "Solver",
       .help = "Jacobi: B <- E + rho F B for all patches at once (one sweep = one more bounce). Gauss-Seidel: uses "
               "new values as soon as they exist (fewer sweeps). Progressive refinement (Cohen et al. 1988): "
               "repeatedly shoots the unshot power of the brightest patch; useful images early. Auto: Gauss-Seidel, "
               "or progressive refinement when the form factors do not fit the memory budget; hierarchical from 50,000 "
               "patches on. Hierarchical with clustering (Hanrahan, Salzman and Aupperle 1991; Smits, Arvo and "
               "Greenberg 1994): light travels on links between clusters of triangles where little power flows and "
               "between triangles where much does, so time and memory grow about as n log n instead of n^2; the "
               "form-factor method then applies to nothing (links have their own factors).",
       .type = ParamType::Enum, .def = kRadiositySolvers.index(RadiositySolver::Auto),
       .choices = kRadiositySolvers.choices()},
      {.name = "bounces", .label = "Bounces",
       .help = "-1: iterate until the tolerance is met (all bounces). 0: direct light only (B = E + rho H_direct); "
               "k: light after k further diffuse inter-reflections (exactly k Jacobi sweeps, as in the course's "
               "progressive images).",
       .type = ParamType::Int, .def = -1, .min = -1, .max = 100000},
      {.name = "tolerance", .label = "Tolerance",
       .help = "Stop when the change of a sweep (Jacobi, Gauss-Seidel) or the unshot power (progressive), as power "
               "relative to the emitted power, is below this.",
       .type = ParamType::Float, .def = 1e-4, .min = 1e-12, .max = 1.0},
      {.name = "max_iterations", .label = "Maximum iterations",
       .help = "Upper bound on sweeps (Jacobi, Gauss-Seidel; hierarchical: per round of link refinement, at most 4 "
               "rounds) or on shots per patch (progressive refinement). 0 = "
               "automatic: each sweep shrinks the remaining error at least by the largest reflectance rho_max (the "
               "spectral radius of rho F is at most rho_max, as rows of F sum to at most 1), so 1.5 ln(tolerance) / "
               "ln(rho_max) sweeps reach the tolerance: 13,809 for rho_max = 0.999 (tolerance 1e-4), 132 for 0.9. A "
               "run stopped by this bound before the tolerance is met logs a warning with the possible error.",
       .type = ParamType::Int, .def = 0, .min = 0, .max = 1000000},
      {.name = "memory_budget_mb", .label = "Memory budget (MB)",
       .help = "Everything the solve holds counts: about 400 bytes per patch (scene, ray casting, solver), one "
               "form-factor row per thread (a hemicube's buffers: 144 MB at resolution 4096), about 1 KB per patch "
               "of the refined mesh with adaptive refinement, and the sparse form-factor matrix, kept while it fits; "
               "beyond that, progressive refinement computes each shooter's row on the fly (more rays, memory linear "
               "in the patch count). A run that cannot fit even so is refused before it starts. A budget above the "
               "memory available is lowered to it (a warning says so).",
       .type = ParamType::Float, .def = 1024, .min = 1, .max = 1e7},
      {.name = "hierarchy_epsilon", .label = "Hierarchical: link tolerance",
       .help = "Hierarchical solver only. A link between two clusters (or patches) is split into links between "
               "their children while the power it may carry, A_p F_max B_q (the BF criterion of Hanrahan et al. "
               "1991), exceeds this fraction of the power leaving all surfaces (emitted and reflected), or while their "
               "bounding spheres overlap. Smaller: "
               "more links, closer to the flat solution (0: every patch pair, the flat solution at its cost).",
       .type = ParamType::Float, .def = 1e-4, .min = 0, .max = 1.0,
       .usedWhen = {{"solver", {kRadiositySolvers.index(RadiositySolver::Auto), kRadiositySolvers.index(RadiositySolver::Hierarchical)}}}},
      {.name = "link_rays", .label = "Hierarchical: visibility rays per link",
       .help = "Hierarchical solver only. Rays between paired points of a link's two nodes that exchange light; "
               "the fraction that passes scales the link's unoccluded form factor (cost: links x rays). Up to 16, a "
               "link from a cluster gathers the radiosity where its passing rays end; above, the cluster's mean.",
       .type = ParamType::Int, .def = 4, .min = 1, .max = 1024,
       .usedWhen = {{"solver", {kRadiositySolvers.index(RadiositySolver::Auto), kRadiositySolvers.index(RadiositySolver::Hierarchical)}}}},
      {.name = "closure_rays", .label = "Hierarchical: closure rays per patch",
       .help = "Hierarchical solver only. The links' form factors are quadratures, so the factors of one patch's "
               "links sum only approximately to the part G of its hemisphere that meets a surface (0.94 to 1.06 "
               "in a closed box at the default link tolerance), and at high reflectance light is created or lost "
               "in proportion to 1 / (1 - rho): a closed box read 10% high at rho 0.99 and diverged at 0.999. "
               "This many rays from each patch count G. In a closed room without occluders (every ray hits, no "
               "link needs visibility rays) the links are then balanced so that every patch's links sum to 1, "
               "both what it gathers and what it sends (Sinkhorn balancing): no light is created or lost. "
               "Elsewhere the links stand, and the log's energy_balance_error (against the rays' count of what "
               "escapes) indicates how much light they create or lose (a warning above 5%: use a flat solver there). "
               "Cost: patches x rays (with occluders, where they serve the indicator alone: at most 8 million "
               "rays in all, at least 4 a patch). 0: neither.",
       .type = ParamType::Int, .def = 64, .min = 0, .max = 65536,
       .usedWhen = {{"solver", {kRadiositySolvers.index(RadiositySolver::Auto), kRadiositySolvers.index(RadiositySolver::Hierarchical)}}}},
      {.name = "max_links", .label = "Hierarchical: links at most",
       .help = "Hierarchical solver only. The links stop being refined at this many (as at the memory budget), "
               "refined again best first: the link that may carry the most power is split first, so what stays "
               "coarse carries the least. Time and memory grow with the links (about 56 bytes each); fewer links "
               "cost accuracy (a 100k-triangle scan room: 12M links 1.6%, 2M links 3.1%). 0: no cap but the "
               "memory budget.",
       .type = ParamType::Int, .def = 0, .min = 0, .max = 2000000000,
       .usedWhen = {{"solver", {kRadiositySolvers.index(RadiositySolver::Auto), kRadiositySolvers.index(RadiositySolver::Hierarchical)}}}},
      {.name = "vertex_output", .label = "Vertex values",
       .help = "How vertex colour and quality are made from the patch solution. 'Final gather': the direct light is "
               "computed exactly at each vertex (sharp shadows, no patch staircase) and the indirect light is "
               "gathered from the patch solution with rays from the vertex (no staircase; but a patch that reaches "
               "under a wall into a dark room still carries its light there: the gather reads it, about 1.7% of the "
               "lit room on the shadow-leak scene; refine removes it). 'Interpolated indirect': direct light at the vertex, indirect light as the mean of "
               "the incident patches'. 'Patch average': the area-weighted mean of the incident patches' radiosity "
               "(the classical look of the course's images). These two show the classical leaks more: a vertex "
               "under a box standing on a floor takes the light of the floor patches it shares with the open "
               "floor (an outside audit: 45 cm inside a 1 m box, 1.5 times the floor's mean with Patch average; "
               "refinement moves the leak to the box's rim), where the final gather reads 0.",
       .type = ParamType::Enum, .def = kRadiosityVertexOutputs.index(RadiosityVertexOutput::FinalGather),
       .choices = kRadiosityVertexOutputs.choices()},
      {.name = "gather_rays", .label = "Final-gather rays per vertex",
       .help = "Rays per vertex for the final gather of the indirect light (cosine-weighted).",
       .type = ParamType::Int, .def = 256, .min = 1, .max = 1 << 20,
       .usedWhen = {{"vertex_output", {kRadiosityVertexOutputs.index(RadiosityVertexOutput::FinalGather)}}}},
      {.name = "gather_share_rings", .label = "Final gather: shared with neighbours (rings)",
       .help = "Neighbouring vertices see almost the same surroundings, so each vertex may pool the gather rays of "
               "its neighbours up to this many mesh rings away (1: its direct neighbours, about 7 vertices; 2: about "
               "19), through neighbours whose normals lie within 10 degrees of its own (so pools stop at creases). "
               "A first-order fit over the pool removes the bias of a steady gradient, and Lepski's rule stops a "
               "pool from growing where its estimate departs from the smaller pools' by more than their noise "
               "explains. For dense meshes (a scan, a finely meshed room), where it halves the gather's error at "
               "the same rays; next to an object just above the surface or a concave edge a vertex may take some "
               "of its neighbours' light (up to several percent). 0: every vertex uses its own rays only.",
       .type = ParamType::Int, .def = 0, .min = 0, .max = 8,
       .usedWhen = {{"vertex_output", {kRadiosityVertexOutputs.index(RadiosityVertexOutput::FinalGather)}}}},
      seedSpec("form-factor, shadow and final-gather rays"),
      {.name = "refine", .label = "Adaptive mesh refinement",
       .help = "Subdivide patches where the solution needs it, then solve again: a patch is split 1 -> 4 at its edge "
               "midpoints where its reflected radiosity jumps across an edge (staircase artefacts) or where a shadow "
               "boundary crosses it (its vertices see the lights differently: shadow leaks); neighbours are bisected "
               "or split too, so the mesh stays free of T-junctions (red-green refinement). The refined mesh "
               "replaces the layer's geometry (faces keep colour, quality and selection). Off: the geometry is never "
               "changed.",
       .type = ParamType::Bool, .def = false},
  };
  s.insert(s.end(), solverSpecs.begin(), solverSpecs.end());
  for (const ParamSpec& p : RefineOptions::specs()) s.push_back(p);
  for (const ParamSpec& p : radiosityCourseSpecs()) s.push_back(p);
  return s;
}

RadiosityOptions RadiosityOptions::fromParams(const ParamValues& v) {
  RadiosityOptions o;
  o.formFactors = formFactorSettings(v);
  o.lightSamples = v.getInt("light_samples");
  o.outside = SkySun::fromParams(v);
  o.solver = kRadiositySolvers.get(v, "solver");
  o.bounces = v.getInt("bounces");
  o.tolerance = v.getFloat("tolerance");
  o.maxIterations = v.getInt("max_iterations");
  o.memoryBudgetMB = v.getFloat("memory_budget_mb");
  o.hierarchyEpsilon = v.getFloat("hierarchy_epsilon");
  o.linkRays = v.getInt("link_rays");
  o.closureRays = v.getInt("closure_rays");
  o.maxLinks = double(v.getInt("max_links"));
  o.vertexOutput = kRadiosityVertexOutputs.get(v, "vertex_output");
  o.gatherRays = v.getInt("gather_rays");
  o.gatherShareRings = v.getInt("gather_share_rings");
  o.refine = v.getBool("refine");
  o.refinement = RefineOptions::fromParams(v);
  o.ambientTerm = v.getBool("ambient_term");
  o.snapshotSteps = parseSnapshotSteps(v.getString("snapshot_steps"));
  o.residualCsv = v.getString("residual_csv");
  o.exportSystem = v.getString("export_system");
  return o;
}

bool usesHierarchy(size_t patches, const RadiosityOptions& opt) {
  return opt.solver == RadiositySolver::Hierarchical ||
         (opt.solver == RadiositySolver::Auto && patches >= kHierarchicalAutoPatches);
}

void checkRadiosityOptions(const RadiosityOptions& o) {
  const std::vector<ParamSpec> t = RadiosityOptions::specs();
  requireInRange(t, "light_samples", o.lightSamples);
  requireInRange(t, "bounces", o.bounces);
  requireInRange(t, "tolerance", o.tolerance);
  requireInRange(t, "max_iterations", o.maxIterations);
  // Only what the solver and the vertex output use (the table's usedWhen).
  if (o.solver == RadiositySolver::Auto || o.solver == RadiositySolver::Hierarchical) {
    requireInRange(t, "hierarchy_epsilon", o.hierarchyEpsilon);
    requireInRange(t, "link_rays", o.linkRays);
    requireInRange(t, "closure_rays", o.closureRays);
    requireInRange(t, "max_links", o.maxLinks);
  }
  if (o.vertexOutput == RadiosityVertexOutput::FinalGather) {
    requireInRange(t, "gather_rays", o.gatherRays);
    requireInRange(t, "gather_share_rings", o.gatherShareRings);
  }
  if (!(o.memoryBudgetMB > 0) || !std::isfinite(o.memoryBudgetMB))
    throw std::invalid_argument("memory_budget_mb must be a finite number of megabytes > 0");
  checkFormFactorSettings(o.formFactors);
  o.outside.check();
}

void checkRadiosityMemory(size_t patches, const RadiosityOptions& opt) {
  const double MB = 1048576.0, n = double(patches);
  const bool hierarchy = usesHierarchy(patches, opt);
  const double need = hierarchy ? n * (kSolverBytesPerPatch + 2.0 * kHierarchyBytesPerNode) : solverBaseBytes(patches, opt);
  if (need <= opt.memoryBudgetMB * MB) return;
  const bool hemicube = !hierarchy && opt.formFactors.method == FormFactorMethod::Hemicube;
  char b[600];
  std::snprintf(b, sizeof b,
                "memory_budget_mb = %g is too small: %zu patches need about %.0f MB for %s%s (%.0f bytes per patch%s) "
                "before anything is computed; raise memory_budget_mb to at least %.0f, or use fewer patches%s",
                opt.memoryBudgetMB, patches, std::ceil(need / MB),
                hierarchy ? "the scene, the ray-casting structure and the cluster hierarchy (hierarchical solver"
                          : "the scene, the ray-casting structure, the solver's vectors and a form-factor row per "
                            "thread",
                hemicube ? ", each with the buffers of a hemicube (flat solver" : (hierarchy ? "" : " (flat solver"),
                need / std::max(n, 1.0),
                hierarchy ? "; the links take what is left)"
                          : "; the form-factor matrix takes what is left, else it is computed on the fly)",
                std::ceil(need / MB) + 1.0, hemicube ? " or a lower hemicube resolution" : "");
  throw std::invalid_argument(b);
}

}  // namespace gi
