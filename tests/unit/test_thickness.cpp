// Thickness (shape diameter function) against its exact values for a
// sphere, a slab and a cylinder (derivations in gi/thickness.h and below),
// with and without the robust mean, plus determinism, adaptivity and bad input.
//
// Directions are cosine-distributed in the cone of half-angle alpha around
// -n, so c = cos(theta) has c^2 uniform on [a, 1], a = cos^2(alpha):
//   sphere r:    L = 2 r c                   (chord at angle theta to the diameter)
//   slab t:      L = t / c
//   cylinder R:  L = 2 R c / (c^2 + s^2 cos^2 phi), phi uniform, s = sin(theta)
// Robust mean (Shapira et al. 2008): the mean of the lengths within one
// standard deviation sd of the median m. For the sphere and the slab L is a
// monotone function of U = c^2, so the kept set is an interval of U and
//   sphere: E[2r sqrt(U) | U in [u1, u2]] = 2r (2/3)(u2^1.5 - u1^1.5)/(u2 - u1)
//   slab:   E[t / sqrt(U) | U in [u1, u2]] = 2t (sqrt(u2) - sqrt(u1))/(u2 - u1)
// with m, sd of L from E[L], E[L^2] (sphere: E[L^2] = 4r^2 (1 + a)/2; slab:
// E[L^2] = t^2 ln(1/a)/(1 - a)). The cylinder's robust mean is computed by
// quadrature over (U, phi).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "gi/scenes.h"
#include "gi/thickness.h"
#include "test_helpers.h"

using namespace gi;

