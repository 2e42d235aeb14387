#include "gi/radiosity.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <stdexcept>


#include "gi/color.h"
#include "gi/direct.h"
#include "gi/emitters.h"
#include "gi/form_factor_analytic.h"
#include "gi/luminaires.h"
#include "gi/patch_seen.h"
#include "gi/sampling.h"
#include "radiosity_course.h"
#include "radiosity_solvers.h"
#include "radiosity_vertices.h"
#include "gi/scene_setup.h"

namespace gi {

namespace {

std::string shortPercent(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", v);
  return b;
}

using radiosity::gather;
using radiosity::RowFn;
using radiosity::Setup;
using radiosity::Stopping;

// The direct light's numbers and notes (luminaires, method) after the solver's.
void appendStats(RunStats& to, const RunStats& from) {
  to.numbers.insert(to.numbers.end(), from.numbers.begin(), from.numbers.end());
  to.notes.insert(to.notes.end(), from.notes.begin(), from.notes.end());
  to.warnings.insert(to.warnings.end(), from.warnings.begin(), from.warnings.end());
}

// With patch-average vertex values, the vertices' direct part is their
// faces' (E + rho H_direct, sky and sun included, averaged as B is): a
// two-pass view then takes the same indirect part the vertices show, and a
// direct part an earlier run left on the mesh is replaced, never reused.
std::vector<glm::vec3> patchAverageDirect(const Scene& s, const std::vector<glm::vec3>& E,
                                          const std::vector<glm::vec3>& rho, const std::vector<glm::vec3>& Hd,
                                          const std::vector<float>& seenShare) {
  std::vector<glm::vec3> Bd(E.size());
  for (size_t i = 0; i < E.size(); ++i) Bd[i] = E[i] + rho[i] * Hd[i];
  return faceToVertex(s, Bd, seenShare);
}

// Hd: the direct irradiance from the emitters; Hout: from the sky and the sun
// (gi/sky.h; empty: none). Both are direct light: the solve starts from
// rho (Hd + Hout), and the power entering from outside counts as emitted.
Setup setup(const Scene& s, const std::vector<glm::vec3>& Hd, const std::vector<glm::vec3>& Hout = {}) {
  Setup u;
  u.n = s.faceCount();
  u.unit2 = s.unit * s.unit;
  const auto ok = usableFaceMask(s);
  u.A.resize(u.n);
  u.E.resize(u.n);
  u.rho.resize(u.n);
  for (size_t i = 0; i < u.n; ++i) {
    u.A[i] = ok[i] ? faceArea(s, i) : 0.0;
    u.E[i] = ok[i] ? s.faceEmission(i) : glm::vec3(0.f);
    u.rho[i] = s.faceRho(i);
    for (int k = 0; k < 3; ++k)
      if (!(u.rho[i][k] >= 0.f && u.rho[i][k] < 1.f))
        throw std::invalid_argument("reflectance must be in [0, 1) in every channel (face " + std::to_string(i) +
                                    " has " + std::to_string(u.rho[i][k]) + "): rho >= 1 creates energy");
    u.P += u.A[i] * luminance(u.E[i]);
  }
  u.Hd = Hd;
  if (u.Hd.size() != u.n || (!Hout.empty() && Hout.size() != u.n))
    throw std::logic_error("direct irradiance has the wrong size");
  if (!Hout.empty()) {
    for (size_t i = 0; i < u.n; ++i) u.Hd[i] += Hout[i];
    u.Pout = enteringPower(s, Hout);
    u.P += u.Pout;
  }
  if (!(u.P > 0))
    throw std::invalid_argument("the scene has no emitters and no sky or sun reaching a surface: select the light's "
                                "faces (or mark them by face quality) and choose the matching 'Emitters' option, with "
                                "emitter_intensity above 0 and an emitter_color that is not black, or set "
                                "sky_irradiance or sun_irradiance");
  return u;
}

// The patches' direct light, the same for every solver: the emitters', and
// the sky's and the sun's (through the openings' portals where there are
// any), timed, with its log entries kept for the end of the run.
struct DirectSetup {
  SkyOpenings openings;
  Setup u;
  std::vector<glm::vec3> emitters;  // the emitters' share of u.Hd (the patch means)
  std::vector<glm::vec3> outside;   // the sky's and sun's share
  RunStats stats;
  double seconds = 0;
  // Its numbers and notes after the solver's, and the shadow rays per patch.
  void report(const RadiosityOptions& opt, RunStats& st) const {
    st.add("direct_light_seconds", seconds);
    appendStats(st, stats);
    openings.report(st);
    const bool skyRays = opt.outside.sky() && (!openings.any() || openings.rest);  // the cosine rays still cast
    st.add("shadow_rays", double(u.n) * opt.lightSamples * (1 + int(skyRays) + int(opt.outside.sun())));
    // No surface can receive more direct light than the lights and the sky
    // send. With luminaires each patch takes the exact factor averaged over
    // it (gi/direct.h), and its visibility from a few points, which cannot
    // exceed 1; with more than Luminaires::kMaxLuminaires, power-sampled
    // light points, one per shadow ray, whose estimate is noisy next to an
    // edge a patch shares with a light (a closed tube of 300 sliver facets,
    // its lamp a cone of 300 facets, received up to 3.8% more than the lamp
    // emits at 16 shadow rays). The energy balance does not see it (what
    // escapes is the remainder); the excess is what can be told.
    double received = 0;
    for (size_t i = 0; i < u.n; ++i) received += u.A[i] * luminance(u.Hd[i]);
    st.add("direct_received_power_W", received * u.unit2);
    if (u.P > 0 && received > 1.01 * u.P) {
      // Sampled light points apply only beyond kMaxLuminaires; with fewer
      // the excess is surfaces that overlap (it named the sampling with 7
      // luminaires; an outside audit).
      const bool sampled = stats.get("luminaires", 0.0) > double(Luminaires::kMaxLuminaires);
      st.warn("the patches receive " + shortPercent(100.0 * (received / u.P - 1.0)) +
              "% more direct light than the lights and the sky send: " +
              (sampled ? "their direct light, sampled on the lights (more than " +
                             std::to_string(Luminaires::kMaxLuminaires) +
                             " luminaires), overstates it next to edges they share with a light (raise light_samples; "
                             "the vertex values compute it at each vertex), or "
                       : std::string()) +
              "surfaces overlap in one plane (a face and a copy of it triangulated otherwise) and receive the same "
              "light twice (remove such copies)");
    }
  }
};
DirectSetup directSetup(const Scene& s, const RayCaster& caster, const RadiosityOptions& opt, uint32_t seed,
                        const Progress& emitters, const Progress& outside) {
  Timer timer;
  DirectSetup d;
  d.openings = findSkyOpenings(s, caster, opt.outside, seed);
  d.emitters = patchDirectIrradiance(s, caster, opt.lightSamples, seed, emitters, &d.stats);
  d.outside = patchSkySunIrradiance(s, caster, opt.outside, opt.lightSamples, seed, outside, &d.openings);
  d.u = setup(s, d.emitters, d.outside);
  d.seconds = timer.seconds();
  return d;
}

// Emitted = absorbed + escaped, with the direct light's share from the
// shadow rays and the reflected share from the rows (R = reflected radiosity).
// `complete`: the solution is meant to hold all the light (no bounce count,
// and converged: a solve stopped early has said so already); `tolerance`:
// the one it converged to.
// `closed`: every edge of the scene has two faces, so no light can leave it.
void energyStats(const Setup& u, const RowFn& row, const std::vector<glm::vec3>& R, bool complete, double tolerance,
                 std::optional<FormFactorMethod> method, bool closed, RunStats& st) {
  double absorbed = 0, escaped = u.P;
  for (size_t i = 0; i < u.n; ++i) {
    if (u.A[i] == 0) continue;
    const FormFactorRow& r = row(uint32_t(i));
    const glm::vec3 H = u.Hd[i] + gather(r, R);
    absorbed += u.A[i] * luminance((glm::vec3(1.f) - u.rho[i]) * H);
    escaped += u.A[i] * (luminance(R[i]) * r.escaped - luminance(u.Hd[i]));
  }
  st.add("emitted_power_W", u.P * u.unit2);
  if (u.Pout > 0) st.add("sky_sun_power_W", u.Pout * u.unit2);
  st.add("absorbed_power_W", absorbed * u.unit2);
  st.add("escaped_power_W", escaped * u.unit2);
  const double balance = std::fabs(u.P - absorbed - escaped) / u.P;
  st.add("energy_balance_error", balance);
  // Light booked as leaving a closed scene left through rows of F summing
  // below 1: the balance holds (the shortfall is booked as escaping), but
  // the values are low by about that share, magnified at high reflectance
  // (a sealed box of one patch a side, analytic factors, rho 0.999: 7.7% low
  // and 7.7% "escaped", without a word; an outside audit).
  if (closed && escaped > 0.01 * u.P) {
    char b[480];
    std::snprintf(b, sizeof b,
                  "%.1f%% of the power was booked as leaving a closed scene (every edge has two faces: none can leave): "
                  "the form factors' rows sum below 1 (%s), and the values are low by about as much, more at high "
                  "reflectance; Monte Carlo form factors land every ray in a closed scene",
                  100.0 * escaped / u.P,
                  method && *method == FormFactorMethod::Hemicube
                      ? "the hemicube's cells aliasing coarse or near patches: raise hemicube_resolution or points"
                      : "the analytic quadrature on coarse patches: raise analytic_points");
    st.warn(b);
  }
  // With its sign (it was lost; an outside audit): > 0, light created; < 0, lost.
  st.add("energy_created_fraction", (absorbed + escaped - u.P) / u.P);
  // The shipped scenes balance within 0.14% at the defaults; a converged
  // solution of all bounces off by more than 1% creates or loses light: rows
  // of F summing above 1 (the analytic quadrature beside contacts, magnified
  // by 1 / (1 - rho) at high reflectance).
  // A loose tolerance leaves light unaccounted by itself (tolerance 1 on the
  // Cornell box: 8.4%): a note naming it, not the form factors.
  if (complete && balance > 0.01 && tolerance > 1e-3) {
    char b[240];
    std::snprintf(b, sizeof b,
                  "energy balance off by %.1f%% at the tolerance %.3g: a solve stopped this early leaves part of the "
                  "light unaccounted (lower the tolerance to check the form factors)",
                  100.0 * balance, tolerance);
    st.note(b);
  } else if (complete && balance > 0.01) {
    // What to do depends on the method that made the rows (it advised
    // Monte Carlo to a Monte Carlo run whose rows cannot sum above 1; an
    // outside audit): surfaces that overlap in one plane (a face and a copy
    // of it triangulated otherwise) receive the same light twice with any.
    const char* cause =
        !method ? "form-factor rows summing above 1, or surfaces overlapping in one plane (a face and a copy of it "
                  "triangulated otherwise) receiving the same light twice"
        : *method == FormFactorMethod::Analytic
            ? "form-factor rows summing above 1, as the analytic quadrature gives beside contacts, magnified at high "
              "reflectance; or surfaces overlapping in one plane (a face and a copy of it triangulated otherwise) "
              "receiving the same light twice: use Monte Carlo or hemicube form factors or more analytic points, "
              "and remove such copies"
        : *method == FormFactorMethod::Hemicube
            ? "the hemicube's cells aliasing small or near patches, magnified at high reflectance; or surfaces "
              "overlapping in one plane (a face and a copy of it triangulated otherwise) receiving the same light "
              "twice: raise hemicube_resolution, and remove such copies"
            : "surfaces overlapping in one plane (a face and a copy of it triangulated otherwise) receiving the "
              "same light twice (Monte Carlo rows never sum above 1): remove such copies";
    st.warn("energy balance off by " + shortPercent(100.0 * balance) + "%: the power absorbed and escaping " +
            (absorbed + escaped > u.P ? "exceeds" : "falls short of") + " the power emitted (" + cause + ")");
  }
}

// After any solver: the energy account, what vertices gather from (the
// reflected radiosity Rgather, one sweep behind R when a bounce count is
// fixed: the gather adds that bounce), B = E + R per face and per vertex.
void finishSolution(const Scene& s, const Setup& u, const RowFn& row, const std::vector<glm::vec3>& R,
                    std::vector<glm::vec3> Rgather, bool fixedBounces, double tolerance,
                    std::optional<FormFactorMethod> method, RadiosityResult& res) {
  const bool complete = std::none_of(res.stats.warnings.begin(), res.stats.warnings.end(),
                                     [](const std::string& w) { return w.rfind("not converged", 0) == 0; });
  energyStats(u, row, R, complete && !fixedBounces, tolerance, method, analyzeScene(s).borderEdges == 0, res.stats);
  res.Rgather = std::move(Rgather);
  res.Hindirect.assign(u.n, glm::vec3(0.f));
  for (size_t i = 0; i < u.n; ++i)
    if (u.A[i] > 0) res.Hindirect[i] = gather(row(uint32_t(i)), res.Rgather);
  res.B = R;
  for (size_t i = 0; i < u.n; ++i) res.B[i] += u.E[i] + u.rho[i] * res.ambient;
  res.Bvertex = faceToVertex(s, res.B);
  res.stats.add("iterations", res.iterations);
  res.stats.add("residual", res.residual);
}

// Solves R = S + rho F R for the reflected radiosity R, with the source S =
// rho H_direct, by the chosen solver (Jacobi whenever a bounce count is
// fixed); rows from `row`, held in memory when `transpose` (progressive
// refinement may then read columns).
// `method`: the one that made the rows, where known (its remedies).
RadiosityResult solve(const Scene& s, const Setup& u, const RowFn& row, bool transpose, RadiositySolver solver,
                      const RadiosityOptions& opt, std::optional<FormFactorMethod> method, const Progress& progress) {
  const int bounces = opt.bounces, maxIter = opt.maxIterations;
  const double tol = opt.tolerance;
  RadiosityResult res;
  std::vector<glm::vec3> S(u.n);  // source: once-reflected direct light
  for (size_t i = 0; i < u.n; ++i) S[i] = u.rho[i] * u.Hd[i];
  size_t skippedBlack = 0;
  for (size_t i = 0; i < u.n; ++i) skippedBlack += (u.A[i] > 0 && u.rho[i] == glm::vec3(0.f)) ? 1 : 0;
  Stopping stop{bounces >= 0, bounces, tol, maxIter, 0.0};
  if (stop.fixed) solver = RadiositySolver::Jacobi;
  res.stats.note(std::string("solver ") + kRadiositySolvers.logName(solver) +
                 (stop.fixed ? " (" + std::to_string(bounces) + " bounces requested)" : ""));
  // The radiosity is held in float: sweeps stop changing it near 1e-7 of
  // itself, so a residual of 0 there says no more (at rho 0.999 and
  // tolerance 1e-12, Jacobi read 0 at 7e-6 short of the exact value).
  if (!stop.fixed && tol < 1e-6)
    res.stats.note("tolerance below the radiosity's float precision (about 1e-7 of it): the sweeps stop changing it "
                   "before, and the residual may read 0 a few 1e-6 short");
  if (!stop.fixed) {
    stop.r = radiosity::spectralBound(u, row, transpose);
    if (maxIter <= 0) {
      stop.maxIter = autoIterations(stop.r, tol);
      res.stats.add("max_iterations_auto", stop.maxIter);
    }
  }
  std::vector<glm::vec3> R = S;  // the reflected radiosity while solving
  std::vector<glm::vec3> prevR;  // fixed bounces: the iterate before the last sweep
  SnapshotTaker snap(s, u.E, u.rho, u.A, opt, res);
  if (!opt.snapshotSteps.empty()) {
    stop.observe = [&](long step, const std::vector<glm::vec3>& Rk, const std::vector<glm::vec3>* dB) {
      if (snap.wants(step)) snap.take(step, Rk, dB);
    };
    if (solver != RadiositySolver::Progressive) snap.take(0, R, nullptr);  // progressive: takes its own step 0
  }
  switch (solver) {
    case RadiositySolver::Jacobi:
      radiosity::jacobi(u, row, S, stop, progress, R, stop.fixed ? &prevR : nullptr, res);
      break;
    case RadiositySolver::GaussSeidel: radiosity::gaussSeidel(u, row, S, stop, progress, R, res); break;
    default: radiosity::progressiveRefinement(u, row, transpose, S, stop, progress, R, res); break;
  }
  if (opt.ambientTerm && solver != RadiositySolver::Progressive)
    res.stats.warn(std::string("ambient_term applies to progressive refinement only: ignored with the solver ") +
                   kRadiositySolvers.logName(solver) + (stop.fixed ? " (a bounce count is set)" : ""));
  if (!opt.ambientTerm || solver != RadiositySolver::Progressive) res.ambient = glm::vec3(0.f);
  else res.stats.add("ambient_term", luminance(res.ambient));
  snap.finish(R, res.ambient);
  finishSolution(s, u, row, R, stop.fixed ? std::move(prevR) : R, stop.fixed, tol, method, res);
  // The term spreads the unshot light over the scene as if all of it stayed
  // (Cohen et al.'s closed room): where much leaves, early images overshoot
  // (an outside audit: an open floor under a lamp +91% at the first shot,
  // where no term gave -3.7%; the Cornell box, one side open, +23%).
  if (opt.ambientTerm && solver == RadiositySolver::Progressive) {
    const double P = res.stats.get("emitted_power_W", 0.0), escaped = res.stats.get("escaped_power_W", 0.0);
    if (P > 0.0 && escaped > 0.1 * P)
      res.stats.warn("ambient_term assumes a closed room (all light stays in the scene), but " +
                     shortPercent(100.0 * escaped / P) +
                     "% of the emitted power leaves this one: images before convergence (snapshots, a high "
                     "tolerance) read too bright (an open floor under a lamp: +91% at the first shot, the Cornell "
                     "box +23%); the converged result has no term");
  }
  if (skippedBlack) res.stats.note(std::to_string(skippedBlack) + " black patches (rho = 0) skipped as receivers");
  return res;
}

struct MemoryPlan {
  double rest = 0;    // bytes besides the matrix
  double matrix = 0;  // the full sparse matrix (and its transpose for progressive refinement)
  bool fits = false;  // both within the budget: rows kept in memory
};

MemoryPlan planMemory(size_t n, const FormFactors& ff, const RadiosityOptions& opt) {
  const double MB = 1048576.0, budget = opt.memoryBudgetMB * MB;
  const int threads = workerThreads();
  const double patches = double(n) * kSolverBytesPerPatch, scratch = threads * ff.rowScratchBytes();
  MemoryPlan m;
  m.rest = patches + scratch;  // solverBaseBytes, with the method resolved
  m.matrix = ff.matrixBytesBound() * (opt.solver == RadiositySolver::Progressive && opt.bounces < 0 ? 2.0 : 1.0);
  m.fits = m.rest + m.matrix <= budget;
  if (m.rest > budget) {
    char b[600];
    std::snprintf(b, sizeof b,
                  "memory_budget_mb = %g is too small: %zu patches need about %.0f MB even with the form factors "
                  "computed on the fly (%.0f MB for the patches' scene, ray-casting and solver data, %.0f MB for %d "
                  "threads' form-factor rows%s); raise memory_budget_mb, or use fewer patches%s",
                  opt.memoryBudgetMB, n, m.rest / MB, patches / MB, scratch / MB, threads,
                  ff.method() == FormFactorMethod::Hemicube ? ", each with the buffers of a hemicube" : "",
                  ff.method() == FormFactorMethod::Hemicube ? " or a lower hemicube resolution" : "");
    throw std::invalid_argument(b);
  }
  return m;
}


std::string megabytes(double bytes) { return std::to_string(int(bytes / 1048576.0 + 0.5)); }

// The light on the seen part of each partly buried patch, from its own seen
// points (seenPartDirectIrradiance, seenPartSkySunIrradiance): u.Hd becomes
// a H_seen, so that u.Hd / a, which every solver takes, is H_seen. The
// patch mean over the share (u.Hd / a as it was) divided an estimate from
// patchDirectIrradiance's few points by one from the seen-part points: on
// the Cornell box a floor triangle 3% seen beside the short block, one of
// whose 4 light points fell in the seen corner, had a quarter of the
// unoccluded light over a share of 2/64: 7 times the open floor's
// irradiance (B 2.58 where the brightest floor patch is 0.59), and 0 with
// its corners listed in another order (no light point in the corner).
void seenPartsDirect(const Scene& s, const RayCaster& caster, const RadiosityOptions& opt, uint32_t seed,
                     const PatchSeen& seen, DirectSetup& d) {
  if (!seen.any()) return;
  const std::vector<glm::vec3> Hs = seenPartDirectIrradiance(s, caster, opt.lightSamples, seed, seen.seenPoints);
  const std::vector<glm::vec3> Ho =
      seenPartSkySunIrradiance(s, caster, opt.outside, opt.lightSamples, seed, seen.seenPoints, &d.openings);
  for (size_t i = 0; i < d.u.n; ++i) {
    const float a = seen.fraction[i];
    if (a > 0.f && a < 1.f) d.u.Hd[i] += a * (Hs[i] + Ho[i]) - d.emitters[i] - d.outside[i];
  }
}

// The flat solvers work with the seen part of each patch (gi/patch_seen.h):
// its area a A, its direct irradiance H / a and its row F / a (the last in
// `ff`). A patch no one sees keeps no area and no light.
void useSeenParts(const PatchSeen& seen, Setup& u, FormFactors& ff) {
  if (!seen.any()) return;
  for (size_t i = 0; i < u.n; ++i) {
    const float a = seen.fraction[i];
    if (a >= 1.f) continue;
    u.A[i] *= a;
    u.Hd[i] = a > 0.f ? u.Hd[i] / a : glm::vec3(0.f);
  }
  ff.useSeenParts(seen.fraction);
}

void reportSeenParts(const PatchSeen& seen, RunStats& st, const FormFactors* ff = nullptr) {
  st.add("seen_part_rays", double(seen.rays));
  if (!seen.any()) return;
  st.add("patches_partly_buried", double(seen.partial));
  st.add("patches_buried", double(seen.buried));
  char b[420];
  std::snprintf(b, sizeof b,
                "%zu patches partly and %zu wholly buried under other surfaces (%.2g%% of the surface, where no ray "
                "can reach): their radiosity is that of the part the scene sees%s",
                seen.partial, seen.buried, 100.0 * seen.buriedArea / seen.area,
                ff && ff->method() == FormFactorMethod::Hemicube && ff->hemicubePoints() <= 1
                    ? " (direct light; a hemicube at the centre gives the centre's row)"
                    : "");
  st.note(b);
}

// The whole sparse matrix computed first (in parallel) and kept for the solve.
RadiosityResult solveInMemory(const Scene& s, const Setup& u, const FormFactors& ff, const MemoryPlan& mem,
                              RadiositySolver solver, const RadiosityOptions& opt, const Progress& progress) {
  std::vector<FormFactorRow> rows(u.n);
  Timer ffTimer;
  parallelBlocks(u.n, progress.sub(0.1, 0.8), "form factors", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) rows[i] = ff.row(uint32_t(i));
  });
  const double ffSeconds = ffTimer.seconds();
  size_t entries = 0;
  for (const auto& r : rows) entries += r.j.size();
  RadiosityResult res = solve(s, u, [&rows](uint32_t i) -> const FormFactorRow& { return rows[i]; }, true, solver,
                              opt, ff.method(), progress.sub(0.8, 1.0));
  if (!opt.exportSystem.empty()) {
    std::vector<double> area(u.A);
    for (double& a : area) a *= u.unit2;
    // The solution of the system, without the display's ambient term (an
    // early stop of progressive refinement adds rho x ambient to B).
    std::vector<glm::vec3> B = res.B;
    for (size_t i = 0; i < B.size(); ++i) B[i] -= u.rho[i] * res.ambient;
    res.exports = linearSystemFiles(rows, area, u.E, u.rho, u.Hd, B);
  }
  res.stats.add("form_factor_seconds", ffSeconds);
  res.stats.add("form_factor_entries", double(entries));
  res.stats.add("form_factor_MB", double(entries) * 8.0 / 1048576.0);
  res.stats.note("full sparse form-factor matrix (estimated " + megabytes(mem.matrix) + " MB, with the rest " +
                 megabytes(mem.matrix + mem.rest) + " MB <= budget)");
  return res;
}

