// Photon density estimates where the gather disk leaves the surface: the
// exact area of a triangle inside a ball (against closed forms and Monte
// Carlo), and the furnace box, whose creases and corners get the same
// B = E / (1 - rho) as its interior in every mode, a welded room's edges
// against the reference, and a caustic read at a crease.
#include <gtest/gtest.h>

#include <cmath>

#include "gi/color.h"
#include "gi/form_factor_analytic.h"
#include "gi/pathtrace.h"
#include "gi/photon.h"
#include "gi/sampling.h"
#include "gi/scenes.h"

using namespace gi;

namespace {

// 0 interior, 1 edge, 2 corner (|coordinate| = 0.5 on 1, 2 or 3 axes).
int kind(const Scene& s, size_t i) {
  const glm::dvec3 p = s.toWorld(s.positions[i]);
  int on = 0;
  for (int a = 0; a < 3; ++a) on += std::abs(std::abs(p[a]) - 0.5) < 1e-6;
  return on - 1;
}


// The furnace box: a closed cube of edge 1, n x n cells per face, every face
// emitting E = 1 with reflectance rho = 0.896. Radiosity is uniform, so
// B = E + rho B: B = E / (1 - rho) = 1 / 0.104 = 9.615, and every vertex
// sees irradiance H = B (E = 1 of it direct). `welded`: the faces share
// their edge and corner vertices (normals averaged there) instead of
// meeting as six separate sheets.
constexpr float kFurnaceRho = 0.896f;
const double kFurnaceB = 1.0 / (1.0 - double(kFurnaceRho));

// The scene's sheets joined at their common edges and corners (one vertex per position).
Scene weld(const Scene& in) {
  const scenes::SceneFile sf{in, {}};
  std::vector<glm::dvec3> pts;
  std::vector<uint32_t> id(sf.scene.vertexCount());
  for (size_t i = 0; i < id.size(); ++i) {
    const glm::dvec3 p = sf.scene.toWorld(sf.scene.positions[i]);
    size_t j = 0;
    while (j < pts.size() && glm::length(pts[j] - p) > 1e-9) ++j;
    if (j == pts.size()) pts.push_back(p);
    id[i] = uint32_t(j);
  }
  std::vector<glm::uvec3> tris;
  for (const auto& t : sf.scene.triangles) tris.push_back({id[t.x], id[t.y], id[t.z]});
  Scene s = Scene::fromAbsolute(pts, tris);
  s.rho = sf.scene.rho;
  s.emission = sf.scene.emission;
  return s;
}

Scene furnaceBox(int n, bool welded) {
  auto sf = scenes::closedBox(1.0, n, true);
  scenes::setUniform(sf, glm::vec3(kFurnaceRho), glm::vec3(1.f));
  return welded ? weld(sf.scene) : sf.scene;
}

// Mean B over the interior, edge and corner vertices.
struct ByKind {
  double mean[3] = {0, 0, 0};
  int count[3] = {0, 0, 0};
};
ByKind meanByKind(const Scene& s, const std::vector<glm::vec3>& B) {
  ByKind m;
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    const int k = kind(s, i);
    m.mean[k] += B[i].g;
    ++m.count[k];
  }
  for (int k = 0; k < 3; ++k) m.mean[k] /= std::max(1, m.count[k]);
  return m;
}

}  // namespace

