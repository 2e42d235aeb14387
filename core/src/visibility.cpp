// Visibility between a point and a triangle by one shadow ray: the
// visibility term of the point-to-triangle form factors.
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "gi/raycaster.h"
#include "gi/sampling.h"
#include "gi/scene.h"

namespace gi {

namespace {

// The angle at corner p of the spherical triangle (p, q, r), unit vectors:
// between the great arcs towards q and r.
double cornerAngle(const glm::dvec3& p, const glm::dvec3& q, const glm::dvec3& r) {
  const glm::dvec3 tq = q - glm::dot(p, q) * p, tr = r - glm::dot(p, r) * p;
  return std::atan2(glm::length(glm::cross(tq, tr)), glm::dot(tq, tr));
}

glm::dvec3 unitOr(const glm::dvec3& v, const glm::dvec3& fallback) {
  const double l = glm::length(v);
  return l > 0 ? v / l : fallback;
}

// A direction uniform in the solid angle of the spherical triangle (A, B,
// C) with angle alpha at A and area `area`: Arvo 1995, "Stratified
// Sampling of Spherical Triangles" (SIGGRAPH 95, p. 437), figure 2. The
// first number cuts the sub-triangle (A, B, C') of area u1 * area, the
// second places the point on the arc from B to C'.
struct SphericalTriangle {
  glm::dvec3 A, B, C, Cperp;  // Cperp: C's direction off A, unit
  double alpha, ca, sa, cosAB, area;
};

glm::dvec3 arvoDirection(const SphericalTriangle& T, double u1, double u2) {
  const glm::dvec3 &A = T.A, &B = T.B;
  const double s = std::sin(u1 * T.area - T.alpha), t = std::cos(u1 * T.area - T.alpha);
  const double ca = T.ca, sa = T.sa;
  const double u = t - ca, v = s + sa * T.cosAB;
  const double den = (v * s + u * t) * sa;
  const double q = std::clamp(den != 0 ? ((v * t - u * s) * ca - v) / den : 1.0, -1.0, 1.0);
  const glm::dvec3 Chat = q * A + std::sqrt(std::max(0.0, 1 - q * q)) * T.Cperp;
  const double z = 1 - u2 * (1 - glm::dot(Chat, B));
  return z * B + std::sqrt(std::max(0.0, 1 - z * z)) * unitOr(Chat - glm::dot(Chat, B) * B, Chat);
}

// One shadow ray from x along unit w to the plane (normal nt) through x + da.
bool castToPlane(const RayCaster& caster, const glm::vec3& x, const glm::dvec3& w, const glm::dvec3& nt,
                 const glm::dvec3& da, float eps) {
  const double along = glm::dot(nt, w);
  const double t = along != 0 ? glm::dot(nt, da) / along : 0.0;
  if (!(t > 0) || !std::isfinite(t)) return true;
  Ray ray;
  ray.o = x;
  ray.d = glm::vec3(w);
  ray.tfar = float(t) * (1.f - 1e-4f) - eps;
  return ray.tfar <= 0.f || !caster.occluded(ray);
}

// The largest cosine n . w over the spherical triangle: 1 if n points into
// it, else the largest over its three arcs (at an end, or where the arc
// comes nearest n).
double largestCosine(const glm::dvec3& n, const glm::dvec3 (&p)[3]) {
  double best = -1;
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3 &P = p[k], &Q = p[(k + 1) % 3];
    best = std::max(best, glm::dot(n, P));
    const glm::dvec3 m = glm::cross(P, Q);
    const double lm = glm::length(m);
    if (!(lm > 0)) continue;
    const double side = glm::dot(n, m) / lm;
    inside = inside && side >= 0;
    const glm::dvec3 proj = n - side * (m / lm);
    if (glm::dot(glm::cross(P, proj), m) >= 0 && glm::dot(glm::cross(proj, Q), m) >= 0)
      best = std::max(best, glm::length(proj));
  }
  // The corners wound one way or the other: n inside if on the same side of all three arcs.
  if (inside) return 1.0;
  bool insideOther = true;
  for (int k = 0; k < 3; ++k) insideOther = insideOther && glm::dot(n, glm::cross(p[k], p[(k + 1) % 3])) <= 0;
  return insideOther ? 1.0 : std::min(1.0, best);
}

}  // namespace