namespace {

constexpr double kPi = 3.14159265358979323846;

ThicknessResult runThickness(const Scene& s, int rays, double coneDeg, bool robust, uint32_t seed = 0) {
  auto caster = makeEmbreeCaster(s);
  ThicknessOptions o;
  o.raysPerVertex = rays;
  o.coneAngleDeg = float(coneDeg);
  o.rejectOutliers = robust;
  o.seed = seed;
  return computeThickness(s, *caster, o);
}

// Appends an nu x nv grid over the quad p00 p10 p11 p01, triangles facing `out`.
void grid(std::vector<glm::dvec3>& P, std::vector<glm::uvec3>& T, glm::dvec3 p00, glm::dvec3 p10, glm::dvec3 p11,
          glm::dvec3 p01, int nu, int nv, glm::dvec3 out) {
  const uint32_t base = uint32_t(P.size());
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double u = double(i) / nu, v = double(j) / nv;
      P.push_back((1 - u) * (1 - v) * p00 + u * (1 - v) * p10 + u * v * p11 + (1 - u) * v * p01);
    }
  auto id = [&](int i, int j) { return base + uint32_t(j * (nu + 1) + i); };
  auto tri = [&](uint32_t a, uint32_t b, uint32_t c) {
    if (glm::dot(glm::cross(P[b] - P[a], P[c] - P[a]), out) < 0) std::swap(b, c);
    T.push_back({a, b, c});
  };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      tri(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      tri(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
}

// Closed box [-W/2, W/2]^2 x [0, t]: top and bottom n x n, sides 1 cell high.
// (Separate grids per side: the sides' vertices do not disturb the top's normals.)
Scene slab(double W, double t, int n) {
  std::vector<glm::dvec3> P;
  std::vector<glm::uvec3> T;
  const double h = W / 2;
  grid(P, T, {-h, -h, t}, {h, -h, t}, {h, h, t}, {-h, h, t}, n, n, {0, 0, 1});
  grid(P, T, {-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}, n, n, {0, 0, -1});
  grid(P, T, {-h, -h, 0}, {h, -h, 0}, {h, -h, t}, {-h, -h, t}, n, 1, {0, -1, 0});
  grid(P, T, {-h, h, 0}, {h, h, 0}, {h, h, t}, {-h, h, t}, n, 1, {0, 1, 0});
  grid(P, T, {-h, -h, 0}, {-h, h, 0}, {-h, h, t}, {-h, -h, t}, n, 1, {-1, 0, 0});
  grid(P, T, {h, -h, 0}, {h, h, 0}, {h, h, t}, {h, -h, t}, n, 1, {1, 0, 0});
  return Scene::fromAbsolute(P, T);
}

// Closed cylinder of radius R around z, z in [0, H]: m segments, k rings, fan caps.
Scene cylinder(double R, double H, int m, int k) {
  std::vector<glm::dvec3> P;
  std::vector<glm::uvec3> T;
  for (int j = 0; j <= k; ++j)
    for (int i = 0; i < m; ++i) {
      const double phi = 2 * kPi * i / m;
      P.push_back({R * std::cos(phi), R * std::sin(phi), H * j / k});
    }
  auto id = [&](int i, int j) { return uint32_t(j * m + (i % m)); };
  auto tri = [&](uint32_t a, uint32_t b, uint32_t c, glm::dvec3 out) {
    if (glm::dot(glm::cross(P[b] - P[a], P[c] - P[a]), out) < 0) std::swap(b, c);
    T.push_back({a, b, c});
  };
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < m; ++i) {
      const glm::dvec3 c = (P[id(i, j)] + P[id(i + 1, j + 1)]) * 0.5;
      const glm::dvec3 out(c.x, c.y, 0.0);
      tri(id(i, j), id(i + 1, j), id(i + 1, j + 1), out);
      tri(id(i, j), id(i + 1, j + 1), id(i, j + 1), out);
    }
  for (int cap = 0; cap < 2; ++cap) {
    const uint32_t centre = uint32_t(P.size());
    P.push_back({0, 0, cap ? H : 0.0});
    const int j = cap ? k : 0;
    for (int i = 0; i < m; ++i) tri(centre, id(i, j), id(i + 1, j), {0, 0, cap ? 1.0 : -1.0});
  }
  return Scene::fromAbsolute(P, T);
}

// Mean of `value` over the chosen vertices and its standard error (the
// vertices' rays are independent: the variances add).
struct Mean {
  double mean = 0, se = 0;
  size_t n = 0;
};
Mean meanOver(const ThicknessResult& r, const std::vector<size_t>& v) {
  Mean m;
  double var = 0;
  for (size_t i : v) { m.mean += r.value[i]; var += double(r.stdError[i]) * r.stdError[i]; }
  m.n = v.size();
  m.mean /= double(m.n);
  m.se = std::sqrt(var) / double(m.n);
  return m;
}

double sphereMean(double r, double alpha) {
  const double c = std::cos(alpha);
  return 4.0 * r / 3.0 * (1 + c + c * c) / (1 + c);
}
double slabMean(double t, double alpha) { return 2.0 * t / (1 + std::cos(alpha)); }

// Robust means of the sphere and the slab: L = f(U) monotone, U uniform on [a, 1].
double sphereRobust(double r, double alpha) {
  const double a = std::pow(std::cos(alpha), 2);
  const double mean = sphereMean(r, alpha), m = 2 * r * std::sqrt((1 + a) / 2);
  const double sd = std::sqrt(4 * r * r * (1 + a) / 2 - mean * mean);
  auto U = [&](double L) { return std::clamp(std::pow(L / (2 * r), 2), a, 1.0); };
  const double u1 = U(m - sd), u2 = U(m + sd);
  return 2 * r * (2.0 / 3.0) * (std::pow(u2, 1.5) - std::pow(u1, 1.5)) / (u2 - u1);
}
double slabRobust(double t, double alpha) {
  const double a = std::pow(std::cos(alpha), 2);
  const double mean = slabMean(t, alpha), m = t / std::sqrt((1 + a) / 2);
  const double sd = std::sqrt(t * t * std::log(1 / a) / (1 - a) - mean * mean);
  auto U = [&](double L) { return std::clamp(std::pow(t / L, 2), a, 1.0); };
  const double u1 = U(m + sd), u2 = U(std::max(m - sd, t));
  return 2 * t * (std::sqrt(u2) - std::sqrt(u1)) / (u2 - u1);
}
// The cylinder's robust mean by midpoint quadrature over (U, phi): 2000^2
// equally likely directions (error of the quadrature well below 1e-4 R).
double cylinderRobust(double R, double alpha) {
  const double a = std::pow(std::cos(alpha), 2);
  const int n = 2000;
  std::vector<float> L;
  L.reserve(size_t(n) * n);
  for (int i = 0; i < n; ++i) {
    const double U = a + (1 - a) * (i + 0.5) / n, c = std::sqrt(U), s2 = 1 - U;
    for (int j = 0; j < n; ++j) {
      const double cp = std::cos(2 * kPi * (j + 0.5) / n);
      L.push_back(float(2 * R * c / (U + s2 * cp * cp)));
    }
  }
  return robustMean(L, true).mean;
}

std::vector<size_t> sideMiddle(const Scene& s, double zlo, double zhi) {
  std::vector<size_t> v;
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    const glm::dvec3 p = s.toWorld(s.positions[i]);
    if (p.z > zlo && p.z < zhi && std::hypot(p.x, p.y) > 0.5) v.push_back(i);
  }
  return v;
}

