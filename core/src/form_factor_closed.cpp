#include "gi/form_factor_closed.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "gi/raycaster.h"
#include "gi/scene_setup.h"

namespace gi {

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string fmt(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", x);
  return b;
}

// Lengths in (0, 1e12), at most kMaxDimensionRatio apart: beyond, the
// sampled methods see F below about 1e-9 as 0 (a relative tolerance of 6e7
// then passed), and the perpendicular closed form loses its digits to
// cancellation (a strip 1e-20 wide read -7e-20; an outside audit).
constexpr double kMaxDimensionRatio = 1e4;
void checkDims(std::initializer_list<double> dims, const char* what) {
  for (double d : dims)
    if (!(std::isfinite(d) && d > 0 && d < 1e12))
      throw std::invalid_argument(std::string(what) + ": every dimension must be a positive finite length below 1e12 (" +
                                  fmt(d) + ")");
  const auto [lo, hi] = std::minmax_element(dims.begin(), dims.end());
  if (*hi > kMaxDimensionRatio * *lo)
    throw std::invalid_argument(std::string(what) + ": dimensions " + fmt(*lo) + " and " + fmt(*hi) +
                                " are more than 1e4 apart, beyond what the sampled methods resolve (form factors "
                                "below about 1e-9) and the closed form keeps in double precision");
}

Scene lightless(Scene s) {
  s.rho.assign(s.faceCount(), glm::vec3(0.f));
  s.emission.assign(s.faceCount(), glm::vec3(0.f));
  return s;
}

// sqrt(1 + v^2) atan(u / sqrt(1 + v^2)) - atan(u), without the cancellation
// of its two terms for small u: from atan's series, the sum over k >= 1 of
// (-1)^(k+1) u^(2k+1) / (2k+1) (1 - (1 + v^2)^-k).
double atanDifference(double u, double v) {
  if (u >= 0.1) return std::sqrt(1 + v * v) * std::atan(u / std::sqrt(1 + v * v)) - std::atan(u);
  const double u2 = u * u, lv = std::log1p(v * v);
  double sum = 0, power = u * u2;
  for (int k = 1; k <= 12; ++k, power *= u2)  // u^2 <= 0.01: 12 terms reach 1e-24 of the first
    sum += (k % 2 ? 1.0 : -1.0) * power / (2 * k + 1) * -std::expm1(-k * lv);
  return sum;
}

}  // namespace

// Howell's C-11 in a form without cancellation: its logarithm is
// log1p(x^2 y^2 / (1 + x^2 + y^2)) / 2, and each x sqrt(1 + y^2) atan(...)
// - x atan(x) pair is atanDifference. Written as the four terms, the
// closed form lost all its digits at a distance of 10^4 times the sides
// (F = 3.2e-9 came out 0; an outside audit against 60-digit arithmetic).
double parallelRectanglesF(double a, double b, double c) {
  const double x = a / c, y = b / c;
  const double bracket = 0.5 * std::log1p(x * x * y * y / (1 + x * x + y * y)) + x * atanDifference(x, y) +
                         y * atanDifference(y, x);
  return 2.0 / (kPi * x * y) * bracket;
}

double perpendicularRectanglesF(double w, double h, double l) {
  const double W = w / l, H = h / l, W2 = W * W, H2 = H * H, S = std::sqrt(H2 + W2);
  const double a = W * std::atan(1 / W) + H * std::atan(1 / H) - S * std::atan(1 / S);
  const double b = std::log((1 + W2) * (1 + H2) / (1 + W2 + H2)) +
                   W2 * std::log(W2 * (1 + W2 + H2) / ((1 + W2) * (W2 + H2))) +
                   H2 * std::log(H2 * (1 + H2 + W2) / ((1 + H2) * (H2 + W2)));
  return (a + 0.25 * b) / (kPi * W);
}

// (S - sqrt(S^2 - 4 r^2)) / 2 with r = rj / ri, as 2 r^2 / (S (1 + sqrt(1 -
// (2r/S)^2))): the same number without the difference of two nearly equal
// terms (disks 10^4 radii apart lost a quarter of their factor, 3e4 apart
// all of it).
double coaxialDisksF(double ri, double rj, double L) {
  const double Ri = ri / L, Rj = rj / L, S = 1 + (1 + Rj * Rj) / (Ri * Ri), r = rj / ri;
  const double q = 2 * r / S;
  return 2 * r * r / (S * (1 + std::sqrt(std::max(0.0, 1 - q * q))));
}

// The source at z = 0 facing +z, the target at z = c facing -z.
ClosedFormScene parallelRectanglesScene(double a, double b, double c) {
  checkDims({a, b, c}, "parallel rectangles");
  const std::vector<glm::dvec3> p = {{0, 0, 0}, {a, 0, 0}, {a, b, 0}, {0, b, 0},
                                     {0, 0, c}, {a, 0, c}, {a, b, c}, {0, b, c}};
  return {"parallel " + fmt(a) + " x " + fmt(b) + " at " + fmt(c),
          lightless(Scene::fromAbsolute(p, {{0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6}})), 2,
          parallelRectanglesF(a, b, c), 0.0};
}