bool visibleByFormFactorKernel(const RayCaster& caster, const glm::vec3& x, const glm::vec3& n, const glm::vec3& a,
                               const glm::vec3& b, const glm::vec3& c, Rng& rng, float eps) {
  const glm::dvec3 X(x), N(n), pa(a), pb(b), pc(c);
  const glm::dvec3 da = pa - X, db = pb - X, dc = pc - X;
  const double la = glm::length(da), lb = glm::length(db), lc = glm::length(dc);
  if (!(la > 0 && lb > 0 && lc > 0)) return true;  // x on a corner
  // First a few points uniform by area, each kept with probability
  // K(y) / K_max, the kernel K = (n . (y - x)) h / r^4 (h: x's height over
  // the triangle's plane) over its bound (the largest n . (y - x), at a
  // corner, times h over the nearest distance^4): cheap, and nearly always
  // kept where the triangle is small against its distance. Where none is
  // kept (a large or near triangle), a direction from the spherical
  // triangle. Both draw the same density, so the mixture does too.
  const glm::dvec3 nt = glm::cross(pb - pa, pc - pa);
  const double ln = glm::length(nt);
  if (!(ln > 0)) return true;
  const double h = std::fabs(glm::dot(nt, da)) / ln;
  const double lmax = std::max(glm::dot(N, da), std::max(glm::dot(N, db), glm::dot(N, dc)));
  const glm::dvec3 nearest = closestPointOnTriangle(X, pa, pb, pc) - X;
  const double r2min = glm::dot(nearest, nearest);
  if (h > 0 && lmax > 0 && r2min > 0) {
    const double kmax = lmax * h / (r2min * r2min);
    for (int k = 0; k < 4; ++k) {
      const glm::vec2 ub = uniformTriangle({rng.next(), rng.next()});
      const glm::dvec3 d = double(ub.x) * da + double(ub.y) * db + double(1.f - ub.x - ub.y) * dc;
      const double r2 = glm::dot(d, d);
      if (double(rng.next()) * kmax < glm::dot(N, d) * h / (r2 * r2)) return castToPlane(caster, x, d / std::sqrt(r2), nt, da, eps);
    }
  }
  SphericalTriangle T;
  T.A = da / la, T.B = db / lb, T.C = dc / lc;
  T.alpha = cornerAngle(T.A, T.B, T.C);
  T.area = T.alpha + cornerAngle(T.B, T.C, T.A) + cornerAngle(T.C, T.A, T.B) - M_PI;
  glm::dvec3 w(0.0);
  bool drawn = false;
  // Below 1e-9 sr the angles' rounding dominates the area; so small a
  // triangle has about the same kernel over it, and a point uniform by area
  // serves. So does one whose directions all but graze x's horizon (no
  // direction kept in 64 tries: their cosines are all far below the
  // largest). A direction is kept with probability cos / (the largest cos).
  if (T.area > 1e-9 && std::isfinite(T.area)) {
    T.ca = std::cos(T.alpha), T.sa = std::sin(T.alpha), T.cosAB = glm::dot(T.A, T.B);
    T.Cperp = unitOr(T.C - glm::dot(T.C, T.A) * T.A, T.C);
    const glm::dvec3 corners[3] = {T.A, T.B, T.C};
    const double top = largestCosine(N, corners);
    for (int k = 0; k < 64 && !drawn && top > 0; ++k) {
      const double u1 = rng.next(), u2 = rng.next();
      w = arvoDirection(T, u1, u2);
      drawn = double(rng.next()) * top < glm::dot(N, w);
    }
  }
  if (!drawn) {
    const glm::vec2 ub = uniformTriangle({rng.next(), rng.next()});
    w = unitOr(double(ub.x) * da + double(ub.y) * db + double(1.f - ub.x - ub.y) * dc, T.A);
  }
  return castToPlane(caster, x, w, nt, da, eps);
}

}  // namespace gi