std::vector<size_t> slabTopCentre(const Scene& s, double t, double half) {
  const auto n = computeVertexNormals(s);
  std::vector<size_t> v;
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    const glm::dvec3 p = s.toWorld(s.positions[i]);
    if (std::fabs(p.z - t) < 1e-9 && std::fabs(p.x) < half && std::fabs(p.y) < half && n[i].z > 0.9999f) v.push_back(i);
  }
  return v;
}

}  // namespace

// The exact values themselves: the quadrature of the plain cylinder mean is
// 2R (the azimuthal mean of L is 2R at every theta), which checks the
// formula for L and the quadrature used for the robust value.
TEST(Thickness, ExactValuesAreConsistent) {
  const double a = std::pow(std::cos(kPi / 3), 2);
  double sum = 0;
  const int n = 1000;
  for (int i = 0; i < n; ++i) {
    const double U = a + (1 - a) * (i + 0.5) / n;
    for (int j = 0; j < n; ++j) {
      const double cp = std::cos(2 * kPi * (j + 0.5) / n);
      sum += 2 * std::sqrt(U) / (U + (1 - U) * cp * cp);
    }
  }
  EXPECT_NEAR(sum / (double(n) * n), 2.0, 1e-9);
  // Narrow cones: a sphere's diameter and a slab's thickness.
  EXPECT_NEAR(sphereMean(1.0, 1e-3), 2.0, 1e-6);
  EXPECT_NEAR(slabMean(1.0, 1e-3), 1.0, 1e-6);
  // At the paper's 60 degrees: sphere 14r/9, slab 4t/3.
  EXPECT_NEAR(sphereMean(1.0, kPi / 3), 14.0 / 9.0, 1e-12);
  EXPECT_NEAR(slabMean(1.0, kPi / 3), 4.0 / 3.0, 1e-12);
}

TEST(Thickness, RobustMeanKeepsOneStandardDeviationAroundTheMedian) {
  std::vector<float> L = {1.f, 1.f, 1.f, 1.f, 100.f};
  const RobustMean r = robustMean(L, true);
  EXPECT_EQ(r.count, 4u);  // sd = 44.3, |100 - median| = 99 > sd
  EXPECT_FLOAT_EQ(float(r.mean), 1.f);
  std::vector<float> all = {1.f, 1.f, 1.f, 1.f, 100.f};
  EXPECT_NEAR(robustMean(all, false).mean, 20.8, 1e-9);
  std::vector<float> none;
  EXPECT_EQ(robustMean(none, true).count, 0u);
  // One length has no spread to measure: its error is its whole value, not
  // 0 (an outside audit: one ray per vertex reported "exact" values).
  for (bool reject : {false, true}) {
    std::vector<float> one = {2.5f};
    EXPECT_FLOAT_EQ(float(robustMean(one, reject).stdError), 2.5f) << reject;
  }
}

// Sphere of radius 1 (icosphere, 2,562 vertices) at the 60 degree cone.
// Tolerance: 5 standard errors of the mean over the vertices (each vertex's
// error estimate is the iid one, conservative for our scrambled Sobol
// directions) plus the faceting: chords end on the inscribed facets, up to
// 1 - cos(edge / sqrt 3) ~ 0.1% short.
TEST(Thickness, SphereGivesTheConeWeightedChord) {
  auto sf = scenes::sphere(1.0, 4, false);
  const Scene& s = sf.scene;
  std::vector<size_t> all(s.vertexCount());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  for (bool robust : {false, true}) {
    const ThicknessResult r = runThickness(s, 256, 60.0, robust);
    const Mean m = meanOver(r, all);
    const double exact = robust ? sphereRobust(1.0, kPi / 3) : sphereMean(1.0, kPi / 3);
    EXPECT_NEAR(m.mean, exact, 5 * m.se + 2e-3) << (robust ? "robust" : "plain") << ", se " << m.se;
    // Every vertex on its own within 5 of its standard errors (plus the faceting).
    size_t outliers = 0;
    for (size_t i : all)
      if (std::fabs(r.value[i] - exact) > 5 * r.stdError[i] + 2e-3) ++outliers;
    EXPECT_EQ(outliers, 0u);
  }
  // Uniform instead of cosine-weighted directions would give 2r (1 + c)/2 = 1.5:
  // 3.6% below 14/9, far outside the tolerance (about 0.3%).
  EXPECT_GT(std::fabs(sphereMean(1.0, kPi / 3) - 1.5), 20 * 2e-3);
}

