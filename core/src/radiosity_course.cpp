#include "radiosity_course.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "gi/color.h"
#include "gi/scene_setup.h"

namespace gi {

std::vector<ParamSpec> radiosityCourseSpecs() {
  return {
      {.name = "ambient_term", .label = "Ambient term (progressive refinement)",
       .help = "Progressive refinement only. On: adds to each patch rho_i A, the light not yet shot spread evenly "
               "over the scene and reflected 1 / (1 - rho_avg) times, A = sum_j A_j dB_j / sum_j A_j / (1 - "
               "rho_avg) (Cohen et al. 1988, 'A progressive refinement approach to fast radiosity image "
               "generation'), so that images after few shots (a high tolerance, or the snapshots) have about the "
               "converged brightness: for display. It assumes a closed room (all light stays in the scene): where "
               "much leaves (an open floor, the Cornell box's open side) early images overshoot, which the log "
               "warns of. Off: B is the physical radiosity of the shots made so far. At convergence the term "
               "vanishes.",
       .type = ParamType::Bool, .def = false},
      {.name = "snapshot_steps", .label = "Snapshot steps",
       .help = "Comma-separated step counts, e.g. '0, 10, 100' (at most 64): after each, the patch-average "
               "radiosity B per vertex is kept as the attribute Radiosity_step_N (RGB, W/m^2; with the ambient "
               "term when it is on). A step is a sweep for Jacobi and Gauss-Seidel (with 'Bounces' k: bounce "
               "k), a shot of one patch for progressive refinement; step 0 is the direct light only. A step the "
               "solve does not reach keeps the final state (the log says so). Empty: no snapshots.",
       .type = ParamType::String, .defText = "",
       .checkText = [](const std::string& t) {
         try {
           (void)parseSnapshotSteps(t);
           return std::string();
         } catch (const std::invalid_argument& e) {
           return std::string(e.what());
         }
       }},
      {.name = "residual_csv", .label = "Residual per step (CSV file)",
       .help = "If not empty, a CSV file 'step,residual' written after the solve: per sweep the change of the "
               "reflected power, per shot (progressive refinement) the unshot power, both relative to the "
               "emitted power. The log shows the residual after steps 1, 2, 4, 8, ... and the last.",
       .type = ParamType::String, .defText = ""},
      {.name = "export_system", .label = "Export the linear system (path prefix)",
       .help = "If not empty, a path prefix: the system solved is written as Matrix Market files (1-based) so that "
               "B = E + rho F B can be solved elsewhere: PREFIX_F.mtx (form factors, sparse), PREFIX_E.mtx, "
               "PREFIX_rho.mtx, PREFIX_Esys.mtx (E + rho (H_direct - F E): with it the system has the filter's "
               "exact direct light), PREFIX_B.mtx (the filter's patch radiosity, to check against; without the "
               "ambient term, which only the display adds) and "
               "PREFIX_area.mtx (of the part the scene sees, where a patch is partly buried under another "
               "surface). Needs the form-factor matrix in memory (memory budget).",
       .type = ParamType::String, .defText = ""},
  };
}

namespace {

std::string denseMatrix(const std::vector<glm::vec3>& v, const char* what) {
  std::string out = "%%MatrixMarket matrix array real general\n% " + std::string(what) + "\n";
  out += std::to_string(v.size()) + " 3\n";
  char line[32];
  for (int c = 0; c < 3; ++c)  // column-major: all R, then G, then B
    for (const glm::vec3& x : v) {
      std::snprintf(line, sizeof line, "%.9g\n", double(x[c]));
      out += line;
    }
  return out;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> linearSystemFiles(const std::vector<FormFactorRow>& rows,
                                                                   const std::vector<double>& area,
                                                                   const std::vector<glm::vec3>& E,
                                                                   const std::vector<glm::vec3>& rho,
                                                                   const std::vector<glm::vec3>& Hd,
                                                                   const std::vector<glm::vec3>& B) {
  const size_t n = rows.size();
  size_t nnz = 0;
  for (const FormFactorRow& r : rows) nnz += r.j.size();
  std::string F = "%%MatrixMarket matrix coordinate real general\n"
                  "% form factors F_ij: row i, column j (patches = the mesh's triangles, 1-based)\n";
  F += std::to_string(n) + " " + std::to_string(n) + " " + std::to_string(nnz) + "\n";
  char line[64];
  std::vector<glm::vec3> Esys(n);
  for (size_t i = 0; i < n; ++i) {
    glm::dvec3 FE(0.0);
    for (size_t k = 0; k < rows[i].j.size(); ++k) {
      std::snprintf(line, sizeof line, "%zu %u %.9g\n", i + 1, rows[i].j[k] + 1, double(rows[i].F[k]));
      F += line;
      FE += double(rows[i].F[k]) * glm::dvec3(E[rows[i].j[k]]);
    }
    Esys[i] = glm::vec3(glm::dvec3(E[i]) + glm::dvec3(rho[i]) * (glm::dvec3(Hd[i]) - FE));
  }
  std::string A = "%%MatrixMarket matrix array real general\n% patch areas\n" + std::to_string(n) + " 1\n";
  for (double a : area) {
    std::snprintf(line, sizeof line, "%.9g\n", a);
    A += line;
  }
  return {{"_F.mtx", F},
          {"_E.mtx", denseMatrix(E, "emitted radiosity E (W/m^2), columns R, G, B")},
          {"_rho.mtx", denseMatrix(rho, "reflectance rho, columns R, G, B")},
          {"_Esys.mtx", denseMatrix(Esys, "E + rho (H_direct - F E): B = Esys + rho F B has the filter's B")},
          {"_B.mtx", denseMatrix(B, "the filter's patch radiosity B (W/m^2), columns R, G, B")},
          {"_area.mtx", A}};
}

std::vector<int> parseSnapshotSteps(const std::string& text) {
  std::vector<int> steps;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const size_t b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
    if (b == std::string::npos) continue;
    const std::string t = item.substr(b, e - b + 1);
    char* end = nullptr;
    const long v = std::strtol(t.c_str(), &end, 10);
    if (*end != '\0' || v < 0 || v > 1000000000L)
      throw std::invalid_argument("snapshot_steps: '" + t + "' is not a step count (whole numbers >= 0, comma-separated)");
    steps.push_back(int(v));
  }
  std::sort(steps.begin(), steps.end());
  steps.erase(std::unique(steps.begin(), steps.end()), steps.end());
  if (steps.size() > 64) throw std::invalid_argument("snapshot_steps: at most 64 steps (each is a per-vertex attribute)");
  return steps;
}

namespace {
glm::dvec3 areaMeanRho(const std::vector<double>& A, const std::vector<glm::vec3>& rho) {
  double Atot = 0;
  glm::dvec3 rhoA(0.0);
  for (size_t i = 0; i < A.size(); ++i) Atot += A[i], rhoA += A[i] * glm::dvec3(rho[i]);
  return Atot > 0 ? rhoA / Atot : glm::dvec3(0.0);
}
}  // namespace

glm::vec3 ambientRadiosity(const std::vector<double>& A, const std::vector<glm::vec3>& rho,
                           const std::vector<glm::vec3>& dB) {
  // Per colour channel, as Cohen et al. work per band: one grey rho_avg (the
  // channels' luminance mix) made a closed room of rho (0.79, 0.31, 0.05)
  // 34% dark in red after 306 shots instead of exact (an outside check).
  double Atot = 0;
  glm::dvec3 unshot(0.0);
  for (size_t i = 0; i < A.size(); ++i) {
    Atot += A[i];
    unshot += A[i] * glm::dvec3(dB[i]);
  }
  if (!(Atot > 0)) return glm::vec3(0.f);
  return glm::vec3(unshot / Atot / (glm::dvec3(1.0) - areaMeanRho(A, rho)));
}

glm::vec3 areaMeanReflectance(const std::vector<double>& A, const std::vector<glm::vec3>& rho) {
  return glm::vec3(areaMeanRho(A, rho));
}

SnapshotTaker::SnapshotTaker(const Scene& s, const std::vector<glm::vec3>& E, const std::vector<glm::vec3>& rho,
                             const std::vector<double>& A, const RadiosityOptions& opt, RadiosityResult& res)
    : s_(s), E_(E), rho_(rho), A_(A), opt_(opt), res_(res), pending_(opt.snapshotSteps) {
  std::sort(pending_.begin(), pending_.end());
  for (size_t i = 0; i < A.size(); ++i) P_ += A[i] * luminance(E[i]);
}

bool SnapshotTaker::wants(long step) const { return std::binary_search(pending_.begin(), pending_.end(), step); }

void SnapshotTaker::take(long step, const std::vector<glm::vec3>& R, const std::vector<glm::vec3>* dB) {
  if (!wants(step)) return;
  double residual = std::numeric_limits<double>::quiet_NaN();
  if (step > 0 && !res_.residualHistory.empty()) residual = res_.residualHistory.back();
  glm::vec3 ambient(0.f);
  if (dB) {
    if (step == 0 && P_ > 0) {
      double U = 0;
      for (size_t i = 0; i < A_.size(); ++i) U += A_[i] * luminance((*dB)[i]);
      residual = U / P_;
    }
    if (opt_.ambientTerm) ambient = ambientRadiosity(A_, rho_, *dB);
  }
  keep(int(step), int(step), residual, R, ambient);
  pending_.erase(std::find(pending_.begin(), pending_.end(), int(step)));
}

void SnapshotTaker::finish(const std::vector<glm::vec3>& R, const glm::vec3& ambient) {
  if (pending_.empty() && res_.snapshots.empty()) return;
  for (int step : pending_) keep(step, res_.iterations, res_.residual, R, ambient);
  if (!pending_.empty())
    res_.stats.note("snapshot steps from " + std::to_string(pending_.front()) + " on not reached (the solve ended at " +
                    std::to_string(res_.iterations) + "): they hold the final state");
  pending_.clear();
  std::sort(res_.snapshots.begin(), res_.snapshots.end(),
            [](const RadiosityResult::Snapshot& a, const RadiosityResult::Snapshot& b) { return a.step < b.step; });
  res_.stats.add("snapshots", double(res_.snapshots.size()));
}

void SnapshotTaker::keep(int step, int reached, double residual, const std::vector<glm::vec3>& R,
                         const glm::vec3& ambient) {
  std::vector<glm::vec3> B(R.size());
  // The vertices weigh their faces by seen area (A_ is each patch's seen
  // part), as the final state's do: otherwise a snapshot taken at the last
  // step differed from the result by up to 0.37 (an outside review).
  std::vector<float> seen(R.size(), 0.f);
  for (size_t i = 0; i < R.size(); ++i) {
    B[i] = A_[i] > 0 ? E_[i] + R[i] + rho_[i] * ambient : glm::vec3(0.f);
    const double whole = faceArea(s_, i);
    seen[i] = whole > 0 ? float(std::min(1.0, A_[i] / whole)) : 0.f;
  }
  res_.snapshots.push_back({step, reached, residual, faceToVertex(s_, B, seen)});
}

std::string residualCsv(const RadiosityResult& r) {
  std::string out = "step,residual\n";
  char line[64];
  for (size_t k = 0; k < r.residualHistory.size(); ++k) {
    std::snprintf(line, sizeof line, "%zu,%.9g\n", k + 1, r.residualHistory[k]);
    out += line;
  }
  return out;
}

std::string residualLogNote(const RadiosityResult& r) {
  const size_t n = r.residualHistory.size();
  if (n == 0) return "no solver steps";
  std::string out = "residual by step:";
  char item[48];
  for (size_t step = 1; step <= n; step *= 2) {
    std::snprintf(item, sizeof item, " %zu: %.3g,", step, r.residualHistory[step - 1]);
    out += item;
  }
  std::snprintf(item, sizeof item, " %zu: %.3g", n, r.residualHistory[n - 1]);
  return out + item;
}

}  // namespace gi
