// The iterative solvers of the radiosity system R = S + rho F R (R the
// reflected radiosity, S = rho H_direct the once-reflected direct light, F
// the form factors): Jacobi, Gauss-Seidel (Cohen and Wallace 1993, ch. 5)
// and progressive refinement with its ambient term (Cohen et al. 1988),
// with the stopping rule, the bound on the spectral radius of rho F and the
// warning when a solve stops before its tolerance. The rows of F come from
// a function (in memory or computed on the fly). Internal to gi_core.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "gi/form_factors.h"
#include "gi/radiosity.h"
#include "gi/run.h"

namespace gi::radiosity {

using RowFn = std::function<const FormFactorRow&(uint32_t)>;

// One solve's patches: areas (0: unusable), emission, reflectance, direct
// irradiance (the emitters', the sky's and the sun's), and the power in.
struct Setup {
  size_t n;
  std::vector<double> A;
  std::vector<glm::vec3> E, rho, Hd;  // emission, reflectance, direct irradiance
  double P = 0;  // emitted power and the power entering from the sky and the sun (luminance), local units
  double Pout = 0;  // the latter alone
  double unit2 = 1;  // world area of one local unit of area (Scene::unit^2)
};

// When a solver stops: after exactly `bounces` Jacobi sweeps (fixed, bounces
// >= 0), or when the residual falls below tol, after at most maxIter sweeps
// (shots per patch for progressive refinement); r bounds the spectral
// radius of rho F (for the warning when maxIter stops it first).
struct Stopping {
  bool fixed = false;
  int bounces = -1;
  double tol = 1e-4;
  int maxIter = 0;
  double r = 0;
  // Called after each step (sweep or shot) with the step count, R and, for
  // progressive refinement, the unshot dB: the snapshots.
  std::function<void(long, const std::vector<glm::vec3>&, const std::vector<glm::vec3>*)> observe;
};

// The irradiance a patch gathers through its row: sum_j F_ij B_j.
glm::vec3 gather(const FormFactorRow& r, const std::vector<glm::vec3>& B);

// The bound r on the spectral radius of rho F (see the definition).
double spectralBound(const Setup& u, const RowFn& row, bool rowsInMemory);

// Jacobi sweeps; with a fixed bounce count (prevR given), *prevR is the
// iterate before the last sweep and res.Rbounces the ones the final gather
// reads.
void jacobi(const Setup& u, const RowFn& row, const std::vector<glm::vec3>& S, const Stopping& stop,
            const Progress& progress, std::vector<glm::vec3>& R, std::vector<glm::vec3>* prevR, RadiosityResult& res);

// Gauss-Seidel sweeps in place.
void gaussSeidel(const Setup& u, const RowFn& row, const std::vector<glm::vec3>& S, const Stopping& stop,
                 const Progress& progress, std::vector<glm::vec3>& R, RadiosityResult& res);

// Progressive refinement (shooting); res.ambient gets the ambient term of
// the unshot radiosity left. transpose: the rows are in memory (the
// receivers' own rows are read, as columns).
void progressiveRefinement(const Setup& u, const RowFn& row, bool transpose, const std::vector<glm::vec3>& S,
                           const Stopping& stop, const Progress& progress, std::vector<glm::vec3>& R,
                           RadiosityResult& res);

}  // namespace gi::radiosity
