// Closed-form configuration factors and the three methods beside them (the
// course's "form factors: closed form against the methods"). From J. R.
// Howell, "A Catalog of Radiation Heat Transfer Configuration Factors":
//  - C-11, identical parallel directly opposed rectangles a x b at distance c,
//    x = a/c, y = b/c:
//      F = 2/(pi x y) { ln sqrt[(1+x^2)(1+y^2)/(1+x^2+y^2)] + x sqrt(1+y^2) atan(x/sqrt(1+y^2))
//                       + y sqrt(1+x^2) atan(y/sqrt(1+x^2)) - x atan x - y atan y };
//  - C-14, rectangles at 90 degrees with a common edge of length l, from the
//    one of width w to the one of height h, W = w/l, H = h/l:
//      F = 1/(pi W) [ W atan(1/W) + H atan(1/H) - sqrt(H^2+W^2) atan(1/sqrt(H^2+W^2))
//          + 1/4 ln( (1+W^2)(1+H^2)/(1+W^2+H^2) [W^2(1+W^2+H^2)/((1+W^2)(W^2+H^2))]^(W^2)
//                    [H^2(1+H^2+W^2)/((1+H^2)(H^2+W^2))]^(H^2) ) ];
//  - C-41, coaxial parallel disks of radii ri (source) and rj at distance L,
//    Ri = ri/L, Rj = rj/L, S = 1 + (1 + Rj^2)/Ri^2:
//      F = (S - sqrt(S^2 - 4 (rj/ri)^2)) / 2.
// The scenes are meshed as a student would: each rectangle two triangles, a
// disk a polar grid; F of the source to the target is the area-weighted mean
// over the source's triangles of their row sums to the target's (as `gi
// formfactors --face_index i` gives one triangle's row).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "gi/form_factors.h"
#include "gi/scene.h"

namespace gi {

double parallelRectanglesF(double a, double b, double c);
double perpendicularRectanglesF(double w, double h, double l);
double coaxialDisksF(double ri, double rj, double L);

// A configuration meshed: the source's faces are [0, split), the target's
// [split, n); F its closed form; meshError the relative error the meshing
// itself may cause (a disk as a polygon: 2 (1 - polygon area / disk area);
// 0 for rectangles).
struct ClosedFormScene {
  std::string name;
  Scene scene;
  uint32_t split = 0;
  double F = 0;
  double meshError = 0;
};
// Throw std::invalid_argument unless every dimension is finite and > 0.
ClosedFormScene parallelRectanglesScene(double a, double b, double c);
ClosedFormScene perpendicularRectanglesScene(double w, double h, double l);
ClosedFormScene coaxialDisksScene(double ri, double rj, double L, int rings = 2, int segments = 64);

// F of the source to the target by one method.
double sourceToTargetF(const ClosedFormScene& c, const FormFactors::Settings& set);

// Each method with the tolerance it is held to (relative to the closed form):
//  - Monte Carlo: four binomial standard errors of the area-weighted F,
//    4 sqrt((1 - F) / (n_source N F)) for N rays per source triangle (a
//    correct estimator is outside with probability below 1e-4), at least
//    0.5%;
//  - analytic point-to-polygon: 0.5% (its adaptive midpoint rule refines to
//    about 0.3% of F, gi/form_factor_analytic.h);
//  - hemicube: 2% with at least 129 views per triangle and 128 cells across
//    (measured at most 0.84% on the catalogue cases); with fewer views none
//    (NaN): one view is the classic approximation, off by up to 89% for
//    patches large against their distance;
// each plus the meshing error.
struct MethodEstimate {
  FormFactorMethod method;
  double F = 0;
  double tolerance = 0;  // relative; NaN: the method states none for these settings
  double relError = 0;   // F / closed - 1
  bool within() const;   // |relError| <= tolerance, or no tolerance stated
};
struct ClosedFormComparison {
  std::string name;
  double closed = 0;
  size_t sourceFaces = 0, targetFaces = 0;
  std::vector<MethodEstimate> methods;  // Monte Carlo, analytic, hemicube
};
struct ComparisonSettings {
  int raysPerPatch = 262144;
  int analyticPoints = 4;
  int hemicubeResolution = 128;
  int hemicubePoints = 129;
  uint32_t seed = 0;
};
ClosedFormComparison compareWithClosedForm(const ClosedFormScene& c, const ComparisonSettings& set);

}  // namespace gi
