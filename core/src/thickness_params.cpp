// Parameter table of the thickness filter (MeshLab dialog and CLI flags).
#include "gi/thickness.h"

namespace gi {

std::vector<ParamSpec> ThicknessOptions::specs() {
  std::vector<ParamSpec> s;
  s.push_back({.name = "rays_per_vertex", .label = "Rays per vertex",
               .help = "Rays cast into the object from each vertex when no target error is set. Shapira et al. "
                       "(2008) used 30; our scrambled Sobol directions make 64 smooth on most meshes. Cost is linear "
                       "in it.",
               .type = ParamType::Int, .def = 64, .min = 1, .max = 1 << 20});
  s.push_back({.name = "target_error", .label = "Target relative error",
               .help = "Adaptive sampling: if > 0, each vertex casts rays in rounds of 32 until the standard error "
                       "of its mean length is below this fraction of the mean (0.01 = 1%), between the minimum and "
                       "maximum ray counts. 0 = fixed ray count.",
               .type = ParamType::Float, .def = 0.0, .min = 0.0, .max = 0.5});
  s.push_back({.name = "min_rays", .label = "Minimum rays (adaptive)",
               .help = "Adaptive sampling never stops before this many rays.",
               .type = ParamType::Int, .def = 32, .min = 1, .max = 1 << 20});
  s.push_back({.name = "max_rays", .label = "Maximum rays (adaptive)",
               .help = "Adaptive sampling never casts more than this many rays.",
               .type = ParamType::Int, .def = 4096, .min = 1, .max = 1 << 22});
  s.push_back({.name = "cone_angle", .label = "Cone half-angle (deg)",
               .help = "Rays go into the object within this angle of the inward normal (cosine-distributed). A "
                       "wider cone averages over more of the opposite side (robust on noisy meshes) but reads longer, "
                       "slanted chords. Their plain mean (Reject outliers off): a sphere of radius r gives "
                       "(4r/3)(1 + c + c^2)/(1 + c) with c = cos(angle), a slab of thickness t gives 2t/(1 + c), a "
                       "cylinder exactly its diameter; the robust mean (on, the default) trims both tails: at 60 "
                       "degrees 1.598 r, 1.210 t and 0.982 times the diameter (plain: 1.556 r, 1.333 t, 1). Both "
                       "reach 2r, t and the diameter as the angle goes to 0. Shapira et al. (2008): 60 (a 120 degree "
                       "cone).",
               .type = ParamType::Float, .def = 60.0, .min = 0.5, .max = 89.0});
  s.push_back({.name = "reject_outliers", .label = "Reject outliers",
               .help = "Average only the lengths within one standard deviation of their median (Shapira et al. "
                       "2008), so that rays slipping through a gap or along a fin do not count; needs 16 rays or "
                       "more (fewer: the window comes from too few lengths, and the log warns). Off: the plain mean.",
               .type = ParamType::Bool, .def = true});
  s.push_back(seedSpec("ray directions"));
  return s;
}

ThicknessOptions ThicknessOptions::fromParams(const ParamValues& v) {
  ThicknessOptions o;
  o.raysPerVertex = v.getInt("rays_per_vertex");
  o.targetError = v.getFloat("target_error");
  o.minRays = v.getInt("min_rays");
  o.maxRays = v.getInt("max_rays");
  o.coneAngleDeg = float(v.getFloat("cone_angle"));
  o.rejectOutliers = v.getBool("reject_outliers");
  o.seed = uint32_t(v.getInt("seed"));
  return o;
}

}  // namespace gi