// Beyond the budget: each row computed when the solver reads it, so
// progressive refinement unless a bounce count is fixed (Jacobi).
RadiosityResult solveOnTheFly(const Scene& s, const Setup& u, const FormFactors& ff, const MemoryPlan& mem,
                              RadiositySolver solver, const RadiosityOptions& opt, const Progress& progress) {
  // A solver asked for by name and replaced is said as a warning (it was a
  // note the user could miss; an outside audit); Auto's choice stays a note.
  const bool replaced = solver != RadiositySolver::Progressive && opt.bounces < 0;
  const RadiositySolver asked = solver;
  if (replaced) solver = RadiositySolver::Progressive;
  thread_local FormFactorRow scratch;
  RadiosityResult res = solve(s, u, [&ff](uint32_t i) -> const FormFactorRow& { scratch = ff.row(i); return scratch; },
                              false, solver, opt, ff.method(), progress.sub(0.1, 1.0));
  if (!opt.exportSystem.empty())
    res.stats.warn("export_system needs the form-factor matrix in memory (raise memory_budget_mb): nothing exported");
  res.stats.note("form factors on the fly: the matrix (estimated " + megabytes(mem.matrix) + " MB) and the rest (" +
                 megabytes(mem.rest) + " MB) exceed the memory budget");
  if (replaced && opt.solver == asked)
    res.stats.warn(std::string("solver ") + kRadiositySolvers.logName(asked) +
                   " needs the form-factor matrix in memory, which exceeds memory_budget_mb: progressive refinement "
                   "(rows computed as they are shot) solved it instead; raise memory_budget_mb for the solver asked");
  return res;
}

