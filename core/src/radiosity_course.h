// Course outputs of the radiosity solvers: the ambient term of progressive
// refinement (Cohen et al. 1988, "A progressive refinement approach to fast
// radiosity image generation"):
//   A = 1 / (1 - rho_avg) * sum_j A_j dB_j / sum_j A_j,   B_i,display = B_i + rho_i A
// (per colour channel: rho_avg the area-weighted mean reflectance, dB_j the
// unshot radiosity),
// and snapshots of B after chosen steps. Internal to gi_core.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "gi/params.h"
#include "gi/radiosity.h"
#include "gi/scene.h"

namespace gi {

std::vector<ParamSpec> radiosityCourseSpecs();

// The ambient radiosity A above, RGB (0 for a scene without area).
glm::vec3 ambientRadiosity(const std::vector<double>& A, const std::vector<glm::vec3>& rho,
                           const std::vector<glm::vec3>& dB);
// The area mean reflectance rho-bar it assumes, RGB (0 without area).
glm::vec3 areaMeanReflectance(const std::vector<double>& A, const std::vector<glm::vec3>& rho);

// Keeps B per vertex (patch average) after the steps of opt.snapshotSteps.
class SnapshotTaker {
 public:
  SnapshotTaker(const Scene& s, const std::vector<glm::vec3>& E, const std::vector<glm::vec3>& rho,
                const std::vector<double>& A, const RadiosityOptions& opt, RadiosityResult& res);
  bool wants(long step) const;
  // R: the reflected radiosity after `step`; dB: the unshot radiosity
  // (progressive refinement; its ambient term when the option is on).
  void take(long step, const std::vector<glm::vec3>& R, const std::vector<glm::vec3>* dB);
  // Steps not reached take the final state (R with its ambient term).
  void finish(const std::vector<glm::vec3>& R, const glm::vec3& ambient);

 private:
  void keep(int step, int reached, double residual, const std::vector<glm::vec3>& R, const glm::vec3& ambient);
  const Scene& s_;
  const std::vector<glm::vec3>& E_;
  const std::vector<glm::vec3>& rho_;
  const std::vector<double>& A_;
  const RadiosityOptions& opt_;
  RadiosityResult& res_;
  std::vector<int> pending_;  // sorted, not yet taken
  double P_ = 0;              // emitted power (luminance), for step 0's unshot fraction
};

}  // namespace gi
