#include "gi/form_factors.h"

#include <algorithm>
#include <array>
#include <map>
#include <cmath>
#include <cstdio>
#include <limits>

#include "gi/form_factor_analytic.h"
#include "gi/run.h"
#include "gi/sampling.h"
#include "hit_origin.h"

#include <stdexcept>
#include <string>

namespace gi {

void checkFormFactorSettings(const FormFactors::Settings& set) {
  // The table's bounds are the dialog's advice; the library takes any count
  // that gives a row (the tests use a few rays, `gi formfactors-table` up
  // to 2^26; memory and time are checked where they are spent).
  auto atLeast = [&](const char* name, int v, int lo) {
    if (v < lo)
      throw std::invalid_argument(std::string("parameter '") + name + "' = " + std::to_string(v) + " must be >= " +
                                  std::to_string(lo));
  };
  // Each method's own settings (Auto: Monte Carlo's or the analytic ones).
  const FormFactorMethod m = set.method;
  const bool auto_ = m == FormFactorMethod::Auto;
  if (auto_ || m == FormFactorMethod::MonteCarlo) atLeast("rays_per_patch", set.raysPerPatch, 1);
  if (auto_ || m == FormFactorMethod::Analytic) atLeast("analytic_points", set.analyticPoints, 1);
  if (m == FormFactorMethod::Hemicube) {
    atLeast("hemicube_resolution", set.hemicubeResolution, 4);
    atLeast("hemicube_points", set.hemicubePoints, 1);
  }
}

FormFactors::FormFactors(const Scene& s, const RayCaster& caster, const Settings& settings)
    : s_(s), caster_(caster), set_(settings), eps_(float(sceneScale(s).rayEpsilon)) {
  checkCasterFor(s, caster);
  checkFormFactorSettings(settings);
  ok_ = usableFaceMask(s);
  area_.resize(s.faceCount());
  normal_.resize(s.faceCount());
  rays_.assign(s.faceCount(), 0);
  farPairs_.assign(s.faceCount(), 0);
  cutPairs_.assign(s.faceCount(), 0);
  centroid_.assign(s.faceCount(), glm::dvec3(0.0));
  radius_.assign(s.faceCount(), 0.0);
  for (size_t f = 0; f < s.faceCount(); ++f) {
    // An unusable face's corners may lie outside the vertices: not read.
    area_[f] = ok_[f] ? faceArea(s, f) : 0.0;
    normal_[f] = ok_[f] ? glm::normalize(faceNormalUnnormalized(s, f)) : glm::vec3(0.f);
    const auto& t = s.triangles[f];
    if (ok_[f]) {
      centroid_[f] = (glm::dvec3(s.positions[t.x]) + glm::dvec3(s.positions[t.y]) + glm::dvec3(s.positions[t.z])) / 3.0;
      for (int k = 0; k < 3; ++k) radius_[f] = std::max(radius_[f], glm::length(glm::dvec3(s.positions[t[k]]) - centroid_[f]));
    }
  }
  if (set_.method == FormFactorMethod::Auto) {
    // Exact-per-point factors are affordable for small scenes (n^2 work);
    // Monte Carlo rays scale as n N.
    size_t usable = 0;
    for (uint8_t o : ok_) usable += o;
    set_.method = usable <= 2000 ? FormFactorMethod::Analytic : FormFactorMethod::MonteCarlo;
  }
  if (set_.method == FormFactorMethod::Analytic) unoccluded_ = pairwiseUnoccluded(s);
}

uint64_t FormFactors::farPairsByOnePoint() const {
  uint64_t t = 0;
  for (uint64_t r : farPairs_) t += r;
  return t;
}

uint64_t FormFactors::pairsCutShort() const {
  uint64_t t = 0;
  for (uint64_t r : cutPairs_) t += r;
  return t;
}

double FormFactors::matrixBytesBound() const {
  const double n = double(area_.size());
  const double perRow = set_.method == FormFactorMethod::MonteCarlo ? std::min<double>(set_.raysPerPatch, n) : n;
  return n * perRow * 8.0 + n * 64.0;
}

double FormFactors::rowScratchBytes() const {
  const double n = double(area_.size());
  if (set_.method == FormFactorMethod::Hemicube) return 8.0 * n + hemicubeBufferBytes(set_.hemicubeResolution);
  if (set_.method == FormFactorMethod::MonteCarlo) return 8.0 * std::min<double>(set_.raysPerPatch, n) + 4.0 * set_.raysPerPatch;
  return 8.0 * n;
}

namespace {

// The row of the seen share a of a patch: its buried points' rays met back
// faces only, so the mean over the seen points is F / a; capped where the
// row would sum above 1 (a share estimated a little low must not create
// light). Entries to patches taken as wholly buried (their screening points
// all buried: a sliver of under 1/16 may still be seen, and rays land
// there) are dropped, as light that leaves: such a patch has no area to
// receive it (a division by that area gave NaN; an outside review).
// escaped stays 1 - the row's sum, as each method defines it.
FormFactorRow seenPart(FormFactorRow r, const std::vector<float>& seen, uint32_t i, bool pointRow) {
  const float a = pointRow ? 1.f : seen[i];  // one hemicube at the centre: that point's row
  if (!(seen[i] > 0.f)) return FormFactorRow{{}, {}, 1.f};
  size_t kept = 0;
  for (size_t k = 0; k < r.j.size(); ++k)
    if (seen[r.j[k]] > 0.f) r.j[kept] = r.j[k], r.F[kept++] = r.F[k];
  r.j.resize(kept);
  r.F.resize(kept);
  double sum = 0;
  for (float f : r.F) sum += f;
  const double g = a >= 1.f ? 1.0 : sum * a > 1.0 ? 1.0 / sum : 1.0 / a;
  for (float& f : r.F) f = float(f * g);
  r.escaped = float(std::clamp(1.0 - sum * g, 0.0, 1.0));
  return r;
}

}  // namespace

void FormFactors::useSeenParts(std::vector<float> a) {
  if (a.size() != area_.size()) throw std::logic_error("seen parts: one share per patch");
  seen_ = std::move(a);
}

FormFactorRow FormFactors::row(uint32_t i) const {
  if (i >= ok_.size())
    throw std::out_of_range("form-factor row " + std::to_string(i) + " of " + std::to_string(ok_.size()) + " patches");
  if (!ok_[i]) return {};
  FormFactorRow r;
  switch (set_.method) {
    case FormFactorMethod::Analytic: r = analyticRow(i); break;
    case FormFactorMethod::Hemicube: r = hemicubeRow(i); break;
    default: r = monteCarloRow(i); break;
  }
  return seen_.empty() ? r
                       : seenPart(std::move(r), seen_, i,
                                  set_.method == FormFactorMethod::Hemicube && set_.hemicubePoints <= 1);
}

FormFactorReport formFactorsOfFace(const Scene& s, const RayCaster& caster, const FormFactors::Settings& settings,
                                   uint32_t face, int reciprocityChecks) {
  if (face >= s.faceCount()) throw std::invalid_argument("face " + std::to_string(face) + " does not exist");
  if (!usableFaceMask(s)[face]) throw std::invalid_argument("face " + std::to_string(face) + " is degenerate");
  Timer timer;
  const FormFactors ff(s, caster, settings);
  FormFactorReport rep;
  rep.row = ff.row(face);
  rep.pairsCutShort = ff.pairsCutShort();
  for (float f : rep.row.F) rep.rowSum += f;
  rep.escaped = rep.row.escaped;
  std::vector<size_t> order(rep.row.j.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return rep.row.F[a] > rep.row.F[b]; });
  for (size_t k = 0; k < order.size() && int(k) < reciprocityChecks; ++k) {
    const uint32_t j = rep.row.j[order[k]];
    const FormFactorRow rj = ff.row(j);
    double Fji = 0;
    for (size_t m = 0; m < rj.j.size(); ++m)
      if (rj.j[m] == face) Fji = rj.F[m];
    const double lhs = ff.area(face) * rep.row.F[order[k]], rhs = ff.area(j) * Fji;
    rep.maxReciprocityError = std::max(rep.maxReciprocityError, std::fabs(lhs - rhs) / lhs);
    ++rep.reciprocityChecked;
  }
  rep.seconds = timer.seconds();
  return rep;
}