// The robust mean's error bars at few rays: its window (median +- sd) is
// chosen from the same lengths, so the kept lengths' spread over sqrt(k)
// understates the error; the trimmed mean's winsorised standard error does
// not. Sphere (2,562 vertices), 16 rays per vertex: z = (value - exact) /
// stdError must have an RMS below 1.4 and at most 4% of the vertices beyond
// 3 (an outside audit measured 1.77 and 6.5% on a finer sphere before;
// this one, 1.75 and 6.0%; now 1.17 and 2.1%). Below 16 rays the log warns.
TEST(Thickness, RobustErrorBarsHoldFromSixteenRays) {
  auto sf = scenes::sphere(1.0, 4, false);
  const Scene& s = sf.scene;
  const double exact = sphereRobust(1.0, kPi / 3);
  const ThicknessResult r = runThickness(s, 16, 60.0, true);
  double z2 = 0;
  size_t beyond = 0;
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    const double z = (r.value[i] - exact) / r.stdError[i];
    z2 += z * z;
    beyond += std::fabs(z) > 3;
  }
  const double rmsZ = std::sqrt(z2 / double(s.vertexCount())), share = double(beyond) / double(s.vertexCount());
  std::printf("robust thickness at 16 rays: RMS z %.3f, %.2f%% beyond 3\n", rmsZ, 100 * share);
  EXPECT_LT(rmsZ, 1.4);
  EXPECT_LT(share, 0.04);
  bool warned = false;
  for (const auto& w : runThickness(s, 8, 60.0, true).stats.warnings) warned |= w.find("too few lengths") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_TRUE(r.stats.warnings.empty());
}

// Slab 0.1 thick, 4 wide: from the top's central vertices a ray at 60 degrees
// travels 0.17 sideways, far from the sides. Plain mean 2t/(1 + cos alpha);
// a narrow (2 degree) cone gives t itself within 0.03%.
TEST(Thickness, SlabGivesItsThickness) {
  const double t = 0.1;
  const Scene s = slab(4.0, t, 40);
  const auto centre = slabTopCentre(s, t, 1.0);
  ASSERT_GT(centre.size(), 300u);
  const double deg2 = 2.0 * kPi / 180;
  struct Case { double alpha; bool robust; double exact; };
  for (const Case c : {Case{kPi / 3, false, slabMean(t, kPi / 3)}, Case{kPi / 3, true, slabRobust(t, kPi / 3)},
                       Case{deg2, false, slabMean(t, deg2)}, Case{deg2, true, slabRobust(t, deg2)}}) {
    const ThicknessResult r = runThickness(s, 256, c.alpha * 180 / kPi, c.robust);
    const Mean m = meanOver(r, centre);
    // The flat slab has no faceting error: only the sampling (5 standard errors).
    EXPECT_NEAR(m.mean, c.exact, 5 * m.se + 1e-7)
        << "alpha " << c.alpha << (c.robust ? " robust" : " plain");
  }
  // Every length lies in [t, t / cos 2 deg]: both means within 0.061% of t.
  EXPECT_NEAR(slabMean(t, deg2), t, 3.1e-4 * t);
  EXPECT_NEAR(slabRobust(t, deg2), t, 6.1e-4 * t);
}

// The same slab 1 thick in a scene 3,000 wide: the rays' origins lie 1e-5
// of the scene's size (0.042, 4% of the thickness) inside the surface, and
// the chord must not depend on it. Measured from the vertex to the exit
// point, the mean was 1.8% low at 60 degrees (an outside audit: 3.5% at
// 6,000 wide); the vertices of the flat top all see the same slab, so the
// mean over them has only the sampling's error (5 standard errors).
// A mesh exported with its faces unwelded (every triangle its own corners)
// reads what the welded mesh reads: the slab's vertices, top, bottom, sides
// and corners, within 5 standard errors of the welded vertex at the same
// place (each 64 rays). Before, a corner took the normal of one face only,
// and its cone met the neighbouring faces there: a cube's corners read
// 0.0003 of the welded 2.46 (an outside audit).
TEST(Thickness, UnweldedMeshReadsAsWelded) {
  // The slab's six grids welded into one closed surface (coincident points merged).
  const Scene parts = slab(1.0, 0.25, 4);
  std::vector<glm::dvec3> P;
  std::vector<uint32_t> id(parts.vertexCount());
  for (size_t i = 0; i < parts.vertexCount(); ++i) {
    const glm::dvec3 p = parts.toWorld(parts.positions[i]);
    const auto at = std::find(P.begin(), P.end(), p);
    id[i] = uint32_t(at - P.begin());
    if (at == P.end()) P.push_back(p);
  }
  std::vector<glm::uvec3> T;
  for (const glm::uvec3& t : parts.triangles) T.push_back({id[t.x], id[t.y], id[t.z]});
  const Scene welded = Scene::fromAbsolute(P, T);
  ASSERT_LT(welded.vertexCount(), parts.vertexCount());
  std::vector<glm::dvec3> soup;
  std::vector<glm::uvec3> tris;
  for (const glm::uvec3& t : welded.triangles) {
    for (int k = 0; k < 3; ++k) soup.push_back(welded.toWorld(welded.positions[t[k]]));
    tris.push_back({uint32_t(soup.size() - 3), uint32_t(soup.size() - 2), uint32_t(soup.size() - 1)});
  }
  const Scene loose = Scene::fromAbsolute(soup, tris);
  for (bool robust : {false, true}) {
    const ThicknessResult a = runThickness(welded, 64, 60, robust), b = runThickness(loose, 64, 60, robust);
    size_t k = 0;
    for (const glm::uvec3& t : welded.triangles)
      for (int c = 0; c < 3; ++c, ++k) {
        const uint32_t v = t[c];
        const double se = std::hypot(a.stdError[v], b.stdError[k]);
        ASSERT_GT(a.value[v], 0.1f);
        EXPECT_NEAR(b.value[k], a.value[v], 5 * se + 1e-3) << "vertex " << v << (robust ? " robust" : " plain");
      }
  }
}