// The hierarchical solver (gi/hierarchical.h) on the patches, then the same
// vertex values as the flat solvers: the hierarchy gives each triangle its
// reflected radiosity and indirect irradiance.
RadiosityResult solveHierarchicalRadiosity(const Scene& s, const RayCaster& caster, const RadiosityOptions& opt,
                                           const Progress& progress) {
  // Refused before any work, not left out in silence: the hierarchy has no
  // matrix to export and no sweeps of whole solutions to keep.
  if (!opt.exportSystem.empty() || !opt.snapshotSteps.empty())
    throw std::invalid_argument(std::string(!opt.exportSystem.empty() ? "export_system" : "snapshot_steps") +
                                " needs a flat solver (Jacobi, Gauss-Seidel or Progressive refinement): the hierarchical "
                                "solver has no form-factor matrix and no sweeps of whole solutions" +
                                (opt.solver == RadiositySolver::Auto ? " (Auto chose it for " +
                                                                           std::to_string(s.faceCount()) + " patches)"
                                                                     : std::string()));
  Timer timer;
  const double budget = opt.memoryBudgetMB * 1048576.0;
  const size_t n = s.faceCount();
  DirectSetup direct =
      directSetup(s, caster, opt, opt.formFactors.seed, progress.sub(0.0, 0.1), progress.sub(0.1, 0.2));
  const Setup& u = direct.u;
  HierarchySettings hs;
  hs.epsilon = opt.hierarchyEpsilon;
  hs.linkRays = opt.linkRays;
  hs.closureRays = opt.closureRays;
  hs.memoryBytes = budget - double(n) * kSolverBytesPerPatch;
  if (opt.maxLinks > 0) hs.maxLinks = opt.maxLinks;
  hs.enteringPower = u.Pout;
  hs.seed = opt.formFactors.seed;
  Timer seenTimer;
  const PatchSeen seen = patchSeenFractions(s, caster, opt.formFactors.seed, &u.Hd);
  seenPartsDirect(s, caster, opt, opt.formFactors.seed, seen, direct);
  if (seen.any()) hs.seen = seen.fraction, hs.seenPoints = seen.seenPoints;
  const double seenSeconds = seenTimer.seconds();
  // Progress: direct light 0-20%, the hierarchy to 70% (to 100% without per-vertex values), the vertices after.
  const bool vertices = opt.vertexOutput != RadiosityVertexOutput::PatchAverage;
  HierarchicalSolution h = solveHierarchical(s, caster, u.Hd, hs, opt.bounces, opt.tolerance, opt.maxIterations,
                                             progress.sub(0.2, vertices ? 0.7 : 1.0));
  RadiosityResult res;
  res.stats = std::move(h.stats);
  res.iterations = h.iterations;
  res.residual = h.residual;
  res.residualHistory = std::move(h.residualHistory);
  res.Rgather = std::move(h.Rprev);
  res.Rbounces = std::move(h.Rbounces);
  res.Hindirect = std::move(h.H);
  res.B = h.R;
  for (size_t i = 0; i < n; ++i) res.B[i] += u.E[i];
  if (seen.any()) res.seenShare = seen.fraction;
  res.Bvertex = faceToVertex(s, res.B, res.seenShare);
  res.stats.note("solver hierarchical with clustering" +
                 (opt.bounces >= 0 ? " (" + std::to_string(opt.bounces) + " bounces requested)" : std::string()));
  if (opt.solver == RadiositySolver::Auto)
    res.stats.note("auto: hierarchical for " + std::to_string(n) + " patches (>= " +
                   std::to_string(kHierarchicalAutoPatches) + ")");
  res.stats.add("iterations", res.iterations);
  res.stats.add("residual", res.residual);
  if (opt.hierarchyEpsilon == 0 && n > 20000)
    res.stats.warn("hierarchy_epsilon = 0 links every pair of the " + std::to_string(n) +
                   " patches (the flat solution at quadratic cost); 1e-4 is the default");
  if (vertices) {
    radiosityVertexValues(s, caster, opt, res, progress.sub(0.7, 1.0), &direct.openings);
  } else {
    std::vector<glm::vec3> Hd = u.Hd;  // of the seen parts, as B
    for (size_t i = 0; i < Hd.size() && seen.any(); ++i)
      Hd[i] = seen.fraction[i] > 0 ? Hd[i] / seen.fraction[i] : glm::vec3(0.f);
    res.Bdirect = patchAverageDirect(s, u.E, u.rho, Hd, res.seenShare);
  }
  direct.report(opt, res.stats);
  res.stats.add("patches", double(u.n));
  reportSeenParts(seen, res.stats);
  res.stats.add("seen_part_seconds", seenSeconds);
  res.stats.add("memory_estimate_MB", double(n) * kSolverBytesPerPatch / 1048576.0 + res.stats.get("hierarchy_MB", 0.0));
  res.stats.add("seconds", timer.seconds());
  return res;
}

}  // namespace