std::string cutShortWarning(uint64_t pairs) {
  if (pairs == 0) return "";
  return std::to_string(pairs) + " pairs of patches needed more refinement of the analytic form factor than it is "
         "allowed (slivers, a side many thousand times the patch's width): their factors may be off by more "
         "than 1%; Monte Carlo form factors do not depend on the patches' shape, or remesh the slivers";
}

std::vector<ParamSpec> formFactorSpecs() {
  return {
      {.name = "form_factor_method", .label = "Form factors",
       .help = "How the form factors F_ij are computed. Monte Carlo: from stratified points on each patch, rays in "
               "cosine-weighted directions (origins and directions from independent Owen-scrambled Sobol "
               "dimensions); the fraction that lands on patch j's front is F_ij (visibility included; cost n x "
               "rays). Analytic point-to-polygon (Wallace et al. 1989): the exact unoccluded factor from points of "
               "each patch to every other patch, averaged by an adaptive midpoint rule, times one visibility ray per "
               "point (none in an empty convex room; cost n^2 x points). Hemicube (Cohen and Greenberg 1985): all "
               "patches rasterised onto a hemicube with a depth buffer, at each patch centre or at several points "
               "(cost n^2 x resolution x points; aliasing for small or distant patches). Auto: analytic up to 2,000 "
               "patches, else Monte Carlo. Light that leaves the scene or meets a back face is lost (absorbed).",
       .type = ParamType::Enum, .def = kFormFactorMethods.index(FormFactorMethod::MonteCarlo),
       .choices = kFormFactorMethods.choices()},
      {.name = "rays_per_patch", .label = "Rays per patch (Monte Carlo)",
       .help = "Form-factor rays cast from each patch. The error of each F_ij falls as 1/sqrt(N) or faster; for a "
               "small F_ij it is about 1/sqrt(N F_ij) of it (3.4% for F = 0.003 at 262,144 rays). The radiosity "
               "error averages over many patches and falls faster.",
       .type = ParamType::Int, .def = 1024, .min = 16, .max = 1 << 22},
      {.name = "analytic_points", .label = "Points per patch (analytic)",
       .help = "Base points per patch: the patch is split into 4^L similar triangles (this number rounded down to a "
               "power of 4: 1, 4, 16, 64 ...) and the exact factor taken at each one's centroid (the midpoint rule; "
               "its error is about (r/d)^2/4 for parts of radius r at distance d). For pairs of patches closer than "
               "4 part radii the parts are split further, up to 8 more levels, where a split changes the estimate by "
               "more than 1% of the pair's factor (large patches at a common edge, where the factor varies fastest, "
               "come out within 0.2% too), and, up to 6 levels more, where an edge of the other patch passes "
               "closer than a part's width across it and the factor may change there unseen by the points "
               "(plates 0.01 apart, a strip 0.001 high at a common edge: within 0.5%; a sliver patch as the "
               "source stays within about 1%). One visibility ray per base point and pair.",
       .type = ParamType::Int, .def = 4, .min = 1, .max = 4096},
      {.name = "hemicube_resolution", .label = "Hemicube resolution",
       .help = "Cells across the hemicube's top face (the sides have half as many rows). A patch seen across few "
               "cells aliases: a 0.1 x 0.1 square one away covers about 6 x 6 cells at 128 and comes out 12% low "
               "with one view (3% high at 512); several views (hemicube_points) average that out. Cost grows as the "
               "square.",
       .type = ParamType::Int, .def = 128, .min = 4, .max = 4096},
      {.name = "hemicube_points", .label = "Hemicube views per patch",
       .help = "1: one hemicube at the patch's centre (Cohen and Greenberg 1985), enough when patches are small "
               "against their distances (the error of one central view is about (r/d)^2/4 for patch radius r at "
               "distance d: 12% for unit squares one apart). More: the patch is bisected where its views differ most "
               "and a hemicube placed at each part's centroid (2 views per split), each turned by a random angle "
               "about the normal so that the cells' aliasing averages out. Cost grows in proportion; 129 views (128 "
               "cells) bring two-triangle rectangles of Howell's catalogue within 1% of their exact factor, but "
               "not patches thinner than a few cells as the views see them (a strip 0.01 high at a common edge: "
               "-78%; plates 0.1 to 0.01 apart: +1.2% to +2.7%): use the analytic method there.",
       .type = ParamType::Int, .def = 1, .min = 1, .max = 4096},
  };
}

