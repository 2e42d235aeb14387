// Thickness per vertex: the shape diameter function (Shapira, Shamir and
// Cohen-Or 2008, "Consistent mesh partitioning and skeletonisation using the
// shape diameter function"): rays from the vertex into the object, in a cone
// of half-angle alpha around the inward normal -n, each measuring the length
// L(w) to the opposite side; the SDF is their mean, made robust by keeping
// only the lengths within one standard deviation of their median (theirs).
//   SDF(p) = E[L(w)],  w cosine-distributed in the cone:
//            pdf(w) = cos(theta) / (pi sin^2 alpha),  theta <= alpha
// (AO's sampling restricted to the cone: cos^2(theta) is uniform on
// [cos^2 alpha, 1]). Exact values of the plain mean (tests/unit/test_thickness.cpp):
//   sphere of radius r:   L = 2 r cos(theta),  SDF = (4r/3) (1 + c + c^2) / (1 + c),  c = cos alpha
//   infinite cylinder R:  L = 2R c / (c^2 + s^2 cos^2 phi), whose mean over the azimuth phi
//                         is 2R at every theta, so SDF = 2R (its diameter) for any cone
//   slab of thickness t:  L = t / cos(theta),  SDF = 2t / (1 + c)  (t as alpha -> 0)
// A ray counts only if its first hit is the back of a face (it leaves the
// object there); rays that miss or meet a front face (an open mesh, inward
// normals, an inner shell) are left out, as in the paper.
#pragma once
#include <cstdint>
#include <vector>

#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/run.h"
#include "gi/scene.h"

namespace gi {

struct ThicknessOptions {
  int raysPerVertex = 64;      // fixed count when targetError == 0
  double targetError = 0.0;    // adaptive: relative standard error of the mean to stop at
  int minRays = 32, maxRays = 4096;
  float coneAngleDeg = 60.f;   // half-angle (the paper's 120 degree cone)
  bool rejectOutliers = true;  // keep the lengths within one standard deviation of the median
  uint32_t seed = 0;

  static std::vector<ParamSpec> specs();
  static ThicknessOptions fromParams(const ParamValues& v);
};

struct ThicknessResult {
  std::vector<float> value;     // SDF in world units; 0 where no ray found the opposite side
  std::vector<float> stdError;  // standard error of the mean (world units); the scene's diagonal where nothing was measured
  std::vector<int> rays;        // rays cast
  std::vector<int> hits;        // rays that met the back of a face (those averaged, before trimming)
  RunStats stats;
};

// Vertex normals: scene.vertexNormals if given, else computed from faces.
ThicknessResult computeThickness(const Scene& scene, const RayCaster& caster, const ThicknessOptions& opt,
                                 const Progress& progress = Progress(nullptr));

// The robust mean of lengths (sorted in place): the mean of those within one
// standard deviation of the median (or of all, if !reject), with its
// standard error (a trimmed mean's: the winsorised standard deviation over
// (k / n) sqrt(n), Tukey and McLaughlin 1963); count = how many were averaged.
struct RobustMean {
  double mean = 0.0, stdError = 0.0;
  size_t count = 0;
};
RobustMean robustMean(std::vector<float>& lengths, bool reject);
// Fewer rays than this with reject_outliers are warned about (the window
// comes from too few lengths: error bars too small, value biased).
constexpr int kRobustMinRays = 16;

}  // namespace gi
