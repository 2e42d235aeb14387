// The ambient-occlusion test scene where sharing or splitting can go wrong
// (a crease with a contact shadow, a sphere resting on the floor, a thin
// disc hovering over it), its regions, its per-vertex reference and the
// error statistics the AO estimators' tests check (test_ao_shared.cpp,
// test_ao_strata.cpp).
#pragma once
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gi/ambient.h"
#include "gi/scenes.h"

namespace gi::test {

// AO at distance d from a wall of height H on an infinite floor (docs/design.md,
// "Analytic references").
inline double wallAO(double d, double H) { return 0.5 + d / (2.0 * std::sqrt(d * d + H * H)); }

// Appends `part` with x -> x * scale + offset (scale per axis) to `s`.
inline void appendScaled(Scene& s, const Scene& part, const glm::dvec3& scale, const glm::dvec3& offset) {
  std::vector<glm::dvec3> pts;
  for (const auto& p : part.positions) pts.push_back(part.toWorld(p) * scale + offset);
  const Scene t = Scene::fromAbsolute(pts, part.triangles);
  if (s.positions.empty()) s = t;
  else s.append(t);
}

// The test scene, 2 x 2 units of floor (z = 0, 80 x 80 patches), a wall
// 0.5 high along its x = 0 edge (80 x 20 patches, a crease with a contact
// shadow), a sphere of radius 0.25 resting on the floor (icosphere, 2562
// vertices: its contact point), and a thin disc (an icosphere flattened to
// half-thickness 0.01, radius 0.35) hovering 0.04 above the floor: its two
// sides see the sky and the floor, 0.02 apart, joined by a sharp rim.
struct TestScene {
  Scene s;
  size_t floor0 = 0, wall0 = 0, sphere0 = 0, disc0 = 0, end = 0;
};

inline const glm::dvec3 kSphereCentre{1.45, 0.55, 0.25};
inline const glm::dvec3 kDiscCentre{1.2, 1.4, 0.05};

inline TestScene makeScene() {
  TestScene t;
  t.floor0 = 0;
  appendScaled(t.s, scenes::openPlane(2.0, 80).scene, {1, 1, 1}, {1.0, 1.0, 0.0});
  t.wall0 = t.s.vertexCount();
  // openPlane faces +z; the wall faces +x: (x, y, z) -> (z', y, x') rotates +z onto +x
  // with counter-clockwise order kept (a proper rotation about y).
  {
    Scene w = scenes::openPlane(1.0, 20).scene;
    std::vector<glm::dvec3> pts;
    for (const auto& p : w.positions) {
      const glm::dvec3 q = w.toWorld(p);  // q in [-0.5, 0.5]^2 x {0}
      pts.push_back({q.z, 1.0 + 2.0 * q.y, 0.25 - 0.5 * q.x});
    }
    t.s.append(Scene::fromAbsolute(pts, w.triangles));
  }
  t.sphere0 = t.s.vertexCount();
  appendScaled(t.s, scenes::sphere(1.0, 4, false).scene, {0.25, 0.25, 0.25}, kSphereCentre);
  t.disc0 = t.s.vertexCount();
  appendScaled(t.s, scenes::sphere(1.0, 4, false).scene, {0.35, 0.35, 0.01}, kDiscCentre);
  t.end = t.s.vertexCount();
  return t;
}

// The places where pooling neighbours is wrong, and everything.
struct Region {
  std::string name;
  std::vector<size_t> v;
};

inline std::vector<Region> regions(const TestScene& t) {
  Region crease{"crease and its contact shadow (floor within 0.15 of the wall, wall below 0.15)", {}},
      contact{"sphere resting on the floor (floor within 0.3 of the contact point, sphere below z = 0.1)", {}},
      thin{"thin disc (both sides and the rim) and the floor under it", {}},
      edge{"the floor along the disc's shadow edge (0.3 to 0.45 from its axis)", {}}, all{"all vertices", {}};
  for (size_t i = 0; i < t.end; ++i) {
    const glm::dvec3 p = t.s.toWorld(t.s.positions[i]);
    all.v.push_back(i);
    if ((i < t.wall0 && p.x < 0.15) || (i >= t.wall0 && i < t.sphere0 && p.z < 0.15)) crease.v.push_back(i);
    const double dContact = glm::length(glm::dvec2(p.x - kSphereCentre.x, p.y - kSphereCentre.y));
    if ((i < t.wall0 && dContact < 0.3) || (i >= t.sphere0 && i < t.disc0 && p.z < 0.1)) contact.v.push_back(i);
    const double dDisc = glm::length(glm::dvec2(p.x - kDiscCentre.x, p.y - kDiscCentre.y));
    if (i >= t.disc0 || (i < t.wall0 && dDisc < 0.45)) thin.v.push_back(i);
    if (i < t.wall0 && dDisc > 0.3 && dDisc < 0.45) edge.v.push_back(i);
  }
  return {crease, contact, thin, edge, all};
}

inline AmbientResult run(const Scene& s, const AmbientOptions& o) {
  auto caster = makeEmbreeCaster(s, BatchMode::Single);
  return computeAmbient(s, *caster, o);
}

// The reference: the per-vertex estimator (tested against analytic values in
// test_ambient.cpp) with 2048 rays per vertex and another seed. Its standard
// error is at most sqrt(p(1-p)/2048) <= 0.011 (binomial; its scrambled Sobol
// directions do better, about N^-3/4).
inline const AmbientResult& reference(const Scene& s) {
  static const AmbientResult r = [&] {
    AmbientOptions o;
    o.raysPerVertex = 2048;
    o.seed = 987654;
    return run(s, o);
  }();
  return r;
}

inline const TestScene& scene() {
  static const TestScene t = makeScene();
  return t;
}

struct Errors {
  double rms = 0;     // RMS of (shared - reference)
  double meanZ2 = 0;  // mean of (shared - reference)^2 / se_shared^2
  double tail = 0;    // fraction with |shared - reference| > 4 max(target, se_shared)
  double worst = 0;   // largest |shared - reference|
};

// The reference's own error is left in (it only makes the checks harder to
// pass): with 2048 scrambled Sobol rays it is about 0.003 or less, small
// against the errors checked (0.01 and up).
inline Errors errors(const AmbientResult& a, const AmbientResult& ref, const std::vector<size_t>& v, double target) {
  Errors e;
  size_t far = 0;
  for (size_t i : v) {
    const double d = double(a.value[i]) - double(ref.value[i]), sa = a.stdError[i];
    e.rms += d * d;
    e.meanZ2 += d * d / std::max(1e-12, sa * sa);
    if (std::fabs(d) > 4.0 * std::max(target, sa)) ++far;
    e.worst = std::max(e.worst, std::fabs(d));
  }
  const double m = double(v.size());
  e.rms = std::sqrt(e.rms / m);
  e.meanZ2 /= m;
  e.tail = double(far) / m;
  return e;
}

}  // namespace gi::test