TEST(Thickness, ThinSlabInALargeSceneGivesItsThickness) {
  const double t = 1.0;
  const Scene s = slab(3000.0, t, 20);
  const auto centre = slabTopCentre(s, t, 1000.0);
  ASSERT_GT(centre.size(), 100u);
  for (double alpha : {kPi / 3, kPi / 12}) {
    const ThicknessResult r = runThickness(s, 256, alpha * 180 / kPi, false);
    const Mean m = meanOver(r, centre);
    EXPECT_NEAR(m.mean, slabMean(t, alpha), 5 * m.se + 1e-6) << "alpha " << alpha;
  }
}

// Cylinder of radius 1, 10 long: vertices on the side within 0.6 of
// mid-height (rays travel at most 2/cos(60) sin(60) = 3.5 along the axis at
// 60 degrees). Plain mean: the diameter 2 for any cone. 128 segments: the
// opposite side's facets lie up to 1 - cos(pi / 128) = 3.0e-4 inside the circle.
TEST(Thickness, CylinderGivesItsDiameter) {
  const Scene s = cylinder(1.0, 10.0, 128, 20);
  const auto middle = sideMiddle(s, 4.4, 5.6);
  ASSERT_EQ(middle.size(), 3u * 128u);
  for (double deg : {60.0, 30.0}) {
    const ThicknessResult r = runThickness(s, 256, deg, false);
    const Mean m = meanOver(r, middle);
    EXPECT_NEAR(m.mean, 2.0, 5 * m.se + 3e-4) << deg << " degrees";
  }
  const ThicknessResult r = runThickness(s, 256, 60.0, true);
  const Mean m = meanOver(r, middle);
  EXPECT_NEAR(m.mean, cylinderRobust(1.0, kPi / 3), 5 * m.se + 3e-4);
}

TEST(Thickness, DeterministicForAnyThreadCount) {
  auto sf = scenes::sphere(1.0, 3, false);
  ThicknessResult one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = runThickness(sf.scene, 64, 60.0, true, 5);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = runThickness(sf.scene, 64, 60.0, true, 5);
  }
  for (size_t i = 0; i < one.value.size(); ++i) ASSERT_EQ(one.value[i], two.value[i]) << i;
  EXPECT_GT(test::rms(runThickness(sf.scene, 64, 60.0, true, 6).value, one.value), 0.0);
}

// Adaptive: every vertex stops once its standard error is 1% of its mean (or
// at max_rays), and the result still matches the exact value.
TEST(Thickness, AdaptiveMeetsItsTarget) {
  auto sf = scenes::sphere(1.0, 3, false);
  auto caster = makeEmbreeCaster(sf.scene);
  ThicknessOptions o;
  o.targetError = 0.01;
  o.rejectOutliers = false;
  const ThicknessResult r = computeThickness(sf.scene, *caster, o);
  int fewer = 0;
  for (size_t i = 0; i < r.value.size(); ++i) {
    EXPECT_TRUE(r.stdError[i] <= 0.01 * r.value[i] || r.rays[i] >= o.maxRays) << i;
    EXPECT_NEAR(r.value[i], sphereMean(1.0, kPi / 3), 5 * r.stdError[i] + 4e-3) << i;
    fewer += r.rays[i] < o.maxRays;
  }
  EXPECT_EQ(fewer, int(r.value.size()));
  EXPECT_TRUE(r.stats.warnings.empty());
}

