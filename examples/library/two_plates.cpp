// The engine as a library: a scene built from arrays, its form factors,
// radiosity and ambient occlusion, each checked against its closed form.
//
// Two parallel unit squares one unit apart: the top one emits E = 1 W/m^2
// (reflectance 0), the bottom one, cut into 8 x 8 cells, reflects 0.5.
//   - The form factor from the bottom square to the top one has Howell's
//     closed form (parallel rectangles, catalogue C-11): 0.19982.
//   - The bottom's radiosity is rho E F_i,top per patch, so its area mean
//     is 0.5 x 0.19982 (the light it sends up is absorbed by the black top).
//   - Ambient occlusion at a bottom vertex x is 1 - F(x -> top), the
//     point-to-polygon factor (Lambert's contour integral).
// Exit status 0 when all three agree within their stated tolerances.
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "gi/ambient.h"
#include "gi/form_factor_analytic.h"
#include "gi/form_factor_closed.h"
#include "gi/form_factors.h"
#include "gi/radiosity.h"
#include "gi/raycaster.h"
#include "gi/scene.h"

namespace {

// An n x n grid of the unit square at height y, its triangles facing up or down.
void addSquare(std::vector<glm::dvec3>& pts, std::vector<glm::uvec3>& tris, double y, int n, bool up) {
  const uint32_t base = uint32_t(pts.size());
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) pts.push_back({double(i) / n, y, double(j) / n});
  auto at = [&](int i, int j) { return base + uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      // (i, j) -> (i, j + 1) -> (i + 1, j + 1) turns counter-clockwise seen from +y.
      const uint32_t a = at(i, j), b = at(i, j + 1), c = at(i + 1, j + 1), d = at(i + 1, j);
      if (up) tris.push_back({a, b, c}), tris.push_back({a, c, d});
      else tris.push_back({a, c, b}), tris.push_back({a, d, c});
    }
}

}  // namespace

int main() {
  const int n = 8;
  std::vector<glm::dvec3> pts;
  std::vector<glm::uvec3> tris;
  addSquare(pts, tris, 0.0, n, true);   // bottom: faces [0, 2n^2), facing +y
  const size_t bottomFaces = tris.size(), bottomVertices = pts.size();
  addSquare(pts, tris, 1.0, 1, false);  // top: two triangles facing -y
  gi::Scene scene = gi::Scene::fromAbsolute(pts, tris);
  // Per-face arrays: empty, or one entry per face (anything else is refused).
  scene.rho.assign(scene.faceCount(), glm::vec3(0.5f));
  scene.emission.assign(scene.faceCount(), glm::vec3(0.f));
  for (size_t f = bottomFaces; f < scene.faceCount(); ++f) scene.rho[f] = glm::vec3(0.f), scene.emission[f] = glm::vec3(1.f);
  // The caster must outlive everything that uses it, and be built from this scene.
  const auto caster = gi::makeEmbreeCaster(scene);
  bool ok = true;

  // 1. Form factors: each bottom patch's row, area-weighted.
  gi::FormFactors::Settings ffs;
  ffs.method = gi::FormFactorMethod::Analytic;
  ffs.analyticPoints = 16;
  const gi::FormFactors ff(scene, *caster, ffs);
  double FA = 0, A = 0;
  for (uint32_t i = 0; i < bottomFaces; ++i) {
    const gi::FormFactorRow row = ff.row(i);
    for (size_t k = 0; k < row.j.size(); ++k)
      if (row.j[k] >= bottomFaces) FA += ff.area(i) * row.F[k];
    A += ff.area(i);
  }
  const double F = FA / A, Fexact = gi::parallelRectanglesF(1.0, 1.0, 1.0);
  std::printf("form factor bottom -> top: %.5f, closed form %.5f (%+.2f%%)\n", F, Fexact, 100.0 * (F / Fexact - 1.0));
  ok &= std::fabs(F / Fexact - 1.0) < 0.002;

  // 2. Radiosity (the defaults: Gauss-Seidel, per-face B and per-vertex values).
  gi::RadiosityOptions ro;
  const gi::RadiosityResult rad = gi::solveRadiosity(scene, *caster, ro);
  double BA = 0;
  for (size_t f = 0; f < bottomFaces; ++f) BA += gi::faceArea(scene, f) * rad.B[f].g;
  const double B = BA / A, Bexact = 0.5 * Fexact;
  std::printf("mean radiosity of the bottom: %.5f W/m^2, closed form %.5f (%+.2f%%)\n", B, Bexact,
              100.0 * (B / Bexact - 1.0));
  ok &= std::fabs(B / Bexact - 1.0) < 0.005;

  // 3. Ambient occlusion at the bottom's vertices, with its error bars.
  gi::AmbientOptions ao;
  ao.raysPerVertex = 1024;
  const gi::AmbientResult occ = gi::computeAmbient(scene, *caster, ao);
  int outside = 0;
  double worst = 0;
  for (size_t v = 0; v < bottomVertices; ++v) {
    const glm::dvec3 x = pts[v];
    double Fx = 0;
    for (size_t f = bottomFaces; f < tris.size(); ++f)
      Fx += gi::pointToTriangleFormFactor(x, {0, 1, 0}, pts[tris[f].x], pts[tris[f].y], pts[tris[f].z]);
    const double err = occ.value[v] - (1.0 - Fx);
    worst = std::max(worst, std::fabs(err));
    outside += std::fabs(err) > 4.0 * occ.stdError[v] + 1e-4;
  }
  std::printf("ambient occlusion at %zu vertices: worst error %.5f, %d beyond 4 reported standard errors\n",
              bottomVertices, worst, outside);
  ok &= outside == 0;

  // 4. A mistake is an exception that names it, never a NaN.
  try {
    gi::RadiosityOptions bad;
    bad.gatherRays = 0;
    gi::solveRadiosity(scene, *caster, bad);
    ok = false;
  } catch (const std::invalid_argument& e) {
    std::printf("refused as expected: %s\n", e.what());
  }
  std::printf("%s\n", ok ? "all within tolerance" : "OUTSIDE TOLERANCE");
  return ok ? 0 : 1;
}
