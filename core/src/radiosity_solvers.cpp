#include "radiosity_solvers.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gi/color.h"
#include "radiosity_course.h"

namespace gi::radiosity {

glm::vec3 gather(const FormFactorRow& r, const std::vector<glm::vec3>& B) {
  glm::dvec3 h(0.0);
  for (size_t k = 0; k < r.j.size(); ++k) h += double(r.F[k]) * glm::dvec3(B[r.j[k]]);
  return glm::vec3(h);
}

// The bound r on the spectral radius of rho F: the largest reflectance
// channel, times the largest row sum of F where one exceeds 1 (analytic
// quadrature). Rows are read only when they are in memory; computed on the
// fly they come from Monte Carlo or hemicube rows (sums <= 1) or are too
// costly to read twice.
double spectralBound(const Setup& u, const RowFn& row, bool rowsInMemory) {
  double rhoMax = 0, rowMax = 1;
  for (size_t i = 0; i < u.n; ++i) {
    if (u.A[i] == 0) continue;
    rhoMax = std::max({rhoMax, double(u.rho[i].r), double(u.rho[i].g), double(u.rho[i].b)});
    if (!rowsInMemory) continue;
    double sum = 0;
    for (float F : row(uint32_t(i)).F) sum += F;
    rowMax = std::max(rowMax, sum);
  }
  return rhoMax * rowMax;
}

namespace {

// A solve stopped by max_iterations before its tolerance: a warning with the
// possible error. The remaining reflected power M is at most residual x P x
// r / (1 - r) (each further sweep returns at most r of the last change, or
// of the unshot power); with F the power found so far, the converged total
// is F + M, of which M / (F + M) (increasing in M: the bound gives a bound)
// is missing: a bound on the total, not on each patch (a Cornell box after
// one Jacobi sweep: 32% stated, 11.7% short in all, one patch 92%).
void warnIfNotConverged(const Setup& u, const std::vector<glm::vec3>& R, double residual, double tol, double r,
                        int maxIter, const char* per, RunStats& st) {
  if (residual < tol) return;
  double found = u.P;
  for (size_t i = 0; i < u.n; ++i) found += u.A[i] * luminance(R[i]);
  const double missing = residual * u.P * r / (1.0 - r);
  char b[480];
  if (r < 1.0)
    std::snprintf(b, sizeof b,
                  "not converged: stopped at max_iterations = %d %s with the residual %.3g above the tolerance %.3g; "
                  "with reflectance up to %.4g the total radiosity (the power the surfaces send) may be short by up "
                  "to %.1f%% of its converged value, patches far from the lights by more (raise max_iterations, or "
                  "0 = automatic)",
                  maxIter, per, residual, tol, r, std::ceil(1000.0 * missing / (found + missing)) / 10.0);
  else
    std::snprintf(b, sizeof b,
                  "not converged: stopped at max_iterations = %d %s with the residual %.3g above the tolerance %.3g; "
                  "reflectance x form-factor row sums reach %.4g >= 1, so the iteration need not converge at all",
                  maxIter, per, residual, tol, r);
  st.warn(b);
}

// Books one sweep that changed the reflected power by `change`; true when
// the solve has converged.
bool endSweep(const Setup& u, const Stopping& stop, int it, double change, const Progress& progress,
              RadiosityResult& res) {
  res.residual = change / u.P;
  res.residualHistory.push_back(res.residual);
  res.iterations = it + 1;
  const int sweeps = stop.fixed ? stop.bounces : stop.maxIter;
  progress.report(stop.fixed ? double(it + 1) / sweeps
                             : std::min(1.0, std::log(res.residual + 1e-300) / std::log(stop.tol)),
                  "solving");
  return !stop.fixed && res.residual < stop.tol;
}

}  // namespace

// Jacobi: R <- S + rho F R for all patches from the last iterate (sweep k
// adds bounce k). With a fixed bounce count, *prevR gets the iterate before
// the last sweep (zero for no sweep at all: no indirect light at vertices)
// and res.Rbounces the iterates the final gather reads (keptBounce).
void jacobi(const Setup& u, const RowFn& row, const std::vector<glm::vec3>& S, const Stopping& stop,
            const Progress& progress, std::vector<glm::vec3>& R, std::vector<glm::vec3>* prevR, RadiosityResult& res) {
  const int sweeps = stop.fixed ? stop.bounces : stop.maxIter;
  std::vector<glm::vec3> Rn = R;
  if (prevR) prevR->assign(u.n, glm::vec3(0.f));
  if (prevR) res.Rbounces.assign(size_t(std::max(0, sweeps)), {});
  for (int it = 0; it < sweeps; ++it) {
    if (prevR) *prevR = R;
    if (prevR && keptBounce(it + 1, sweeps)) res.Rbounces[size_t(it)] = R;  // R^(it + 1)
    parallelBlocks(u.n, Progress(nullptr), "", [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i)
        Rn[i] = (u.A[i] > 0 && u.rho[i] != glm::vec3(0.f)) ? S[i] + u.rho[i] * gather(row(uint32_t(i)), R) : S[i];
    });
    double change = 0;
    for (size_t i = 0; i < u.n; ++i) change += u.A[i] * std::fabs(luminance(Rn[i] - R[i]));
    R.swap(Rn);
    const bool done = endSweep(u, stop, it, change, progress, res);
    if (stop.observe) stop.observe(it + 1, R, nullptr);
    if (done) break;
  }
  if (!stop.fixed) warnIfNotConverged(u, R, res.residual, stop.tol, stop.r, stop.maxIter, "sweeps", res.stats);
}