// A mesh whose normals point inwards (the furnace sphere) or an open plane:
// no ray finds an opposite side; every vertex gets 0 and the log says why.
TEST(Thickness, NoOppositeSideWarns) {
  for (auto sf : {scenes::sphere(1.0, 2, true), scenes::openPlane(1.0, 4)}) {
    const ThicknessResult r = runThickness(sf.scene, 32, 60.0, true);
    for (float v : r.value) EXPECT_EQ(v, 0.f);
    ASSERT_EQ(r.stats.warnings.size(), 1u);
    EXPECT_NE(r.stats.warnings[0].find("opposite side"), std::string::npos);
  }
  auto sf = scenes::sphere(1.0, 2, false);
  auto caster = makeEmbreeCaster(sf.scene);
  ThicknessOptions o;
  o.coneAngleDeg = 90.f;
  EXPECT_THROW(computeThickness(sf.scene, *caster, o), std::invalid_argument);
}

// Any scale: a sphere 1e-12 across gives the same thickness relative to its
// size. Not bit for bit: the re-centred coordinates round differently, and a
// normal whose z is +-4e-18 (a vertex on the equator) flips the tangent frame
// (Duff et al. 2017 branch on the sign of z), i.e. another, equally valid set
// of directions. So each vertex agrees within 5 standard errors of the
// difference of two independent estimates.
TEST(Thickness, ScaleInvariant) {
  auto sf = scenes::sphere(1.0, 2, false);
  const Scene tiny = test::transformed(sf.scene, 1e-12, glm::dvec3(0.0));
  for (bool robust : {false, true}) {
    const ThicknessResult a = runThickness(sf.scene, 64, 60.0, robust), b = runThickness(tiny, 64, 60.0, robust);
    for (size_t i = 0; i < a.value.size(); ++i)
      EXPECT_NEAR(b.value[i] / 1e-12, a.value[i], 5.0 * std::hypot(a.stdError[i], b.stdError[i] / 1e-12)) << i;
  }
}

// Two solids touching: a second slab stacked on the first shares its top as
// a reversed copy (the same corners, facing down). The caster reports the
// copy's front where a ray meets the first slab's top from inside; thickness
// still takes it as the ray leaving the first slab (it lost those rays, and
// the bottom's vertices their thickness, when the casters began to report
// fronts on 4 December 2026). The first slab's bottom vertices, whose rays
// leave through the shared face, get the values they get alone (to the ray
// offset, which grows with the scene's diagonal).
TEST(Thickness, TouchingSolidsKeepTheirThickness) {
  const double t = 0.1;
  const Scene alone = slab(4.0, t, 40);
  // The copy in the same local coordinates, its bottom exactly on the top
  // (every vertex of the slab lies on its bottom or its top).
  float lo = HUGE_VALF, hi = -HUGE_VALF;
  for (const glm::vec3& p : alone.positions) {
    lo = std::min(lo, p.z);
    hi = std::max(hi, p.z);
  }
  Scene stacked = alone;
  const uint32_t off = uint32_t(alone.vertexCount());
  for (const glm::vec3& p : alone.positions) stacked.positions.push_back({p.x, p.y, p.z == lo ? hi : hi + (hi - lo)});
  for (const glm::uvec3& tri : alone.triangles) stacked.triangles.push_back(tri + glm::uvec3(off));
  ASSERT_EQ(analyzeScene(stacked).twoSidedPairs, 2u * 40u * 40u);  // the shared face, reversed
  const auto n = computeVertexNormals(alone);
  std::vector<size_t> bottom;
  for (size_t i = 0; i < alone.vertexCount(); ++i) {
    const glm::dvec3 p = alone.toWorld(alone.positions[i]);
    if (std::fabs(p.z) < 1e-9 && std::fabs(p.x) < 1.0 && std::fabs(p.y) < 1.0 && n[i].z < -0.9999f) bottom.push_back(i);
  }
  ASSERT_GT(bottom.size(), 300u);
  const ThicknessResult a = runThickness(alone, 64, 60.0, false), b = runThickness(stacked, 64, 60.0, false);
  double mean = 0;
  for (size_t i : bottom) {
    EXPECT_NEAR(b.value[i], a.value[i], 1e-5 * a.value[i]) << i;  // the ray offset follows the scene's size
    mean += b.value[i];
  }
  EXPECT_NEAR(mean / double(bottom.size()), slabMean(t, kPi / 3), 0.02 * t);
}