uint32_t chosenFace(int faceIndex, const std::vector<uint8_t>& selected, size_t faceCount) {
  if (faceIndex >= 0) {
    if (size_t(faceIndex) >= faceCount)
      throw std::invalid_argument("face_index " + std::to_string(faceIndex) + " is beyond the " + std::to_string(faceCount) +
                                  " triangles (a polygon counts as its triangles)");
    return uint32_t(faceIndex);
  }
  std::vector<uint32_t> sel;
  for (size_t f = 0; f < selected.size(); ++f)
    if (selected[f]) sel.push_back(uint32_t(f));
  if (sel.size() != 1)
    throw std::invalid_argument("select exactly one face (" + std::to_string(sel.size()) +
                                " are selected; a selected polygon counts as its triangles), or give face_index");
  return sel[0];
}

FormFactors::Settings formFactorSettings(const ParamValues& v) {
  return {.method = kFormFactorMethods.get(v, "form_factor_method"),
          .raysPerPatch = v.getInt("rays_per_patch"),
          .analyticPoints = v.getInt("analytic_points"),
          .hemicubeResolution = v.getInt("hemicube_resolution"),
          .seed = uint32_t(v.getInt("seed")),
          .hemicubePoints = v.getInt("hemicube_points")};
}

uint64_t FormFactors::raysCast() const {
  uint64_t t = 0;
  for (uint64_t r : rays_) t += r;
  return t;
}
FormFactorRow FormFactors::monteCarloRow(uint32_t i) const {
  FormFactorRow r;
  const int N = set_.raysPerPatch;
  const uint32_t seed = set_.seed;
  const glm::vec3 n = normal_[i];
  const Frame frame(n);
  // Origin (dimension 0) and direction (dimension 1) of ray k from a padded
  // sampler: independent index shuffles, so a ray's origin on the patch says
  // nothing about its direction (two streams stepped together did, and the
  // row did not converge to F on large patches).
  const PaddedSobol smp(hash3(i, seed, 0xf1u));
  const FacePoints points(s_, i, n, eps_, caster_);
  std::vector<uint32_t> hits;
  hits.reserve(size_t(N));
  int lost = 0;
  Ray ray;
  for (int k = 0; k < N; ++k) {
    // Strictly inside the triangle (off an acute edge), then lifted off the plane.
    ray.o = points.at(smp(uint32_t(k), 0)) + n * eps_;
    ray.d = frame.toWorld(cosineHemisphere(smp(uint32_t(k), 1)));
    ray.tnear = 0.f;
    ray.tfar = std::numeric_limits<float>::infinity();
    const Hit h = caster_.intersect(ray);
    if (h.valid() && h.face != i && glm::dot(ray.d, normal_[h.face]) < 0.f) hits.push_back(h.face);
    else ++lost;
  }
  rays_[i] += uint64_t(N);
  std::sort(hits.begin(), hits.end());
  for (size_t k = 0; k < hits.size();) {
    size_t e = k;
    while (e < hits.size() && hits[e] == hits[k]) ++e;
    r.j.push_back(hits[k]);
    r.F.push_back(float(double(e - k) / N));
    k = e;
  }
  r.escaped = float(double(lost) / N);
  return r;
}

