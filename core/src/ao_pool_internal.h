// Pooling for the shared estimators (gi/ao_shared.h), between the pooling
// of one vertex (ao_pool.cpp: poolVertex, poolMeans) and the shared AO
// estimator's lists of rings (ao_shared.cpp): the weighted sums of a pool,
// its first-order fit, Lepski's choice of scale and the breadth-first rings.
// Both ways of listing a vertex's rings go through chooseScale in the same
// order, so they give the same bits.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/ao_shared.h"
#include "gi/sampling.h"

namespace gi::pooling {

// Weighted sums of one pool for the first-order fit f(d) = a + g.d over the
// tangent-plane offsets d of its vertices (weights: their ray counts).
struct PoolSums {
  double W = 0, Y = 0;            // sum n, sum of ray values
  double X[2] = {0, 0};           // sum n d
  double XX[3] = {0, 0, 0};       // sum n d d^T (xx, xy, yy)
  double XY[2] = {0, 0};          // sum d y (y = the vertex's sum of ray values)
  double VW = 0;                  // sum n var (unbounded values)
  void add(double n, double y, double dx, double dy, double var) {
    W += n; Y += y; VW += n * var;
    X[0] += n * dx; X[1] += n * dy;
    XX[0] += n * dx * dx; XX[1] += n * dx * dy; XX[2] += n * dy * dy;
    XY[0] += dx * y; XY[1] += dy * y;
  }
};

// The same sums for the vertices' sums of unoccluded directions b (bent
// normals), fitted like y component by component over PoolSums' design.
struct BentSums {
  double B[3] = {0, 0, 0};                   // sum b
  double BX[2][3] = {{0, 0, 0}, {0, 0, 0}};  // sum d b
  void add(const glm::vec3& b, double dx, double dy) {
    for (int c = 0; c < 3; ++c) {
      B[c] += b[c];
      BX[0][c] += dx * b[c]; BX[1][c] += dy * b[c];
    }
  }
  BentSums& operator+=(const BentSums& o) {
    for (int c = 0; c < 3; ++c) {
      B[c] += o.B[c];
      BX[0][c] += o.BX[0][c]; BX[1][c] += o.BX[1][c];
    }
    return *this;
  }
};

// The fitted value at d = 0 and its variance over v: least squares of the
// vertices' means with weights n (their variances are v / n), i.e.
// a = Y/W - g.xbar, Var(a) = v (1/W + xbar^T C^-1 xbar) with C the centred
// second moments. Too few or collinear vertices for a slope: the mean.
struct Fit {
  double a = 0, varOverV = 0;
};
// The fit of any per-vertex sums y over the pool's design (sum y = Y,
// sum d y = XY).
inline Fit fitOf(const PoolSums& s, double Y, const double XY[2]) {
  Fit f;
  f.a = Y / s.W;
  f.varOverV = 1.0 / s.W;
  const double mx = s.X[0] / s.W, my = s.X[1] / s.W;
  const double cxx = s.XX[0] - s.W * mx * mx, cxy = s.XX[1] - s.W * mx * my, cyy = s.XX[2] - s.W * my * my;
  const double det = cxx * cyy - cxy * cxy, tr = cxx + cyy;
  if (!(tr > 0.0) || det <= 1e-3 * tr * tr) return f;  // no spread in some direction: no slope
  const double ry = XY[0] - mx * Y, rz = XY[1] - my * Y;
  const double gx = (cyy * ry - cxy * rz) / det, gy = (cxx * rz - cxy * ry) / det;
  f.a = Y / s.W - (gx * mx + gy * my);
  f.varOverV = 1.0 / s.W + (cyy * mx * mx - 2.0 * cxy * mx * my + cxx * my * my) / det;
  return f;
}
inline Fit fit(const PoolSums& s) { return fitOf(s, s.Y, s.XY); }

// The bent vector at d = 0 by the same fit, component by component (a mean
// unoccluded direction per ray, not normalised). A plain sum over the pool
// leans towards where its rays are: towards an occluder where the vertices
// nearer it cast more rays (an adaptive run), or where the pool is lopsided;
// measured on a floor beside a wall (tests/unit/test_bent_normals.cpp).
inline glm::vec3 fitBent(const PoolSums& s, const BentSums& bs) {
  glm::vec3 b(0.f);
  for (int c = 0; c < 3; ++c) {
    const double xy[2] = {bs.BX[0][c], bs.BX[1][c]};
    b[c] = float(fitOf(s, bs.B[c], xy).a);
  }
  return b;
}

// Own rays from which the reported bias is at least the pool's departure
// from them (chooseScale).
constexpr uint32_t kOwnRaysForBias = 256;

// Lepski's choice of scale for one vertex with own rays `own`. ring(h, grown,
// db) adds ring h's vertices (those pooled at scale h and not before) to
// grown and, where bent normals are asked for, their unoccluded directions
// to db, and returns how many there were (0: no ring h). Both ways of
// listing the rings (a search each time, or lists kept across rounds) go
// through here in the same order, so they give the same bits.
template <class Ring>
Pooled chooseScale(const VertexRays& own, const PoolOptions& o, Ring&& ring) {
  constexpr int kMaxScales = 65;
  double A[kMaxScales], VarV[kMaxScales], V[kMaxScales];  // estimate, its variance / v, and v, per accepted scale
  PoolSums sums;
  sums.add(own.n, own.sum, 0.0, 0.0, own.var);
  BentSums bent;
  bent.add(own.bent, 0.0, 0.0);
  Pooled p;
  p.vertices = 1;
  p.bent = own.bent;
  if (own.n == 0) return p;
  auto vOf = [&o](const PoolSums& s) {
    if (!o.bounded) return s.VW / s.W;  // the pool's mean sample variance
    return laplaceVariance(s.Y, s.W);  // never 0 after rays that all agreed
  };
  A[0] = sums.Y / sums.W;
  VarV[0] = 1.0 / sums.W;
  V[0] = vOf(sums);
  int chosen = 0;
  // Bounded values: the variance per ray reported is the largest of the
  // pools examined (the chosen scale, the larger ones pooled on the way and
  // the first one Lepski's rule refused). A small pool whose rays happened to
  // agree (no occluded ray among 56, under neighbours that do see occlusion)
  // would otherwise report a small error and stop the vertex early with a
  // value biased towards 1 (measured on a 470k-vertex scan at a target of
  // 0.02: +0.029 mean error on such vertices, errors 1.4 times the reported
  // ones in the band of AO 0.95 to 0.98).
  double vMax = V[0];
  const bool test = o.fixedRings < 0;
  const int R = std::min(test ? o.maxRings : o.fixedRings, kMaxScales - 1);
  for (int h = 1; h <= R; ++h) {
    PoolSums grown = sums;
    BentSums db;
    const uint32_t added = ring(h, grown, db);
    if (added == 0) break;
    const Fit f = fit(grown);
    const double v = vOf(grown);
    vMax = std::max(vMax, v);
    // Lepski: the new estimate within gamma standard errors of every smaller
    // scale's. For nested least-squares fits of one model the larger is the
    // efficient one, so Var(a_h' - a_h) = Var(a_h') - Var(a_h) (Hausman 1978).
    bool agree = true;
    for (int s = 0; s <= chosen && agree && test; ++s) {
      // Unbounded values: each estimate's variance with its own pool's
      // variance per ray (a vertex whose own rays all agreed, hidden under
      // an object, keeps its value however its neighbours' rays spread).
      const double var = o.bounded ? std::max(0.0, v * (VarV[s] - f.varOverV))
                                   : std::max(0.0, V[s] * VarV[s] - v * f.varOverV);
      agree = std::fabs(f.a - A[s]) <= o.gamma * std::sqrt(var);
    }
    if (test && !agree) break;
    chosen = h;
    A[h] = f.a;
    VarV[h] = f.varOverV;
    V[h] = v;
    sums = grown;
    p.vertices += added;
    bent += db;
  }
  if (chosen > 0) {
    // The fit extrapolates where a pool is lopsided: where the value's own
    // fit fell to 0 or below (clamped, no open direction to speak of) or the
    // fitted direction turns more than 30 degrees from the pool's plain mean
    // (the correction is a degree or two where the fit holds), the plain
    // mean stands, which lies within every pooled vertex's hemisphere.
    const glm::vec3 fitted = fitBent(sums, bent), plain(float(bent.B[0]), float(bent.B[1]), float(bent.B[2]));
    const float lf = glm::length(fitted), lp = glm::length(plain);
    p.bent = A[chosen] > 0.0 && lf > 0.f && glm::dot(fitted, plain) >= 0.866f * lf * lp ? fitted : plain;
  }
  p.value = float(o.bounded ? std::clamp(A[chosen], 0.0, 1.0) : std::max(A[chosen], 0.0));
  // The reported error also bounds the pool's bias: Lepski's rule lets
  // through a bias up to gamma times the smaller scales' noise, which is
  // invisible at one vertex but adds up along a band of vertices, and an
  // adaptive vertex stops on this error. The estimate of the bias is the
  // last accepted ring's step (from the vertex's own rays when one ring was
  // pooled), squared and added to the variance: a bound on the mean squared
  // error. On the floor along a thin disc's shadow edge (tests/unit/
  // test_ao_shared.cpp, target 0.02) it takes the mean (error / reported
  // error)^2 from 3.3 to 1.9; on scan_470k the rays per vertex that reach
  // RMS 0.0072 go from 18.6 to 18.3 (the largest step from any pool of one
  // ring or more instead: 1.9 and 19.1 rays; from the own rays too: 0.96
  // and 20.9).
  //
  // From kOwnRaysForBias own rays on, the bias counted is at least the
  // pool's whole departure from the vertex's own mean: those rays are
  // scrambled Sobol points, whose mean is then far more precise than the
  // binomial bound v / n that Lepski's rule compares with (6e-5 against
  // 5.4e-3 at 8,192 rays on a floor 0.1 from a wall), so the rule let pools
  // of two and three rings depart from it by their bias, ring by small ring:
  // at a target of 0.003 errors of -0.0033 under reported 0.0024, mean
  // (error / reported error)^2 3.7 to 4.9 over four seeds (an outside audit;
  // now 0.65 to 0.74). Below 256 own rays their mean's own noise would
  // dominate that departure: counted from 64 rays, scan_470k needs 18.1 rays
  // per vertex for RMS 0.0072 instead of 17.9; from 256, 17.9.
  const double mse = (o.bounded ? vMax : V[chosen]) * VarV[chosen];
  double step = chosen >= 1 ? std::fabs(A[chosen] - A[chosen - 1]) : 0.0;
  if (chosen >= 1 && own.n >= kOwnRaysForBias) step = std::max(step, std::fabs(A[chosen] - A[0]));
  p.stdError = float(std::sqrt(mse + step * step));
  p.rays = uint32_t(sums.W);
  p.rings = chosen;
  return p;
}

// Breadth-first rings around i through vertices that may be pooled with it
// (poolable, with rays, normal within the tolerance). startRings begins the
// search; each nextRing leaves the next ring in sc.frontier (empty: no more).
inline void startRings(uint32_t i, size_t vertexCount, PoolScratch& sc) {
  if (sc.stamp.size() != vertexCount) { sc.stamp.assign(vertexCount, 0); sc.now = 0; }
  if (++sc.now == 0) { std::fill(sc.stamp.begin(), sc.stamp.end(), 0); sc.now = 1; }
  sc.stamp[i] = sc.now;
  sc.frontier.assign(1, i);
}

// Who may join a vertex's rings (poolable, with rays) and its normal: read
// from the run's arrays, or from one packed array (one read per neighbour,
// for building every vertex's lists at once). Both give the same rings.
struct ArrayNodes {
  const std::vector<glm::vec3>& normals;
  const std::vector<VertexRays>& rays;
  const std::vector<uint8_t>& poolable;
  glm::vec3 normal(uint32_t u) const { return normals[u]; }
  bool usable(uint32_t u) const { return poolable[u] && rays[u].n != 0; }
  size_t size() const { return normals.size(); }
};
struct PackedNodes {
  struct Node {
    glm::vec3 n;
    uint32_t usable;
  };
  std::vector<Node> nodes;
  glm::vec3 normal(uint32_t u) const { return nodes[u].n; }
  bool usable(uint32_t u) const { return nodes[u].usable != 0; }
  size_t size() const { return nodes.size(); }
};

template <class Nodes>
void nextRing(uint32_t i, const VertexGraph& g, const Nodes& nodes, const PoolOptions& o, PoolScratch& sc) {
  const uint32_t now = sc.now;
  const glm::vec3 ni = nodes.normal(i);
  sc.next.clear();
  for (uint32_t v : sc.frontier)
    for (uint32_t k = g.offset[v]; k < g.offset[v + 1]; ++k) {
      const uint32_t u = g.nbr[k];
      if (sc.stamp[u] == now) continue;
      sc.stamp[u] = now;
      if (!nodes.usable(u) || glm::dot(nodes.normal(u), ni) < o.normalCos) continue;
      sc.next.push_back(u);
    }
  sc.frontier.swap(sc.next);
}

// Calls visit(h, u) for every vertex u of ring h = 1, ..., maxRings in the
// order poolVertex pools them, and returns the number of rings found (the
// search stops at an empty ring, as poolVertex does).
template <class Nodes, class Visit>
int searchRings(uint32_t i, const VertexGraph& g, const Nodes& nodes, const PoolOptions& o, int maxRings,
                PoolScratch& sc, Visit&& visit) {
  startRings(i, nodes.size(), sc);
  int h = 1;
  for (; h <= maxRings; ++h) {
    nextRing(i, g, nodes, o, sc);
    if (sc.frontier.empty()) break;
    for (uint32_t u : sc.frontier) visit(h, u);
  }
  return h - 1;
}

}  // namespace gi::pooling
