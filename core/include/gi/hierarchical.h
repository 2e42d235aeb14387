// Hierarchical radiosity with clustering: the reflected radiosity R of
//   R_i = rho_i (H_direct,i + sum_j F_ij R_j)          (RGB, W/m^2)
// (the direct light apart, as in gi/radiosity.h) is transported along links
// between nodes of a cluster hierarchy over the triangles instead of between
// every pair of triangles (Hanrahan, Salzman and Aupperle 1991, "A rapid
// hierarchical radiosity algorithm"; clusters of patches as nodes above the
// input triangles: Smits, Arvo and Greenberg 1994, "A clustering algorithm
// for radiosity in complex environments"; Sillion 1995, "A unified
// hierarchical algorithm for global illumination with scattering volumes and
// object clusters"). A link p <- q carries F_pq, the area-mean form factor
// from the receiver node p to the source node q; it is kept when the power it
// can carry, A_p F_max(p, q) max_q R (BF refinement), is below epsilon times
// the power leaving all surfaces (emitted and reflected) and the two nodes'
// bounding spheres are apart, else the larger node is split. Every (triangle, triangle) pair is covered by exactly
// one link between their ancestors, so as epsilon -> 0 all links join
// triangles and the flat solution comes back. A sweep gathers on every link,
// pushes the gathered irradiance down to the triangles and pulls area means
// up (push-pull); sweeps (Jacobi) repeat to the tolerance, and the links are
// refined again with the solved R until no link needs splitting. Where a
// memory budget stops the refinement, the round is redone best first (the
// link that may carry the most power is split first), so the coarse links
// left are the weakest ones everywhere.
// Visibility: a link's F_pq is its unoccluded factor times the fraction of
// its rays between paired points of p and q that pass. Where q is a cluster
// the link remembers which rays passed, and the sweep gathers R at those
// rays' source points instead of q's area mean times that fraction: the
// unbiased estimate of (1/A_p) int int K V R_q when R and visibility
// vary together over q (the brighter triangles of a room are the less
// hidden ones; the area mean lost 1.2% of the absorbed power in the Cornell
// box, the sampled sources 0.4%, against epsilon 0).
// Closure: the links' factors are quadratures, so a triangle's row of them
// sums only approximately to the fraction G of its cosine-weighted
// hemisphere that meets the front of a surface (in a closed box of 768
// triangles, 0.94 to 1.06 at epsilon 1e-4; 0.90 to 1.12 at 1,536), and at
// high reflectance light is created or lost in proportion to 1 / (1 - rho):
// a closed box lit from its ceiling read 10% high at rho 0.99 and diverged
// at 0.999. Each triangle casts closureRays stratified rays to count G;
// where every ray of every triangle hits (a closed room) and no link needs
// visibility rays (no occluders), the links are balanced by row factors
// r_i on what each triangle gathers and column factors c_j on what it
// sends, alternately (Sinkhorn's iterative scaling of r F c, as in matrix
// balancing: Sinkhorn 1964, "A relationship between arbitrary positive
// matrices and doubly stochastic matrices"), so that every row (the
// furnace: a uniform R gives a uniform H) and every column (energy: all
// the power a triangle sends arrives) sums to 1. Elsewhere the links' sums
// stand (every variant tried did worse somewhere: hierarchical.cpp), and
// the energy balance against the rays' count of what escapes indicates how
// much light the links create or lose (not exactly: they are not
// reciprocal).
// Memory: O(n) nodes plus the links.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/scene.h"

namespace gi {

struct HierarchySettings {
  double epsilon = 1e-4;      // BF refinement threshold, fraction of the power leaving all surfaces
  int linkRays = 4;           // visibility rays per link
  double memoryBytes = 1e18;  // the links stop being refined beyond this (with a warning)
  double maxLinks = 1e18;     // and beyond this many links (refined best first, the strongest kept; a note)
  double enteringPower = 0;   // luminance power the sky and the sun bring onto the surfaces (gi/sky.h), local
                              // units; counts with the emitted power (Hd then holds their irradiance too)
  int closureRays = 64;       // rays per triangle counting what its row sums to (0: no closure, no energy balance;
                              // with occluders at most 8M in all, at least 4 a triangle: the energy account alone)
  uint32_t seed = 0;          // of those rays
  // Per triangle, the share of its area the scene sees (gi/patch_seen.h);
  // empty: all of every triangle. The solution is then the radiosity of
  // the seen parts: a node gathers at points on its seen part (the points
  // found open on its partly buried triangles, seenPoints, one list per
  // triangle or empty) and a source's mean is taken over its seen part.
  std::vector<float> seen;
  std::vector<std::vector<glm::vec3>> seenPoints;
};

struct HierarchicalSolution {
  std::vector<glm::vec3> R;     // per face: reflected radiosity (converged, or after the fixed sweeps)
  std::vector<glm::vec3> Rprev; // fixed bounces: the iterate before the last sweep (what vertices gather from)
  std::vector<glm::vec3> H;     // per face: indirect irradiance sum_j F_ij R_j (from Rprev when bounces are fixed)
  std::vector<std::vector<glm::vec3>> Rbounces;  // fixed bounces: as RadiosityResult::Rbounces
  int iterations = 0;
  double residual = 0;
  std::vector<double> residualHistory;
  RunStats stats;
};

// Hd: direct irradiance per face; bounces >= 0: exactly that many sweeps;
// else sweeps until the change is below tolerance x emitted power (at most
// maxIterations, 0: automatic). Deterministic for any thread count.
HierarchicalSolution solveHierarchical(const Scene& s, const RayCaster& caster, const std::vector<glm::vec3>& Hd,
                                       const HierarchySettings& set, int bounces, double tolerance, int maxIterations,
                                       const Progress& progress = Progress(nullptr));

// Bytes per node and per link the solver holds at its peak (for the memory
// plan): a node's geometry, its four per-sweep values and the triangles
// under its 16 source points (64 bytes; 16 before 5 December 2026, when
// only the first link_rays points could be a link's samples); a link's 16
// bytes twice while it is refined, with its ordering and ray count. With the
// radiosity solver's 400 per patch (two nodes per triangle): 407 MB for the
// 321k-triangle benchmark room with 2.6M links (before the sampled sources:
// 4 bytes less per link and 16 per node), measured peak 402 MB, then 48
// bytes more per node (31 MB there).
inline constexpr double kHierarchyBytesPerNode = 304;
inline constexpr double kHierarchyBytesPerLink = 56;

}  // namespace gi
