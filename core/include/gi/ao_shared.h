// Ambient occlusion (and obscurance) shared between neighbouring vertices.
//   AO(p_i) ~ a_h(i), the value at p_i of the first-order fit
//   f(d) = a + g.d to the vertices j in A_h(i): least squares over the
//   tangent-plane offsets d_j = T_i^T (p_j - p_i) of their means
//   y_j = sum_k f_jk / n_j with weights n_j.
// Every vertex j casts its own n_j rays (exactly the per-vertex estimator's
// first n_j rays, values f_jk in [0,1]); A_h(i) is vertex i with the
// vertices up to h mesh rings away whose normals lie within a tolerance of
// n_i (grown only through such vertices, so it stops at creases and never
// reaches the other side of a thin sheet). The gradient term g removes the
// first-order bias of pooling where the occlusion changes across the
// neighbourhood (the irradiance gradients of Ward and Heckbert 1992, fitted
// instead of estimated per ray); with fewer than three vertices spread in
// two directions the fit is the plain pooled mean. The scale h is chosen per
// vertex by Lepski's method (Lepski 1991; Goldenshluger and Nemirovski 1997,
// the "intersection of confidence intervals"): h grows while the fitted value
// stays within gamma standard errors of every smaller scale's,
//   |a_h - a_h'| <= gamma sqrt(v (c_h' - c_h))  for all h' < h,
// with Var(a_h) = v c_h, c_h = 1/N_h + xbar^T C^-1 xbar (N_h the rays pooled,
// xbar their weighted mean offset, C the centred second moments), v =
// p~(1 - p~), p~ = (K_h + 1)/(N_h + 2) (the posterior mean under a uniform
// prior: never a zero variance after rays that all agreed). For nested
// least-squares fits of one model the larger is the efficient one, so
// Var(a_h' - a_h) = Var(a_h') - Var(a_h) (Hausman 1978). A neighbourhood
// thus stops growing where its occlusion departs from a plane by more than
// the rays can explain: at creases, contact shadows and thin features it
// stays small. gamma = 1: at 2 the tests measured errors 1.6x the reported
// standard errors under a thin disc hovering over a floor.
//
// Error accounting with shared samples. The rays of different vertices are
// independent (each vertex's sequence is keyed by the vertex), so the fit's
// variance is v c_h with v bounding the variance of one ray's value (Bhatia
// and Davis 2000: a variable in [0,1] with mean p has variance <= p (1 - p);
// equality for AO's 0/1 values). The reported standard error is
// sqrt(v_max c_h), with v_max the largest v of the scales examined (every
// scale from the vertex's own rays up to the first that Lepski's rule
// refused): a small pool whose rays happened to agree cannot report a small
// variance while a wider one shows occlusion, which otherwise stops such a
// vertex early with a value biased towards 1 under a target error (measured
// on a 470k-vertex scan: +0.029 mean error there). The scales below the
// chosen one count too (the vertex's own few rays, whose v the prior keeps
// high): left out, the test scene's thin disc over a floor gives mean
// (error / reported error)^2 1.26 instead of 0.95 at a target of 0.02, and
// 1.07 instead of 0.75 at 64 fixed rays (tests/unit/test_ao_shared.cpp), for
// the same error against rays on a 470k-vertex scan (RMS 0.0073 at 17.7 rays
// per vertex, against 0.0072 at 17.9). Every shared ray counts
// once in every vertex that pools it,
// weighted as the fit weights it, never more than the rays actually cast
// (c_h >= 1/N_h). Neighbouring vertices' errors are therefore correlated
// (they share rays); each vertex's own error is what is reported. The bias
// of pooling, which Lepski's rule keeps within gamma standard errors of the
// smaller scales, is counted by adding the square of the last accepted
// ring's step (A_h - A_{h-1}) to the variance (from 256 own rays, of the
// larger of it and the whole departure A_h - A_0 from the vertex's own
// mean, whose scrambled Sobol points are then far more precise than the
// binomial bound: at tight targets Lepski's rule otherwise let the pools
// drift from it ring by ring): a bias below each vertex's
// noise still adds up along a band of vertices (tests/unit/test_ao_shared.cpp:
// errors against an independent per-vertex reference over all vertices and
// apart at a crease with its contact shadow, a sphere resting on a floor, a
// thin disc over it and the floor along the disc's shadow edge; mean squared
// error / reported variance 0.19 to 0.65 there, and 1.85 along the shadow
// edge, 3.3 without the step). With a target error, vertices whose standard error exceeds it
// cast more rays (doubling their own count) and every vertex whose
// neighbourhood may contain one of them is pooled again, until every vertex
// meets the target or reaches the maximum ray count.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/run.h"
#include "gi/scene.h"
#include "gi/vertex_graph.h"
#include "gi/vertex_part.h"

