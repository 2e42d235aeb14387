// Ambient occlusion of one vertex by adaptive strata.
//   AO(p) = 1/pi ∫_H V(p, w) cos(theta) dw = ∫_[0,1)^2 V(p, w(x, y)) dx dy,
//   w(x, y) = (sqrt(x) cos 2 pi y, sqrt(x) sin 2 pi y, sqrt(1 - x))
// in the vertex's frame (Malley's method in polar form: uniform (x, y) give
// cosine-weighted directions, so the cell areas are the cosine-weighted
// solid angles over pi). The square is cut into R rows of x (rows of
// elevation: the last row holds the horizon; thinner towards it, x_i =
// 1 - (1 - i/R)^1.25) and C = 2R columns of y (azimuth), and each stratum
// gets one jittered sample (Cook 1986,
// "Stochastic sampling in computer graphics", ACM TOG 5(1)). Visibility is a
// step function, so only strata crossed by an occlusion edge carry
// variance; a stratum is split into its four quarters when one of the pairs
// of its opposite neighbours (above and below, left and right, the two
// diagonals) disagree, an occlusion edge then likely crossing it (adaptive
// refinement where neighbouring samples differ, as in Mitchell 1987,
// "Generating antialiased images at low sampling densities", SIGGRAPH). The
// quarter holding the stratum's sample keeps it; the other three get one
// jittered sample each. The row beyond the horizon is the tangent plane,
// counted occluded; the row above the zenith row is that row half a turn
// away (the cells meet at the pole); columns wrap.
//
// Unbiased, whatever the split rule: a stratum's split is decided by other
// strata's samples only, which are independent of its own, so given the
// decision its sample and its quarters' samples stay uniform in their cells
// (the kept sample, given the quarter it fell in, is uniform in that
// quarter), and each cell's mean is an unbiased estimate of its share.
//   AO ~ sum over strata s of A_s (V_s, or the mean of its quarters' V if split),
// A_s = (x_{i+1} - x_i)/C in row i. Its variance is sum_s A_s^2 Var_s; with one sample per stratum
// Var_s is estimated by collapsing strata in pairs (Cochran 1977, "Sampling
// Techniques", 3rd ed., ch. 5A, collapsed strata, one unit per stratum): two unsplit
// neighbours in a row (columns 2m and 2m + 1, of one area A) count
// A^2 (V_a - V_b)^2, whose mean is A^2 (Var_a + Var_b + (mu_a - mu_b)^2),
// an upper bound; quarters likewise in pairs, (A/4)^2 (V_a - V_b)^2; an
// unsplit stratum whose partner was split counts A^2 (V_s - mean of the
// partner's quarters)^2; and at least (1/n)^2 / 4 in all.
// The bound misses what no sample saw (an occluder thinner than a stratum
// that two partners both miss), as any sample-based estimate must.
//
// To a target standard error (strataOcclusionToTarget): rounds of ever
// finer grids, the first of about min_rays strata, each next one every
// stratum of the last cut into its four quarters (its row halved in x, its
// column in y). A quarter keeps the ray that lies in it (the stratum's
// own, or the one cast for it when the stratum was split), so a round casts
// only the empty quarters' rays and its own splits, and the finest grid's
// estimate uses every ray cast (the same rays a fixed grid of that size
// would cast, less the row spacing: halved rows instead of x_i's power).
// Still unbiased: a kept ray, given the quarter it lies in, is uniform in
// it; the empty quarters get fresh ones; so every stratum of the new grid
// holds one uniform ray independent of the others', and its split is again
// decided by its neighbours' rays only. How many rounds: a pilot, rounds on
// a key of its own until its standard error is at most twice the target
// (within a quarter of max_rays), predicts them, each round taken to divide
// the error by 4^0.75; the result's rounds run on the vertex's key without
// reading their own estimates, and the pilot is left out (gi/sampling.h,
// kPilotMargin: rounds that stopped at the first grid meeting the target
// biased the mean low where light comes through a small opening). A round
// runs only if, with every new stratum split, it fits in what max_rays
// leaves (computeAmbient refuses a max_rays below twice the first round's
// worst case, 4 rays a stratum).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/raycaster.h"
#include "gi/sampling.h"

namespace gi {

struct StrataGrid {
  int rows = 8, cols = 16;
  // About n strata: R rows and 2R columns, R = round(sqrt(n / 2)), at least 1.
  static StrataGrid forRays(int n);
  int strata() const { return rows * cols; }
};

struct StrataEstimate {
  double value = 0.0, variance = 0.0;
  int rays = 0;                    // rays cast
  bool capped = false;             // to a target: a round the pilot asked for would have passed max_rays
  glm::vec3 bent{0.f};             // sum of the open samples' directions times their cells' areas
};

// One vertex: rays from org (tnear 0, tfar), directions in frame; key seeds
// the jitter (the same key gives the same rays and result, on any thread).
StrataEstimate strataOcclusion(const RayCaster& caster, uint32_t key, const glm::vec3& org, const Frame& frame,
                               float tfar, StrataGrid grid);

struct StrataTarget {
  double target = 0.01;            // the standard error to reach
  int minRays = 32, maxRays = 4096;
};

// One vertex, rounds until the target (above); its first round is
// strataOcclusion with the same key and a grid of about minRays strata.
StrataEstimate strataOcclusionToTarget(const RayCaster& caster, uint32_t key, const glm::vec3& org,
                                       const Frame& frame, float tfar, const StrataTarget& t);

// The rays a vertex casts when every ray is open (the tangent plane below
// the horizon row splits that row's strata: 3 more rays a column), with a
// fixed grid and to a target; the open-vertex proof pays where this is
// large.
int strataRaysWhenOpen(StrataGrid grid);
int strataRaysWhenOpen(const StrataTarget& t);

// The last grid estimated on this thread (by strataOcclusion, or the last
// round of strataOcclusionToTarget), for checks: the rows' bounds in x
// (rows + 1), the columns, and per stratum (row-major) its base ray's
// direction and whether that ray was kept from the coarser grid.
struct StrataGridView {
  int rows = 0, cols = 0;
  std::vector<float> rowX;
  std::vector<glm::vec3> dirs;
  std::vector<uint8_t> kept;
};
StrataGridView lastStrataGrid();

}  // namespace gi