// The furnace box in every photon-mapping mode: before the estimates divided
// by the area of the surface inside the gather sphere, the creases and
// corners (where a half or a quarter of the disk pi r^2 is on the vertex's
// faces) read about half and a quarter of the photon light (B = 5.3 and 3.2
// of 9.6 with all light from photons).
//
// 100k paths (about 1M photons stored: k = 256 gathers reach about 0.02 from
// a vertex, the cells are 0.25); progressive: 16 passes of 50k, the first
// radius from k = 64; no path cut (max_depth: rho^32 = 3% of B lies beyond
// 32 bounces). Expected values: the k-nearest estimate k Phi / A(r_k) has mean
// H k / (k - 1) (r_k the k-th photon's distance: A(r_k) lambda is Gamma(k)
// distributed for photons of equal power, as here where rho = q in Russian
// roulette), so the photon-estimated part of H carries the factor k / (k - 1):
//   all from photons:       B = E + rho H k / (k - 1)
//   direct apart, plain:    B = E + rho (E + (H - E) k / (k - 1))
//   final gather:           B = E + rho (E + rho H k / (k - 1))   (rho H = H - E)
//   progressive:            B = E / (1 - rho)  (consistent; 16 passes).
// Tolerances, 4 standard errors of each class's mean: a k-nearest estimate
// has relative noise 1 / sqrt(k) (Poisson), carried into B by the photon
// part's share f = (B - E - rho E) / B (0.80; 0.90 all from photons); corner
// and edge vertices of the sheets that meet there are counted as one
// (a final gather from a crease reads the same photons from each side) and
// a final gather's lookups are taken as fully correlated (one lookup's
// noise: 1 / sqrt(k)), so the class's standard error is f / sqrt(k n) with
// n = 8 corners, 12 (n - 1) edge points and 6 (n - 1)^2 interior vertices.
// Progressive photon mapping: relative noise 1 / sqrt(N) with N the mean
// accumulated photon count per vertex (reported), the same way.
TEST(PhotonMap, FurnaceBoxCreasesAndCorners) {
  const int n = 4;
  const double E = 1.0, rho = kFurnaceRho, B = kFurnaceB, H = B;
  const double independent[3] = {6.0 * (n - 1) * (n - 1), 12.0 * (n - 1), 8.0};
  const char* names[3] = {"interior", "edge", "corner"};
  for (bool welded : {false, true}) {
    const Scene s = furnaceBox(n, welded);
    auto caster = makeEmbreeCaster(s);
    for (int mode = 0; mode < 4; ++mode) {
      if (welded && mode > 1) break;  // welded: the density estimate, and the plain mode's creases
      SCOPED_TRACE(std::string(welded ? "welded, " : "sheets, ") +
                   (mode == 0 ? "all from photons" : mode == 1 ? "plain" : mode == 2 ? "final gather" : "progressive"));
      PhotonOptions o;
      o.photons = mode == 3 ? 50000 : 100000;
      o.kNearest = mode == 3 ? 64 : 256;
      o.maxDepth = 100000;
      o.directLight = mode != 0;
      o.finalGather = mode == 2;
      o.gatherRays = 64;
      o.progressive = mode == 3;
      o.passes = 16;
      o.lightSamples = 256;
      const VertexRadiometry r = computePhotonMap(s, *caster, o);
      const double k = o.kNearest, bias = k / (k - 1);
      const double expected = mode == 0 ? E + rho * H * bias
                              : mode == 1 ? E + rho * (E + (H - E) * bias)
                              : mode == 2 ? E + rho * (E + rho * H * bias)
                                          : B;
      const double share = mode == 0 ? rho * H / B : (B - E - rho * E) / B;
      const double count = mode == 3 ? r.stats.get("ppm_mean_photons_per_vertex") : k;
      ASSERT_GT(count, 16.0);
      const ByKind m = meanByKind(s, r.B);
      for (int c = 0; c < 3; ++c) {
        // Welded, plain: the edge and corner vertices (their faces turn 45 and
        // 55 degrees from their normals) take the final gather.
        const double want = welded && mode == 1 && c > 0 ? E + rho * (E + rho * H * bias) : expected;
        const double tol = 4.0 * share / std::sqrt(count * independent[c]);
        EXPECT_NEAR(m.mean[c] / want, 1.0, tol) << names[c] << ": " << m.mean[c] << " (" << m.count[c]
                                                << " vertices), expected " << want;
      }
    }
  }
}