namespace gi {

// One vertex's own rays: how many, the sum of their values, the sum of the
// unoccluded directions (bent normals).
struct VertexRays {
  uint32_t n = 0;
  double sum = 0.0;
  double var = 0.0;   // unbounded values (not PoolOptions::bounded): their sample variance
  glm::vec3 bent{0.f};
};

struct PoolOptions {
  int maxRings = 3;           // largest neighbourhood, in mesh rings
  float normalCos = 0.9848f;  // cos of the normal tolerance (10 degrees)
  double gamma = 1.0;         // Lepski's threshold in standard errors (tests: 2 lets pooling bias through)
  bool bounded = true;        // values in [0,1] (variance bound p(1-p)); else any >= 0, with VertexRays::var
  int fixedRings = -1;        // >= 0: pool exactly this many rings (no test), as chosen for another quantity
};

struct Pooled {
  float value = 0.f, stdError = 0.f;
  uint32_t rays = 0;      // rays pooled (N_h)
  uint32_t vertices = 0;  // vertices pooled
  int rings = 0;          // chosen scale h
  glm::vec3 bent{0.f};    // unoccluded directions at the vertex, fitted over the pool like the value (only its direction is used)
};

// Per-thread scratch for the neighbourhood search.
struct PoolScratch {
  std::vector<uint32_t> stamp;
  uint32_t now = 0;
  std::vector<uint32_t> frontier, next;
};

// Pools vertex i with its neighbours. `poolable[j]` = 0 keeps j out (no rays
// of its own: open, duplicate or invalid vertices).
Pooled poolVertex(uint32_t i, const VertexGraph& g, const std::vector<glm::vec3>& positions,
                  const std::vector<glm::vec3>& normals, const std::vector<VertexRays>& rays,
                  const std::vector<uint8_t>& poolable, const PoolOptions& o, PoolScratch& scratch);

// Pooling for estimates that are means of unbounded values, such as the
// final gather of a radiosity solution (irradiance, RGB): each vertex's own
// estimate means[v] from lum[v].n rays, whose luminances have the sum
// lum[v].sum and the sample variance lum[v].var. The scale is chosen on the
// luminance, as above with v the pool's n-weighted mean variance, except
// that Lepski's rule compares two scales with each one's own v,
// Var(a_h' - a_h) = v_h' c_h' - v_h c_h (a vertex whose own rays all agreed,
// hidden under an object, then keeps its value however its neighbours'
// rays spread), and each channel is fitted at that scale with the same
// weights. For quasi-Monte Carlo rays the variance per ray over n
// overstates the error of their mean, so Lepski's rule lets through
// differences somewhat larger than the noise actually left: near a
// discontinuity of the pooled quantity (the edge of an object just above
// the surface) a pool may carry some of it (tests/unit/test_final_gather.cpp
// measures both sides). Vertices with
// lum[v].n = 0 neither pool nor are pooled (they keep means[v]). A split
// run (part not whole) exchanges every vertex's sums through
// part.sumOverParts first, so the pools are the whole run's; each part
// pools its own vertices. Adds the mean pool size to `stats`.
std::vector<glm::vec3> poolMeans(const Scene& s, const std::vector<glm::vec3>& normals,
                                 const std::vector<glm::vec3>& means, const std::vector<VertexRays>& lum,
                                 const PoolOptions& o, const VertexPart& part, RunStats* stats = nullptr);

}  // namespace gi
