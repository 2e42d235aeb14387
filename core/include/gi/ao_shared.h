// Ambient occlusion (and obscurance) shared between neighbouring vertices.
//   AO(p_i) ~ S_h(i) = sum_{j in A_h(i)} sum_k f_jk / sum_{j in A_h(i)} n_j
// Every vertex j casts its own n_j rays (exactly the per-vertex estimator's
// first n_j rays, values f_jk in [0,1]); A_h(i) is vertex i with the
// vertices up to h mesh rings away whose normals lie within a tolerance of
// n_i (grown only through such vertices, so it stops at creases and never
// reaches the other side of a thin sheet). The scale h is chosen per vertex
// by Lepski's method (Lepski 1991; Goldenshluger and Nemirovski 1997, the
// "intersection of confidence intervals"): h grows while the pooled estimate
// stays within gamma standard errors of every smaller scale's,
//   |S_h - S_h'| <= gamma sqrt(v (1/N_h' - 1/N_h))  for all h' < h,
// with N_h the rays pooled, v = p~(1 - p~) and p~ = (K_h + 1)/(N_h + 2) (the
// posterior mean under a uniform prior: never a zero variance after rays
// that all agreed). Var(S_h - S_h') = v (1/N_h' - 1/N_h) holds for nested
// pools of rays with a common variance v. So a neighbourhood stops growing
// where its occlusion differs from the vertex's by more than the rays can
// explain: at creases, contact shadows and thin features it stays small.
//
// Error accounting. The rays of different vertices are independent (each
// vertex's sequence is keyed by the vertex), so the pooled estimate's
// variance is that of N_h independent values in [0,1] with mean p:
// at most p (1 - p) / N_h (Bhatia and Davis 2000: a variable in [0,1] with
// mean p has variance <= p (1 - p); equality for AO's 0/1 values). The
// reported standard error is sqrt(v / N_h): every shared ray counts once, in
// every vertex that pools it. What is not counted is the bias of pooling,
// which the test above keeps below what the pooled rays can detect (tests:
// errors against the independent reference over all vertices, and at
// creases, contact areas and thin features apart). With a target error,
// vertices whose pooled standard error exceeds it cast more rays (doubling
// their own count) and everything near them is pooled again, until every
// vertex meets the target or reaches the maximum ray count.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi {

// Vertex adjacency from the usable faces (compressed rows, no duplicates).
struct VertexGraph {
  std::vector<uint32_t> offset;  // vertexCount + 1
  std::vector<uint32_t> nbr;
  static VertexGraph build(const Scene& s);
  size_t degree(uint32_t v) const { return offset[v + 1] - offset[v]; }
};

// One vertex's own rays: how many, the sum of their values, the sum of the
// unoccluded directions (bent normals).
struct VertexRays {
  uint32_t n = 0;
  double sum = 0.0;
  glm::vec3 bent{0.f};
};

struct PoolOptions {
  int maxRings = 3;           // largest neighbourhood, in mesh rings
  float normalCos = 0.9848f;  // cos of the normal tolerance (10 degrees)
  double gamma = 2.0;         // Lepski's threshold in standard errors
};

struct Pooled {
  float value = 0.f, stdError = 0.f;
  uint32_t rays = 0;      // rays pooled (N_h)
  uint32_t vertices = 0;  // vertices pooled
  int rings = 0;          // chosen scale h
  glm::vec3 bent{0.f};    // pooled unoccluded directions (not normalised)
};

// Per-thread scratch for the neighbourhood search.
struct PoolScratch {
  std::vector<uint32_t> stamp;
  uint32_t now = 0;
  std::vector<uint32_t> frontier, next;
};

// Pools vertex i with its neighbours. `poolable[j]` = 0 keeps j out (no rays
// of its own: open, duplicate or invalid vertices).
Pooled poolVertex(uint32_t i, const VertexGraph& g, const std::vector<glm::vec3>& normals,
                  const std::vector<VertexRays>& rays, const std::vector<uint8_t>& poolable, const PoolOptions& o,
                  PoolScratch& scratch);

}  // namespace gi
