// The reference's error bars (core/src/pathtrace.cpp): the variance pooled
// over a vertex's mesh ring.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/vertex_graph.h"

namespace gi::reference {

// The variance per path that a vertex's error bar uses: the larger of its
// own sample variance and the mean of its neighbourhood's. Light that only
// rare paths find (a caustic through glass, a light seen in a mirror: no
// shadow ray aims there) gives a sample variance whose distribution is
// heavily skewed: a vertex whose paths found that light once or never
// reports a small error while the light is missing from its estimate. On
// the Cornell box with a glass sphere and a mirror, 12% of the floor's
// vertices at 64 paths (475 of 3,852) and 2.3% at 2,048 were more than 4
// reported standard errors below a 32,768-path run (mean z^2 11 and 2.8).
// The neighbours receive nearly the same light, so their mean variance is a
// far better estimate of the vertex's; taking the larger keeps the vertex's
// own where the light changes across the ring (a shadow edge). What is
// pooled is the covariance of the irradiance H's three channels, the light
// arriving, which does not depend on the surface; a vertex's B = E + rho H
// takes the variance w^T C w of it, w the vertex's reflectance times the
// luminance weights, so a red wall is not given a blue light's error, and a
// black emitter's B = E keeps its error of 0 beside lit neighbours. The
// ring is two rings of neighbours, and further rings (up to 4) while it
// holds fewer than kPooledVertices traced vertices (a mesh's border or
// corner; an interior vertex of valence 6 has 19 within two). Measured on
// the same scene (mean z^2, |z| > 4): 64 paths 0.88 and 7 vertices, 256
// paths 0.58 and 1, 2,048 paths 0.65 and 0, adaptive to 5% 0.90 and 1 (2.2
// times the paths); on the plain Cornell box at 256 paths 0.83 (1.07 with
// the own variance), the error bars 3.5% wider at the median vertex, 32% at
// the 90th percentile.
constexpr uint32_t kPooledVertices = 10;  // beyond two rings, rings grow (up to 4) until they hold this many

// The covariance per path of H's three channels (rr, gg, bb, rg, rb, gb).
using Cov = std::array<double, 6>;

struct RingVariance {
  std::vector<Cov> mean;           // mean covariance over the traced vertices of the ring (the vertex's own included)
  std::vector<uint32_t> vertices;  // how many (1: the vertex alone)
};

// cov: 6 numbers per vertex (as Cov); paths: nv counts.
RingVariance ringVariance(const VertexGraph& g, const double* cov, const std::vector<double>& paths);

// w^T C w for the symmetric 3 x 3 matrix C: the variance of w . H.
double quadratic(const Cov& C, const glm::dvec3& w);

}  // namespace gi::reference