bool narrowPatch(const Scene& s, size_t f, double width) {
  const auto& t = s.triangles[f];
  const glm::dvec3 a(s.positions[t.x]), b(s.positions[t.y]), c(s.positions[t.z]);
  const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
  return 2.0 * faceArea(s, f) < width * longest;
}

size_t narrowPatchCount(const Scene& s) {
  const auto ok = usableFaceMask(s);
  const double width = sceneScale(s).rayEpsilon;
  size_t narrow = 0;
  for (size_t f = 0; f < s.faceCount(); ++f) narrow += ok[f] && narrowPatch(s, f, width);
  return narrow;
}

std::optional<std::string> narrowPatchWarning(const Scene& s, size_t narrow, const std::string& what) {
  if (!narrow) return std::nullopt;
  char b[480];
  std::snprintf(b, sizeof b,
                "%zu patch%s narrower than the ray offset (%.3g): rays from %s start within the offset of what "
                "%s touch%s and miss its near part, so %s may read too little light there; merge such slivers into "
                "their neighbours",
                narrow, narrow == 1 ? " is" : "es are", sceneScale(s).rayEpsilon * s.unit,
                narrow == 1 ? "it" : "them", narrow == 1 ? "it" : "they", narrow == 1 ? "es" : "", what.c_str());
  return std::string(b);
}