// A room whose walls, floor and ceiling share their edge vertices (welded):
// a vertex on an edge has the mean of its faces' normals, and its value is
// the irradiance of that tilted plane (what the reference computes there,
// and radiosity). The k-nearest density estimate read the photons of both
// faces instead: the mean of the two planes' own irradiances near the edge,
// another quantity, which its blur hid at large radii and showed as they
// shrank (an outside check: a lamp-lit room's ceiling edge -12.9% at 2M
// photons, -15.6% at 20M; a window room's floor edge -4.5 to -7.8% at 100M).
// Vertices at a crease (a face more than 20 degrees from the vertex normal)
// now take a final gather of the photon map. Here a closed 2 m room, 8 x 8
// cells a side, rho 0.7, a 1 m square lamp in the middle of the ceiling:
// the ceiling's edge vertices (no direct light from a lamp in their own
// plane but what their tilted plane sees) against the path-traced
// reference (16,384 paths each), d = B / ref - 1 per vertex. The final
// gather's 1,024 light samples and 64 rays per vertex leave a standard error
// of the mean of d of about 0.5% (from d's spread over the 28 vertices, both
// noises); the mean must lie within 3% (4 of those and 1% for the
// estimate's blur), and its standard error below 1% (a noisier estimate
// cannot pass by its spread). Measured: +0.75% (standard error 0.54%);
// reading the density estimate as before, -7.7% (2.6%): fails both; since
// the near hits are relit (5 December 2026) +0.5% (0.7%). Progressive
// photon mapping hands the same vertices over since 5 December 2026 (4
// passes of 500,000 paths, the gather reading the first): +1.0% (0.5%);
// with its hand-over switched off, -9.0% (1.3%).
TEST(PhotonMap, WeldedRoomEdgesMatchTheReference) {
  auto sf = scenes::closedBox(2.0, 8, true);
  scenes::setUniform(sf, glm::vec3(0.7f), glm::vec3(0.f));
  Scene s = weld(sf.scene);
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const auto& t = s.triangles[f];
    const glm::dvec3 c = s.toWorld((s.positions[t.x] + s.positions[t.y] + s.positions[t.z]) / 3.f);
    if (c.z > 0.999 && std::abs(c.x) < 0.5 && std::abs(c.y) < 0.5) s.emission[f] = glm::vec3(10.f);
  }
  auto caster = makeEmbreeCaster(s);
  auto edge = std::make_shared<std::vector<uint8_t>>(s.vertexCount(), 0);
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    const glm::dvec3 p = s.toWorld(s.positions[i]);
    const bool onX = std::abs(std::abs(p.x) - 1) < 1e-6, onY = std::abs(std::abs(p.y) - 1) < 1e-6;
    (*edge)[i] = p.z > 1 - 1e-6 && onX != onY;  // the ceiling's edges, not its corners
  }
  PathTraceOptions po;
  po.samplesPerVertex = 16384;
  po.tracedSelected = true;
  po.selectedVertices = edge;
  const PathTraceResult ref = pathTrace(s, *caster, po);
  for (bool progressive : {false, true}) {
    PhotonOptions o;
    o.photons = progressive ? 500000 : 2000000;
    o.progressive = progressive;
    o.passes = 4;
    o.lightSamples = 1024;
    const VertexRadiometry r = computePhotonMap(s, *caster, o);
    double sum = 0, sum2 = 0;
    int n = 0;
    for (size_t i = 0; i < s.vertexCount(); ++i) {
      if (!(*edge)[i]) continue;
      const double d = double(luminance(r.B[i])) / double(luminance(ref.B[i])) - 1.0;
      sum += d, sum2 += d * d, ++n;
    }
    ASSERT_EQ(n, 4 * 7);
    const double mean = sum / n, sem = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / (n - 1));
    std::printf("welded room, ceiling edge, %s: %d vertices, photon map / reference - 1 = %+.4f (standard error "
                "%.4f)\n",
                progressive ? "progressive (4 passes of 500k)" : "k nearest", n, mean, sem);
    EXPECT_LT(sem, 0.01);
    EXPECT_LT(std::fabs(mean), 0.03);
  }
}