double solverBaseBytes(size_t patches, const RadiosityOptions& opt) {
  const double n = double(patches);
  double row = 8.0 * n;  // a dense row (analytic, hemicube), at least the sparse one of Monte Carlo
  const FormFactors::Settings& ff = opt.formFactors;
  if (ff.method == FormFactorMethod::Hemicube) row += hemicubeBufferBytes(ff.hemicubeResolution);
  if (ff.method == FormFactorMethod::MonteCarlo) row = 12.0 * ff.raysPerPatch;
  return n * kSolverBytesPerPatch + workerThreads() * row;
}

int autoIterations(double r, double tolerance) {
  if (!(r > 0.0)) return 10;
  if (!(r < 1.0)) return 1000000;
  const double k = 1.5 * std::log(tolerance) / std::log(r);
  return int(std::clamp(std::ceil(k), 10.0, 1e6));
}

RadiosityResult solveWithRows(const Scene& s, const std::vector<FormFactorRow>& rows, const std::vector<glm::vec3>& Hd,
                              RadiositySolver solver, int bounces, double tolerance, int maxIterations,
                              const Progress& progress) {
  RadiosityOptions opt;
  opt.solver = solver;
  opt.bounces = bounces;
  opt.tolerance = tolerance;
  opt.maxIterations = maxIterations;
  return solveWithRows(s, rows, Hd, opt, progress);
}