// Two welded cubes stacked, the upper's bottom the lower's top reversed
// (touching solids as the README asks for them): every vertex of the lower
// cube reads what it reads alone, the rim of the shared face included. The
// rim's vertices took the sum of both cubes' normals (vertices at one
// position were welded whatever mesh they belonged to) and read 0 with an
// error of 0, 64 of them (an outside audit); a cube standing corner on
// vertex on a slab read 60 to 76% thick at its corners so.
TEST(Thickness, WeldedSolidsTouchingAtVerticesKeepTheirNormals) {
  auto cube = [](double z0) {
    std::vector<glm::dvec3> P;
    std::vector<glm::uvec3> T;
    const glm::dvec3 lo(0, 0, z0), hi(1, 1, z0 + 1);
    grid(P, T, {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, 4, 4, {0, 0, 1});
    grid(P, T, {lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z}, 4, 4, {0, 0, -1});
    grid(P, T, {lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {lo.x, lo.y, hi.z}, 4, 4, {0, -1, 0});
    grid(P, T, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, 4, 4, {0, 1, 0});
    grid(P, T, {lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {lo.x, lo.y, hi.z}, 4, 4, {-1, 0, 0});
    grid(P, T, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z}, 4, 4, {1, 0, 0});
    // Welded: one vertex per position (the grids' edges and corners joined).
    std::vector<glm::dvec3> Q;
    std::vector<uint32_t> to(P.size());
    for (size_t i = 0; i < P.size(); ++i) {
      const auto it = std::find(Q.begin(), Q.end(), P[i]);
      to[i] = uint32_t(it - Q.begin());
      if (it == Q.end()) Q.push_back(P[i]);
    }
    for (glm::uvec3& t : T) t = {to[t.x], to[t.y], to[t.z]};
    return std::pair{Q, T};
  };
  const auto [PL, TL] = cube(-1.0);
  const auto [PU, TU] = cube(0.0);
  ASSERT_EQ(PL.size(), 98u);  // 6 n^2 + 2 for n = 4: welded
  std::vector<glm::dvec3> P = PL;
  std::vector<glm::uvec3> T = TL;
  for (const glm::dvec3& p : PU) P.push_back(p);
  for (const glm::uvec3& t : TU) T.push_back(t + glm::uvec3(uint32_t(PL.size())));
  const Scene lower = Scene::fromAbsolute(PL, TL), both = Scene::fromAbsolute(P, T);
  ASSERT_GT(analyzeScene(both).twoSidedPairs, 0u);  // the shared face, reversed
  const ThicknessResult a = runThickness(lower, 64, 60.0, false), b = runThickness(both, 64, 60.0, false);
  size_t rim = 0;
  for (size_t i = 0; i < PL.size(); ++i) {
    const glm::dvec3& p = PL[i];
    const bool onRim = p.z == 0.0 && (p.x == 0.0 || p.x == 1.0 || p.y == 0.0 || p.y == 1.0);
    rim += onRim;
    EXPECT_GT(a.value[i], 0.5f) << i;
    EXPECT_NEAR(b.value[i], a.value[i], 3.0 * std::hypot(a.stdError[i], b.stdError[i]) + 1e-4 * a.value[i])
        << "vertex " << i << (onRim ? " (on the shared face's rim)" : "");
  }
  EXPECT_EQ(rim, 16u);
}

// A tall block open at the bottom (it stands on a floor, as the shipped
// glossy block does), its faces as separate grids: at a top corner three
// faces meet, and the 60-degree cone reaches past them (beyond 35 degrees of
// the corner's diagonal); those rays left within a ray offset, and with the
// long chords escaping through the open bottom they were most of the hits,
// so the robust mean read them: the corners 0.01 to 0.2 where the block is
// 1 wide, which copy depending on the vertex order (an outside audit). Rays
// leaving through a face at their own vertex are no chord and not counted:
// every top-corner vertex reads more than half the width, each copy within 5
// standard errors of the others, and the log says how many rays left so.
TEST(Thickness, ConvexCornerCountsNoRayLeavingAtTheVertex) {
  std::vector<glm::dvec3> P;
  std::vector<glm::uvec3> T;
  const double h = 0.5, H = 4.0;
  grid(P, T, {-h, -h, H}, {h, -h, H}, {h, h, H}, {-h, h, H}, 2, 2, {0, 0, 1});
  grid(P, T, {-h, -h, 0}, {h, -h, 0}, {h, -h, H}, {-h, -h, H}, 2, 8, {0, -1, 0});
  grid(P, T, {-h, h, 0}, {h, h, 0}, {h, h, H}, {-h, h, H}, 2, 8, {0, 1, 0});
  grid(P, T, {-h, -h, 0}, {-h, h, 0}, {-h, h, H}, {-h, -h, H}, 2, 8, {-1, 0, 0});
  grid(P, T, {h, -h, 0}, {h, h, 0}, {h, h, H}, {h, -h, H}, 2, 8, {1, 0, 0});
  const Scene s = Scene::fromAbsolute(P, T);
  const ThicknessResult r = runThickness(s, 256, 60, true);
  std::vector<size_t> corners;
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    const glm::dvec3 p = s.toWorld(s.positions[v]);
    if (std::fabs(std::fabs(p.x) - h) < 1e-9 && std::fabs(std::fabs(p.y) - h) < 1e-9 && std::fabs(p.z - H) < 1e-9)
      corners.push_back(v);
  }
  ASSERT_EQ(corners.size(), 12u);  // 4 corners, each on the top and two sides
  for (size_t v : corners) {
    EXPECT_GT(r.value[v], 0.5f) << "vertex " << v;
    for (size_t w : corners) {
      if (glm::distance(s.positions[v], s.positions[w]) != 0.f) continue;
      EXPECT_NEAR(r.value[v], r.value[w], 5 * std::hypot(r.stdError[v], r.stdError[w])) << v << ", " << w;
    }
  }
  EXPECT_GT(r.stats.get("rays_leaving_at_the_vertex"), 0.0);
}

// A vertex where nothing was measured (an open plane: every ray leaves)
// reads 0 with the scene's diagonal as its error bar, not 0 +- 0, which read
// as an exact thickness of 0 (an outside audit); the log says so.
TEST(Thickness, UnmeasuredVerticesCarryAnErrorBarOfTheSceneSize) {
  const auto sf = scenes::openPlane(2.0, 4);
  const ThicknessResult r = runThickness(sf.scene, 16, 60.0, true);
  const double diag = analyzeScene(sf.scene).diagonal;
  for (size_t i = 0; i < sf.scene.vertexCount(); ++i) {
    EXPECT_EQ(r.hits[i], 0) << i;
    EXPECT_EQ(r.value[i], 0.f) << i;
    EXPECT_FLOAT_EQ(r.stdError[i], float(diag)) << i;
  }
  bool said = false;
  for (const std::string& n : r.stats.notes) said = said || n.find("diagonal as their StdError") != std::string::npos;
  EXPECT_TRUE(said);
}

// A plate thinner than the ray offset (1e-5 of the scene's size): the rays
// start past its other side and it reads 0, which the log blamed on an open
// mesh or inward normals (an outside audit). Said as what it is; a plate
// twice the offset is measured and says nothing of the kind.
TEST(Thickness, PlateThinnerThanTheRayOffsetIsSaid) {
  for (double share : {0.9, 2.0}) {
    const double eps = 1e-5 * std::sqrt(200.0);
    const Scene s = slab(10.0, share * eps, 20);
    const ThicknessResult r = runThickness(s, 16, 60.0, false);
    bool thin = false, open = false;
    for (const std::string& w : r.stats.warnings) {
      thin = thin || w.find("within twice the ray offset") != std::string::npos;
      open = open || w.find("the mesh is open") != std::string::npos;
    }
    EXPECT_EQ(thin, share < 1.0) << share;
    EXPECT_FALSE(open) << share;
    if (share < 1.0) continue;
    double mean = 0;
    int count = 0;
    for (size_t i = 0; i < s.vertexCount(); ++i) {
      const glm::dvec3 p = s.toWorld(s.positions[i]);
      if (std::fabs(p.x) < 2 && std::fabs(p.y) < 2) mean += r.value[i], ++count;
    }
    ASSERT_GT(count, 50);
    EXPECT_NEAR(mean / count, slabMean(share * eps, kPi / 3), 0.05 * share * eps);
  }
}

// An open hemisphere (an icosphere's faces above its equator): every vertex
// finds the far side with some rays (none reads 0), but most of them with
// fewer than half, the rest leaving through the opening. The log warns that
// the mesh is open; it said nothing while no vertex found nothing at all.
TEST(Thickness, OpenMeshIsWarnedOfWhenEveryVertexFindsSomething) {
  const auto sf = scenes::sphere(1.0, 4, false);
  const Scene& full = sf.scene;
  std::vector<glm::dvec3> P;
  std::vector<glm::uvec3> T;
  for (size_t i = 0; i < full.vertexCount(); ++i) P.push_back(full.toWorld(full.positions[i]));
  for (const glm::uvec3& t : full.triangles)
    if (P[t.x].z + P[t.y].z + P[t.z].z > 0.0) T.push_back(t);
  const Scene s = Scene::fromAbsolute(P, T);
  const ThicknessResult r = runThickness(s, 64, 60.0, true);
  EXPECT_EQ(r.stats.get("no_opposite_side"), 0.0);
  bool warned = false;
  for (const auto& w : r.stats.warnings) warned |= w.find("the mesh is open") != std::string::npos;
  EXPECT_TRUE(warned);
  // The closed sphere is not warned of.
  for (const auto& w : runThickness(full, 64, 60.0, true).stats.warnings)
    EXPECT_EQ(w.find("the mesh is open"), std::string::npos) << w;
}