// Closed forms: a triangle wholly inside (its own area), a ball inside a
// large triangle's interior (the disk pi (r^2 - h^2) it cuts from the plane),
// centred on an edge (half of it), at a right-angled corner (a quarter), at
// the apex of a 60-degree corner (a sixth), and out of reach (0).
TEST(PhotonSurface, TriangleBallAreaClosedForms) {
  const glm::dvec3 a(0, 0, 0), b(10, 0, 0), c(0, 10, 0);
  EXPECT_NEAR(triangleBallArea(a, b, c, {1, 1, 0}, 100.0), 50.0, 1e-9);
  const double r = 0.5, h = 0.3, disk = M_PI * (r * r - h * h);
  EXPECT_NEAR(triangleBallArea(a, b, c, {2, 2, h}, r), disk, 1e-9);
  EXPECT_NEAR(triangleBallArea(a, b, c, {2, 2, -h}, r), disk, 1e-9);
  EXPECT_NEAR(triangleBallArea(a, b, c, {3, 0, h}, r), disk / 2, 1e-9);
  EXPECT_NEAR(triangleBallArea(a, b, c, {0, 0, h}, r), disk / 4, 1e-9);
  EXPECT_NEAR(triangleBallArea(a, {10, 0, 0}, {5, 5 * std::sqrt(3.0), 0}, {0, 0, 0}, r), M_PI * r * r / 6, 1e-9);
  EXPECT_EQ(triangleBallArea(a, b, c, {2, 2, 0.6}, r), 0.0);
  EXPECT_EQ(triangleBallArea(a, b, c, {-1, -1, 0}, r), 0.0);
  EXPECT_EQ(triangleBallArea(a, a, c, {0, 0, 0}, r), 0.0);  // degenerate
}

// Random triangles and balls that cut them in every way against Monte Carlo:
// N = 200k uniform points in the triangle, the fraction p inside the ball has
// standard error sqrt(p (1 - p) / N); tolerance 5 of those (times the area),
// plus float rounding of the points.
TEST(PhotonSurface, TriangleBallAreaAgreesWithMonteCarlo) {
  Rng rng(11);
  auto u = [&] { return double(rng.next()) * 2.0 - 1.0; };
  for (int trial = 0; trial < 40; ++trial) {
    const glm::dvec3 a(u(), u(), u()), b(u(), u(), u()), c(u(), u(), u());
    const glm::dvec3 x(0.5 * u(), 0.5 * u(), 0.5 * u());
    const double r = 0.2 + 0.8 * (u() * 0.5 + 0.5);
    const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
    const int N = 200000;
    int inside = 0;
    for (int i = 0; i < N; ++i) {
      double s = rng.next(), t = rng.next();
      if (s + t > 1) { s = 1 - s; t = 1 - t; }
      const glm::dvec3 y = a + s * (b - a) + t * (c - a);
      inside += glm::dot(y - x, y - x) <= r * r;
    }
    const double p = double(inside) / N, sigma = std::sqrt(std::max(p * (1 - p), 1.0 / N) / N);
    EXPECT_NEAR(triangleBallArea(a, b, c, x, r), p * area, 5 * sigma * area + 1e-6) << "trial " << trial;
  }
}


// A vertex whose nearest photons all lie on another, brighter face (the top
// edge of a block's side beside its top, a block's foot beside the floor):
// the search read none on the vertex's own side among the 2k nearest and gave
// 0 without looking further, 0 against the reference's 0.25 (z -72) at 7 of
// the Cornell box's vertices at k = 8, at any photon count (an outside
// audit). Now it searches wider; no vertex the reference lights (more than
// 10 of its standard errors and 0.01 W/m^2) reads 0. The reference: 256
// paths a vertex; the photon map without its direct light (every photon
// counts) at k = 8.
TEST(PhotonMap, NoLitVertexReadsZeroBesideABrighterFace) {
  const Scene s = scenes::cornellBox(50.0).scene;
  auto caster = makeEmbreeCaster(s);
  PathTraceOptions po;
  po.samplesPerVertex = 256;
  const PathTraceResult ref = pathTrace(s, *caster, po);
  PhotonOptions o;
  o.photons = 200000;
  o.kNearest = 8;
  o.directLight = false;
  const VertexRadiometry r = computePhotonMap(s, *caster, o);
  int lit = 0, zero = 0;
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    const double b = luminance(ref.B[i]);
    if (!(b > 0.01 && b > 10.0 * ref.stdError[i])) continue;
    ++lit;
    if (!(luminance(r.B[i]) > 0.f)) {
      ++zero;
      ADD_FAILURE() << "vertex " << i << " reads 0, the reference " << b << " +- " << ref.stdError[i];
    }
  }
  EXPECT_GT(lit, 600);
  EXPECT_EQ(zero, 0);
}