// The common edge from (0,0,0) to (l,0,0); the source in z = 0 reaching
// y = w, facing +z; the target in y = 0 reaching z = h, facing +y; no shared
// vertex (two separate patches, as two files would be).
ClosedFormScene perpendicularRectanglesScene(double w, double h, double l) {
  checkDims({w, h, l}, "perpendicular rectangles");
  const std::vector<glm::dvec3> p = {{0, 0, 0}, {l, 0, 0}, {l, w, 0}, {0, w, 0},
                                     {0, 0, 0}, {l, 0, 0}, {l, 0, h}, {0, 0, h}};
  return {"perpendicular w " + fmt(w) + ", h " + fmt(h) + ", edge " + fmt(l),
          lightless(Scene::fromAbsolute(p, {{0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6}})), 2,
          perpendicularRectanglesF(w, h, l), 0.0};
}

// Each disk a polar grid of `rings` x `segments` (a fan at the centre), the
// source at z = 0 facing +z, the target at z = L facing -z.
ClosedFormScene coaxialDisksScene(double ri, double rj, double L, int rings, int segments) {
  checkDims({ri, rj, L}, "coaxial disks");
  if (rings < 1 || segments < 8) throw std::invalid_argument("coaxial disks: at least 1 ring and 8 segments");
  std::vector<glm::dvec3> pts;
  std::vector<glm::uvec3> tris;
  uint32_t split = 0;
  for (int side = 0; side < 2; ++side) {
    const double z = side * L, r = side == 0 ? ri : rj;
    const uint32_t centre = uint32_t(pts.size());
    pts.push_back({0, 0, z});
    for (int k = 1; k <= rings; ++k)
      for (int j = 0; j < segments; ++j) {
        const double a = 2 * kPi * j / segments, rr = r * k / rings;
        pts.push_back({rr * std::cos(a), rr * std::sin(a), z});
      }
    auto id = [&](int k, int j) { return centre + 1 + uint32_t((k - 1) * segments + (j % segments)); };
    auto tri = [&](uint32_t a, uint32_t b, uint32_t c) {
      tris.push_back(side == 0 ? glm::uvec3(a, b, c) : glm::uvec3(a, c, b));
    };
    for (int j = 0; j < segments; ++j) tri(centre, id(1, j), id(1, j + 1));
    for (int k = 1; k < rings; ++k)
      for (int j = 0; j < segments; ++j) {
        tri(id(k, j), id(k + 1, j), id(k + 1, j + 1));
        tri(id(k, j), id(k + 1, j + 1), id(k, j + 1));
      }
    if (side == 0) split = uint32_t(tris.size());
  }
  // The inscribed polygon's area is sin(2 pi / n) n / (2 pi) of the disk's.
  const double areaRatio = std::sin(2 * kPi / segments) * segments / (2 * kPi);
  return {"coaxial disks r " + fmt(ri) + " to r " + fmt(rj) + " at " + fmt(L), lightless(Scene::fromAbsolute(pts, tris)),
          split, coaxialDisksF(ri, rj, L), 2.0 * (1.0 - areaRatio)};
}

double sourceToTargetF(const ClosedFormScene& c, const FormFactors::Settings& set) {
  const auto caster = makeEmbreeCaster(c.scene);
  const FormFactors ff(c.scene, *caster, set);
  double num = 0, den = 0;
  for (uint32_t i = 0; i < c.split; ++i) {
    const FormFactorRow r = ff.row(i);
    double f = 0;
    for (size_t k = 0; k < r.j.size(); ++k)
      if (r.j[k] >= c.split) f += r.F[k];
    num += faceArea(c.scene, i) * f;
    den += faceArea(c.scene, i);
  }
  return num / den;
}

bool MethodEstimate::within() const { return std::isnan(tolerance) || std::fabs(relError) <= tolerance; }

ClosedFormComparison compareWithClosedForm(const ClosedFormScene& c, const ComparisonSettings& set) {
  if (set.raysPerPatch < 1 || set.analyticPoints < 1 || set.hemicubeResolution < 8 || set.hemicubePoints < 1)
    throw std::invalid_argument("rays, analytic points and hemicube views must be >= 1, the resolution >= 8");
  ClosedFormComparison out;
  out.name = c.name;
  out.closed = c.F;
  out.sourceFaces = c.split;
  out.targetFaces = c.scene.faceCount() - c.split;
  const double F = c.F, n = double(c.split), N = double(set.raysPerPatch);
  auto add = [&](FormFactorMethod m, double tol) {
    FormFactors::Settings s{m, set.raysPerPatch, set.analyticPoints, set.hemicubeResolution, set.seed};
    s.hemicubePoints = set.hemicubePoints;
    MethodEstimate e{m, sourceToTargetF(c, s), tol + c.meshError};
    e.relError = e.F / F - 1;
    out.methods.push_back(e);
  };
  add(FormFactorMethod::MonteCarlo, std::max(0.005, 4.0 * std::sqrt((1 - F) / (n * N * F))));
  add(FormFactorMethod::Analytic, 0.005);
  add(FormFactorMethod::Hemicube, set.hemicubePoints >= 129 && set.hemicubeResolution >= 128 ? 0.02 : std::nan(""));
  return out;
}

}  // namespace gi