RadiosityResult solveWithRows(const Scene& s, const std::vector<FormFactorRow>& rows, const std::vector<glm::vec3>& Hd,
                              const RadiosityOptions& opt, const Progress& progress) {
  const Setup u = setup(s, Hd);
  const RadiositySolver solver = opt.solver == RadiositySolver::Auto ? RadiositySolver::GaussSeidel : opt.solver;
  if (solver == RadiositySolver::Hierarchical)
    throw std::invalid_argument("the hierarchical solver builds its own links: use solveHierarchical");
  return solve(s, u, [&rows](uint32_t i) -> const FormFactorRow& { return rows[i]; }, true, solver, opt,
               std::nullopt, progress);
}

RadiosityResult solveRadiosity(const Scene& s, const RayCaster& caster, const RadiosityOptions& opt, const Progress& progress) {
  checkCasterFor(s, caster);
  checkRadiosityOptions(opt);
  const FormFactors::Settings& ffs = opt.formFactors;
  checkRadiosityMemory(s.faceCount(), opt);  // either solver: before any work
  const std::optional<std::string> narrow =
      narrowPatchWarning(s, narrowPatchCount(s), "their patch values (face output, patch averages)");
  if (usesHierarchy(s.faceCount(), opt)) {
    RadiosityResult res = solveHierarchicalRadiosity(s, caster, opt, progress);
    if (const auto w = emitterOrientationWarning(s, caster, opt.outside.any())) res.stats.warn(*w);
    if (narrow) res.stats.warn(*narrow);
    return res;
  }
  Timer timer;
  FormFactors ff(s, caster, ffs);
  const MemoryPlan mem = planMemory(s.faceCount(), ff, opt);  // refuses before the work if nothing fits
  DirectSetup direct = directSetup(s, caster, opt, ffs.seed, progress.sub(0.0, 0.05), progress.sub(0.05, 0.1));
  Timer seenTimer;
  const PatchSeen seen = patchSeenFractions(s, caster, ffs.seed, &direct.u.Hd);
  seenPartsDirect(s, caster, opt, ffs.seed, seen, direct);
  useSeenParts(seen, direct.u, ff);
  const double seenSeconds = seenTimer.seconds();
  const Setup& u = direct.u;
  RadiositySolver solver = opt.solver;
  if (solver == RadiositySolver::Auto) solver = mem.fits ? RadiositySolver::GaussSeidel : RadiositySolver::Progressive;
  const auto slow = ff.method() == FormFactorMethod::Hemicube ? hemicubeCostWarning(u.n, ffs.hemicubeResolution)
                                                              : std::nullopt;
  RadiosityResult res = mem.fits ? solveInMemory(s, u, ff, mem, solver, opt, progress)
                                 : solveOnTheFly(s, u, ff, mem, solver, opt, progress);
  if (seen.any()) {
    res.seenShare = seen.fraction;
    res.Bvertex = faceToVertex(s, res.B, res.seenShare);
  }
  if (opt.vertexOutput != RadiosityVertexOutput::PatchAverage)
    radiosityVertexValues(s, caster, opt, res, Progress(nullptr), &direct.openings);
  else
    res.Bdirect = patchAverageDirect(s, u.E, u.rho, u.Hd, res.seenShare);
  direct.report(opt, res.stats);
  res.stats.note(std::string("form factors: ") + kFormFactorMethods.logName(ff.method()) +
                 (ffs.method == FormFactorMethod::Auto ? " (auto)" : "") +
                 (ff.unoccluded() ? "; visibility rays skipped: nothing can occlude in this empty convex room" : ""));
  if (const std::string w = cutShortWarning(ff.pairsCutShort()); !w.empty()) res.stats.warn(w);
  if (ff.farPairsByOnePoint())
    res.stats.note(std::to_string(ff.farPairsByOnePoint()) +
                   " far pairs (F < 1e-7 proved by distance) by one point and one ray each, not refined");
  res.stats.add("patches", double(u.n));
  reportSeenParts(seen, res.stats, &ff);
  res.stats.add("seen_part_seconds", seenSeconds);
  if (slow) res.stats.warn(*slow);
  res.stats.add("memory_estimate_MB", (mem.rest + (mem.fits ? mem.matrix : 0.0)) / 1048576.0);
  res.stats.add("rays", double(ff.raysCast() + seen.rays));
  res.stats.add("seconds", timer.seconds());
  if (const auto w = emitterOrientationWarning(s, caster, opt.outside.any())) res.stats.warn(*w);
  if (narrow) res.stats.warn(*narrow);
  return res;
}

}  // namespace gi