// Gauss-Seidel: the same update in place, each patch reading the values
// already updated in this sweep (fewer sweeps; sequential).
void gaussSeidel(const Setup& u, const RowFn& row, const std::vector<glm::vec3>& S, const Stopping& stop,
                 const Progress& progress, std::vector<glm::vec3>& R, RadiosityResult& res) {
  for (int it = 0; it < stop.maxIter; ++it) {
    double change = 0;
    for (size_t i = 0; i < u.n; ++i) {
      if (u.A[i] == 0 || u.rho[i] == glm::vec3(0.f)) continue;
      const glm::vec3 nb = S[i] + u.rho[i] * gather(row(uint32_t(i)), R);
      change += u.A[i] * std::fabs(luminance(nb - R[i]));
      R[i] = nb;
    }
    const bool done = endSweep(u, stop, it, change, progress, res);
    if (stop.observe) stop.observe(it + 1, R, nullptr);
    if (done) break;
  }
  warnIfNotConverged(u, R, res.residual, stop.tol, stop.r, stop.maxIter, "sweeps", res.stats);
}

namespace {

// Ambient term for display (Cohen et al. 1988): the unshot radiosity dB
// spread evenly, amplified by the mean inter-reflection 1 / (1 - rho_avg).
glm::vec3 ambientTerm(const Setup& u, const std::vector<glm::vec3>& dB) { return ambientRadiosity(u.A, u.rho, dB); }

}  // namespace

// Progressive refinement: shoot the unshot radiosity dB of the patch with
// the most unshot power A_i dB_i (Cohen et al. 1988). With rows in memory
// (transpose) the receivers' gain is read from their own rows, dB_j = rho_j
// F_ji dB_i (Southwell relaxation of the very system Jacobi and Gauss-Seidel
// solve, so all solvers agree); with rows on the fly, from the shooter's row
// by reciprocity, dB_j = rho_j dB_i F_ij A_i / A_j (the classical form; Monte
// Carlo rows are reciprocal only in expectation).
void progressiveRefinement(const Setup& u, const RowFn& row, bool transpose, const std::vector<glm::vec3>& S,
                           const Stopping& stop, const Progress& progress, std::vector<glm::vec3>& R,
                           RadiosityResult& res) {
  std::vector<std::vector<std::pair<uint32_t, float>>> columns;
  if (transpose) {
    columns.resize(u.n);
    for (size_t j = 0; j < u.n; ++j) {
      const FormFactorRow& r = row(uint32_t(j));
      for (size_t k = 0; k < r.j.size(); ++k) columns[r.j[k]].push_back({uint32_t(j), r.F[k]});
    }
  }
  // R and dB are kept in double (their float copies, which the snapshots
  // read, follow each change): a patch receives a small gain from every
  // shot, hundreds of thousands of them at high reflectance, and float
  // sums rounded them away (a closed box at rho 0.999 stalled 0.16% low).
  std::vector<glm::vec3> dB = S;
  std::vector<glm::dvec3> Rd(R.begin(), R.end()), dBd(S.begin(), S.end());
  std::vector<double> unshot(u.n);
  double U = 0;
  for (size_t i = 0; i < u.n; ++i) { unshot[i] = u.A[i] * glm::dot(dBd[i], kLuminanceWeights); U += unshot[i]; }
  const long maxShots = long(stop.maxIter) * long(std::max<size_t>(u.n, 1));
  long shots = 0;
  if (stop.observe) stop.observe(0, R, &dB);
  auto receive = [&](uint32_t j, const glm::dvec3& d) {
    Rd[j] += d;
    dBd[j] += d;
    R[j] = glm::vec3(Rd[j]);
    dB[j] = glm::vec3(dBd[j]);
    const double nu = u.A[j] * glm::dot(dBd[j], kLuminanceWeights);
    U += nu - unshot[j];
    unshot[j] = nu;
  };
  while (U / u.P > stop.tol && shots < maxShots) {
    const size_t i = size_t(std::max_element(unshot.begin(), unshot.end()) - unshot.begin());
    if (!(unshot[i] > 0)) break;
    const glm::dvec3 shoot = dBd[i];
    dBd[i] = glm::dvec3(0.0);
    dB[i] = glm::vec3(0.f);
    U -= unshot[i];
    unshot[i] = 0;
    if (transpose) {
      for (const auto& [j, F] : columns[i])
        if (u.rho[j] != glm::vec3(0.f)) receive(j, glm::dvec3(u.rho[j]) * shoot * double(F));
    } else {
      const FormFactorRow& r = row(uint32_t(i));
      for (size_t k = 0; k < r.j.size(); ++k) {
        const uint32_t j = r.j[k];
        if (u.rho[j] == glm::vec3(0.f) || !(u.A[j] > 0)) continue;  // black receivers reflect nothing
        receive(j, glm::dvec3(u.rho[j]) * shoot * (double(r.F[k]) * u.A[i] / u.A[j]));
      }
    }
    ++shots;
    if (shots % long(std::max<size_t>(u.n, 1)) == 0) {  // re-sum: no drift
      U = 0;
      for (double x : unshot) U += x;
    }
    res.residualHistory.push_back(U / u.P);
    if (stop.observe) stop.observe(shots, R, &dB);
    if ((shots & 255) == 0) progress.report(std::min(1.0, std::log(U / u.P + 1e-300) / std::log(stop.tol)), "shooting");
  }
  res.iterations = int(shots);
  res.residual = U / u.P;
  if (shots >= maxShots)
    warnIfNotConverged(u, R, res.residual, stop.tol, stop.r, stop.maxIter, "shots per patch", res.stats);
  res.ambient = ambientTerm(u, dB);
  res.ambientRho = areaMeanReflectance(u.A, u.rho);
}

}  // namespace gi::radiosity
