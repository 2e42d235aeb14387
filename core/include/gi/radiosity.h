// The radiosity method over the triangles of a scene (Goral et al. 1984;
// Cohen and Greenberg 1985):
//   B_i = E_i + rho_i sum_j F_ij B_j          (RGB, W/m^2)
// with form factors F_ij by one of three methods (gi/form_factors.h: Monte
// Carlo rays from each patch, the analytic point-to-polygon factor, or a
// hemicube), the direct light apart (gi/direct.h), solved by Jacobi,
// Gauss-Seidel or progressive refinement (Cohen et al. 1988: shoot the patch
// with the most unshot power). Rows are sparse; only non-zero factors are
// stored, or computed on the fly beyond the memory budget.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "gi/direct.h"
#include "gi/form_factors.h"
#include "gi/hierarchical.h"
#include "gi/memory_limit.h"  // workerThreads
#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/refine.h"
#include "gi/run.h"
#include "gi/scene.h"
#include "gi/sky.h"
#include "gi/vertex_part.h"

namespace gi {

enum class RadiositySolver { Auto, Jacobi, GaussSeidel, Progressive, Hierarchical };
inline constexpr auto kRadiositySolvers = makeEnumTable<RadiositySolver>({
    {RadiositySolver::Auto, "Auto", "auto"},
    {RadiositySolver::Jacobi, "Jacobi", "Jacobi"},
    {RadiositySolver::GaussSeidel, "Gauss-Seidel", "Gauss-Seidel"},
    {RadiositySolver::Progressive, "Progressive refinement", "progressive refinement"},
    {RadiositySolver::Hierarchical, "Hierarchical", "hierarchical with clustering"},
});
// Auto takes the hierarchical solver (gi/hierarchical.h) from this many patches on.
inline constexpr size_t kHierarchicalAutoPatches = 50000;
enum class RadiosityVertexOutput { FinalGather, InterpolatedIndirect, PatchAverage };
inline constexpr auto kRadiosityVertexOutputs = makeEnumTable<RadiosityVertexOutput>({
    {RadiosityVertexOutput::FinalGather, "Final gather", "final gather"},
    {RadiosityVertexOutput::InterpolatedIndirect, "Interpolated indirect", "interpolated indirect"},
    {RadiosityVertexOutput::PatchAverage, "Patch average", "patch average"},
});

struct RadiosityOptions {
  // Method, rays, points, resolution and views (formFactorSettings), and the
  // filter's one seed: it keys the form-factor rays and also the shadow rays
  // and the final gather.
  FormFactors::Settings formFactors;
  int lightSamples = 256;         // shadow rays per patch (and per vertex) for the direct light; as many
                                  // again for the sky and for the sun, each
  SkySun outside;                 // sky and sun: emitters outside the scene (gi/sky.h)
  RadiositySolver solver = RadiositySolver::Auto;
  int bounces = -1;               // -1: iterate to the tolerance; k >= 0: exactly k sweeps (0 = direct light only)
  double tolerance = 1e-4;        // on the relative residual / unshot power
  int maxIterations = 0;          // sweeps (Jacobi, Gauss-Seidel) or shots per patch count (progressive);
                                  // 0: automatic, from the largest reflectance (autoIterations)
  double memoryBudgetMB = 1024;   // full sparse F while it fits; else progressive with rows on the fly
  double hierarchyEpsilon = 1e-4; // hierarchical: BF refinement threshold (fraction of the power leaving surfaces)
  int linkRays = 4;               // hierarchical: visibility rays per link
  int closureRays = 64;           // hierarchical: rays per patch bounding its links' sum (0: off)
  double maxLinks = 0;            // hierarchical: links at most (refined best first where it binds); 0: no cap
  RadiosityVertexOutput vertexOutput = RadiosityVertexOutput::FinalGather;
  int gatherRays = 256;           // final-gather rays per vertex
  int gatherShareRings = 0;       // final gather: neighbourhood (mesh rings) whose rays a vertex may pool; 0: none
  bool refine = false;            // adaptive mesh refinement (solveRadiosityAdaptive)
  RefineOptions refinement;       // its limits, thresholds and seed (RefineOptions::fromParams)
  VertexPart vertices;            // which vertices' final gather to compute (a split run; the patch
                                  // solution is computed whole); the others are left 0
  // Course outputs (radiosity_course.cpp). The ambient term of progressive
  // refinement (Cohen et al. 1988) for display: B_i + rho_i A, with A the
  // unshot radiosity spread over all patches and reflected 1 / (1 - rho_avg)
  // times; off, B is the physical value of the shots made so far.
  bool ambientTerm = false;
  std::vector<int> snapshotSteps;  // steps (sweeps; shots for progressive) after which B is kept per vertex
  std::string residualCsv;         // where runFilter writes the residual per step (empty: not written)
  std::string exportSystem;        // path prefix of the exported linear system (empty: none)
  static std::vector<ParamSpec> specs();
  static RadiosityOptions fromParams(const ParamValues& v);
};

struct RadiosityResult {
  // Per face: the radiosity of the part of the patch the scene sees (a flat
  // solver's patches partly buried under other surfaces, gi/patch_seen.h).
  std::vector<glm::vec3> B;
  std::vector<float> seenShare;     // per face, that part's share of its area; empty: all of every face
  std::vector<glm::vec3> Bvertex;   // per vertex (see RadiosityOptions::vertexOutput)
  // Per vertex, its direct part E + rho H_direct (luminaires, point light,
  // sky and sun): at the vertex where the vertex values compute it there,
  // the patch average of the faces' with patch-average values. A two-pass
  // view replaces it by ray-traced direct light.
  std::vector<glm::vec3> Bdirect;
  std::vector<glm::vec3> Rgather;   // per face: reflected radiosity the vertices gather from
  std::vector<glm::vec3> Hindirect; // per face: irradiance from Rgather
  // A fixed bounce count K: per face, the reflected radiosity after m
  // bounces, R^(m) = rho H_direct + rho F R^(m-1) (R^(1) = rho H_direct,
  // sky and sun included), at index m - 1 for the m that the final gather's
  // near hits read (keptBounce), the others empty.
  std::vector<std::vector<glm::vec3>> Rbounces;
  int iterations = 0;
  double residual = 0.0;            // relative, at the end
  std::vector<double> residualHistory;  // per sweep or per shot (progressive: unshot power fraction)
  glm::vec3 ambient{0.f};           // the ambient term added to B (RadiosityOptions::ambientTerm), else 0
  glm::vec3 ambientRho{0.f};        // the area mean reflectance it assumes (its 1 / (1 - rho) of bounces)
  // B per vertex (patch average, with the ambient term when it is on) after
  // each requested step; a step the solve did not reach holds the final state.
  struct Snapshot {
    int step = 0;          // as requested
    int reached = 0;       // the step the values are from
    double residual = 0;   // after that step (step 0: before any; progressive: the unshot fraction)
    std::vector<glm::vec3> Bvertex;
  };
  std::vector<Snapshot> snapshots;
  // The linear system as Matrix Market files (RadiosityOptions::exportSystem):
  // (file name suffix, text), see linearSystemFiles.
  std::vector<std::pair<std::string, std::string>> exports;
  RunStats stats;
};

// The final gather relights a near hit and gathers again from it, down to
// kGatherNearLevels levels (radiosity_vertices.cpp): with K fixed bounces it
// reads R^(K), R^(K-1) and R^(K-2) there, and R^(1) (to take a patch's own
// indirect part, R^(m) - R^(1) = rho F R^(m-1)).
constexpr int kGatherNearLevels = 2;
inline bool keptBounce(int m, int K) { return m >= 1 && m <= K && (m == 1 || m >= K - kGatherNearLevels); }

RadiosityResult solveRadiosity(const Scene& s, const RayCaster& caster, const RadiosityOptions& opt,
                               const Progress& progress = Progress(nullptr));

// The memory memory_budget_mb must cover besides the form-factor matrix, in
// bytes: per patch, the scene's face arrays, the ray-casting structure and
// the solver's vectors and vertex output (kSolverBytesPerPatch; measured 330
// at peak on a box of 1.08 million patches, the matrix apart; a fixed bounce
// count keeps up to 4 more vectors for the final gather, 48), and per
// worker thread the scratch of one form-factor row (a dense row of n values;
// a hemicube's buffers, 144 MB at resolution 4096).
inline constexpr double kSolverBytesPerPatch = 400;
double solverBaseBytes(size_t patches, const RadiosityOptions& opt);
// Whether solveRadiosity runs the hierarchical solver (asked for, or Auto
// from kHierarchicalAutoPatches on).
bool usesHierarchy(size_t patches, const RadiosityOptions& opt);
// Refuses, before anything large is allocated (the front ends call it
// before building the ray-casting structure), a run whose fixed memory
// exceeds memory_budget_mb: per patch kSolverBytesPerPatch, and the cluster
// tree (2 kHierarchyBytesPerNode) for the hierarchical solver or a
// form-factor row per thread for the flat ones (solverBaseBytes). Throws
// std::invalid_argument with one sentence: the megabytes needed, the budget
// and what to change. What is left of the budget bounds the hierarchy's
// links or the flat form-factor matrix (kept in memory only if it fits).
void checkRadiosityMemory(size_t patches, const RadiosityOptions& opt);
// Refuses (std::invalid_argument) options a library caller set outside the
// parameter table's ranges (rays, bounces, tolerance, iterations, links,
// the sky and sun), a memory budget that is not a positive number, and form
// factors without rays, points or cells: what the front ends' checks
// refuse, and what gave NaN vertices (gather_rays 0) or the direct light
// alone (a NaN tolerance). solveRadiosity calls it first.
void checkRadiosityOptions(const RadiosityOptions& opt);

// Sweeps enough for the residual to fall below `tolerance` when each sweep
// shrinks it at least by the factor r (the spectral radius bound: the
// largest reflectance, times the largest row sum of F if above 1):
// 1.5 ln(tolerance) / ln(r), at least 10, at most 1,000,000.
int autoIterations(double r, double tolerance);

// Solvers on precomputed rows and direct irradiance (exposed for tests;
// maxIterations 0 = automatic).
RadiosityResult solveWithRows(const Scene& s, const std::vector<FormFactorRow>& rows, const std::vector<glm::vec3>& Hd,
                              RadiositySolver solver, int bounces, double tolerance, int maxIterations,
                              const Progress& progress);
// The same with the solver, bounces, tolerance, maximum iterations, ambient
// term and snapshot steps of `opt`.
RadiosityResult solveWithRows(const Scene& s, const std::vector<FormFactorRow>& rows, const std::vector<glm::vec3>& Hd,
                              const RadiosityOptions& opt, const Progress& progress);

// The residual per step as CSV ("step,residual"; progressive refinement: the
// unshot power, else the change of a sweep, both relative to the emitted
// power), and its log line: the residual after steps 1, 2, 4, 8, ... and the last.
std::string residualCsv(const RadiosityResult& r);
std::string residualLogNote(const RadiosityResult& r);
// The system the filter solved, for a solver of one's own (Matrix Market,
// 1-based): _F.mtx the form factors F (coordinate, n x n, F_ij in row i),
// _E.mtx the emitted radiosity E, _rho.mtx the reflectance, _Esys.mtx the
// source with the direct light exact, E + rho (H_direct - F E), _B.mtx the
// filter's patch radiosity (each dense, n x 3, RGB in W/m^2), _area.mtx the
// patch areas (n x 1, the mesh's units squared). B = Esys + rho F B has the
// filter's B as its solution; B = E + rho F B is the classical system, with
// the direct light from F as well.
std::vector<std::pair<std::string, std::string>> linearSystemFiles(const std::vector<FormFactorRow>& rows,
                                                                   const std::vector<double>& area,
                                                                   const std::vector<glm::vec3>& E,
                                                                   const std::vector<glm::vec3>& rho,
                                                                   const std::vector<glm::vec3>& Hd,
                                                                   const std::vector<glm::vec3>& B);
// Parses snapshot_steps ("0, 10, 100"): at most 64 steps >= 0; throws
// std::invalid_argument with one sentence otherwise.
std::vector<int> parseSnapshotSteps(const std::string& text);

// Adaptive mesh refinement (refine.h): solve, mark the faces where the
// reflected radiosity jumps across an edge or a shadow boundary crosses,
// red-green subdivide them, solve again; up to refinement.maxDepth levels or
// refinement.maxPatches faces. Intermediate solves use patch averages at the
// vertices (their vertex values are not needed); the last one uses
// opt.vertexOutput. The stats say per level how many faces were refined and
// why refinement stopped. Deterministic for any thread count.
struct AdaptiveRadiosity {
  RefinedMesh mesh;        // the refined scene and where each face came from
  RadiosityResult result;  // on mesh.scene
};
using CasterFactory = std::function<std::unique_ptr<RayCaster>(const Scene&)>;
AdaptiveRadiosity solveRadiosityAdaptive(const Scene& s, const RadiosityOptions& opt,
                                         const Progress& progress = Progress(nullptr),
                                         const CasterFactory& makeCaster = nullptr);

}  // namespace gi