bool pairwiseUnoccluded(const Scene& s) {
  const auto ok = usableFaceMask(s);
  const double scale = sceneScale(s).maxAbs;  // over the vertices faces use (SceneScale)
  const double tol = 1e-5 * (scale > 0 ? scale : 1.0);
  std::vector<uint32_t> used;
  {
    std::vector<uint8_t> u(s.vertexCount(), 0);
    for (size_t f = 0; f < s.faceCount(); ++f)
      if (ok[f]) u[s.triangles[f].x] = u[s.triangles[f].y] = u[s.triangles[f].z] = 1;
    for (size_t v = 0; v < u.size(); ++v)
      if (u[v]) used.push_back(uint32_t(v));
  }
  // Distinct planes only (a subdivided box has six), visited in a scattered
  // order so that a non-convex scene fails on one of the first planes tried.
  std::map<std::array<long long, 4>, std::pair<glm::dvec3, glm::dvec3>> planes;
  for (size_t k = 0, n = s.faceCount(); k < n; ++k) {
    const size_t f = (k * 2654435761ull) % n;
    if (!ok[f]) continue;
    const glm::dvec3 nn = glm::normalize(glm::dvec3(faceNormalUnnormalized(s, f)));
    const glm::dvec3 a(s.positions[s.triangles[f].x]);
    const std::array<long long, 4> key = {std::llround(nn.x * 1e6), std::llround(nn.y * 1e6), std::llround(nn.z * 1e6),
                                          std::llround(glm::dot(nn, a) / tol)};
    planes.emplace(key, std::make_pair(nn, a));
    if (planes.size() * used.size() > 200000000ull) return false;  // too costly to prove: assume occlusion
  }
  std::vector<std::pair<glm::dvec3, glm::dvec3>> order;
  for (const auto& kv : planes) order.push_back(kv.second);
  for (size_t k = 0, n = order.size(); k < n; ++k) {
    const auto& [nn, a] = order[(k * 2654435761ull) % n];
    for (uint32_t v : used)
      if (glm::dot(nn, glm::dvec3(s.positions[v]) - a) < -tol) return false;
  }
  return true;
}

}  // namespace gi
