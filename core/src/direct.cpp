#include "gi/direct.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>

#include "gi/color.h"
#include "gi/emitters.h"
#include "gi/form_factors.h"
#include "gi/luminaires.h"
#include "gi/sampling.h"
#include "gi/sky.h"
#include "gi/vertex_graph.h"
#include "hit_origin.h"

namespace gi {

VertexMaterial vertexMaterial(const Scene& s) {
  const size_t nv = s.vertexCount();
  VertexMaterial m;
  std::vector<glm::dvec3> rho(nv, glm::dvec3(0.0)), E(nv, glm::dvec3(0.0));
  std::vector<double> w(nv, 0.0);
  const auto ok = usableFaceMask(s);
  for (size_t f = 0; f < s.faceCount(); ++f) {
    // Mirror and glass faces carry no diffuse radiosity: vertices only on them are not valid.
    if (!ok[f] || s.faceMaterial(f) != Material::Diffuse) continue;
    const double a = faceArea(s, f);
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = s.triangles[f][k];
      rho[v] += a * glm::dvec3(s.faceRho(f));
      E[v] += a * glm::dvec3(s.faceEmission(f));
      w[v] += a;
    }
  }
  m.n = vertexNormalsForRays(s);
  m.rho.resize(nv);
  m.E.resize(nv);
  m.valid.resize(nv);
  m.diffuse.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    m.diffuse[i] = w[i] > 0.0;
    m.valid[i] = m.diffuse[i] && glm::dot(m.n[i], m.n[i]) > 0.5f;
    m.rho[i] = w[i] > 0.0 ? glm::vec3(rho[i] / w[i]) : glm::vec3(0.f);
    m.E[i] = w[i] > 0.0 ? glm::vec3(E[i] / w[i]) : glm::vec3(0.f);
  }
  return m;
}

VertexSides twoSidedVertices(const Scene& s, const VertexMaterial& m) {
  std::vector<uint8_t> candidate(s.vertexCount(), 0), faces = usableFaceMask(s);
  for (size_t v = 0; v < candidate.size(); ++v) candidate[v] = m.diffuse[v] && !m.valid[v];
  for (size_t f = 0; f < faces.size(); ++f) faces[f] = faces[f] && s.faceMaterial(f) == Material::Diffuse;
  return vertexSides(s, candidate, faces);
}

VertexSides vertexSides(const Scene& s, const std::vector<uint8_t>& candidate, const std::vector<uint8_t>& faces) {
  const size_t nv = s.vertexCount();
  VertexSides out;
  out.slot.assign(nv, -1);
  std::vector<uint32_t> candidates;
  for (size_t v = 0; v < nv; ++v)
    if (candidate[v]) {
      out.slot[v] = int32_t(candidates.size());
      candidates.push_back(uint32_t(v));
    }
  if (candidates.empty()) return out;
  const size_t nc = candidates.size();
  std::vector<glm::dvec3> ref(nc, glm::dvec3(0.0)), nsum[2], rho[2], E[2];
  std::vector<double> area[2];
  for (int k = 0; k < 2; ++k) {
    nsum[k].assign(nc, glm::dvec3(0.0));
    rho[k].assign(nc, glm::dvec3(0.0));
    E[k].assign(nc, glm::dvec3(0.0));
    area[k].assign(nc, 0.0);
  }
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!faces[f]) continue;
    const auto& t = s.triangles[f];
    const glm::dvec3 a(s.positions[t.x]), cr = glm::cross(glm::dvec3(s.positions[t.y]) - a, glm::dvec3(s.positions[t.z]) - a);
    const double twiceArea = glm::length(cr);
    if (!(twiceArea > 0)) continue;
    for (int c = 0; c < 3; ++c) {
      const int32_t k = out.slot[t[c]];
      if (k < 0) continue;
      if (ref[size_t(k)] == glm::dvec3(0.0)) ref[size_t(k)] = cr / twiceArea;  // the first face (by index) is side A
      const int side = glm::dot(cr, ref[size_t(k)]) > 0 ? 0 : 1;
      nsum[side][size_t(k)] += cr;
      rho[side][size_t(k)] += 0.5 * twiceArea * glm::dvec3(s.faceRho(f));
      E[side][size_t(k)] += 0.5 * twiceArea * glm::dvec3(s.faceEmission(f));
      area[side][size_t(k)] += 0.5 * twiceArea;
    }
  }
  out.slot.assign(nv, -1);
  for (size_t k = 0; k < nc; ++k) {
    const double l0 = glm::length(nsum[0][k]), l1 = glm::length(nsum[1][k]);
    // Two-sided: both sides turn clearly one way, and cancel each other (a
    // reversed copy's cross product is the exact negative). A vertex whose
    // faces do not cancel (a cone's tip whose given normal is not finite)
    // is no two-sided vertex.
    if (!(l0 > 1e-6 * 2 * area[0][k]) || !(l1 > 1e-6 * 2 * area[1][k])) continue;
    if (!(glm::length(nsum[0][k] + nsum[1][k]) <= 1e-6 * (l0 + l1))) continue;
    out.slot[candidates[k]] = int32_t(out.vertex.size());
    out.vertex.push_back(candidates[k]);
    out.ref.push_back(ref[k]);
    for (int sd = 0; sd < 2; ++sd) {
      out.n[sd].push_back(glm::vec3(nsum[sd][k] / (sd ? l1 : l0)));
      out.rho[sd].push_back(glm::vec3(rho[sd][k] / area[sd][k]));
      out.E[sd].push_back(glm::vec3(E[sd][k] / area[sd][k]));
    }
  }
  return out;
}

Scene splitSides(const Scene& s, const VertexSides& sides) {
  Scene out = s;
  if (sides.vertex.empty()) return out;
  const size_t nv = s.vertexCount();
  for (uint32_t v : sides.vertex) out.positions.push_back(s.positions[v]);
  if (out.vertexNormals.size() == nv) {
    for (size_t k = 0; k < sides.vertex.size(); ++k) out.vertexNormals[sides.vertex[k]] = sides.n[0][k];
    for (size_t k = 0; k < sides.vertex.size(); ++k) out.vertexNormals.push_back(sides.n[1][k]);
  }
  const std::vector<uint8_t> ok = usableFaceMask(s);
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!ok[f]) continue;
    glm::uvec3& t = out.triangles[f];
    // The side by vertexSides's own rule (the sides' normals, reflectances
    // and emissions were summed by it).
    const glm::dvec3 a(s.positions[t.x]), cr = glm::cross(glm::dvec3(s.positions[t.y]) - a, glm::dvec3(s.positions[t.z]) - a);
    for (int c = 0; c < 3; ++c) {
      const int32_t k = sides.slot[t[c]];
      if (k >= 0 && !(glm::dot(cr, sides.ref[size_t(k)]) > 0)) t[c] = uint32_t(nv + size_t(k));
    }
  }
  return out;
}

void mergeSides(std::vector<glm::vec3>& value, const VertexSides& sides) {
  if (value.empty() || sides.vertex.empty()) return;
  const size_t nv = sides.slot.size();
  for (size_t k = 0; k < sides.vertex.size(); ++k) {
    glm::vec3& a = value[sides.vertex[k]];
    a = 0.5f * (a + value[nv + k]);
  }
  value.resize(nv);
}

void mergeSideErrors(std::vector<float>& error, const VertexSides& sides) {
  if (error.empty() || sides.vertex.empty()) return;
  const size_t nv = sides.slot.size();
  for (size_t k = 0; k < sides.vertex.size(); ++k) {
    float& a = error[sides.vertex[k]];
    const float b = error[nv + k];
    a = 0.5f * std::sqrt(a * a + b * b);
  }
  error.resize(nv);
}

VertexRadiometry computeDirect(const Scene& s, const RayCaster& caster, const DirectOptions& opt, const Progress& progress) {
  checkCasterFor(s, caster);
  if (opt.lightSamples < 1) throw std::invalid_argument("light_samples must be >= 1");
  Timer timer;
  const EmitterSampler lights(s);
  if (lights.empty())
    throw std::invalid_argument("the scene has no emitters: select the light's faces (or mark them by face quality) "
                                "and choose the matching 'Emitters' option, with emitter_intensity above 0 and an "
                                "emitter_color that is not black");
  const SceneReport rep = analyzeScene(s);
  const float eps = float(rep.rayEpsilon);
  const VertexMaterial mat = vertexMaterial(s);
  const size_t nv = s.vertexCount();
  const std::vector<glm::vec3> origins = vertexRayOrigins(s, mat.n, eps);
  VertexRadiometry out;
  out.B.assign(nv, glm::vec3(0.f));
  out.H.assign(nv, glm::vec3(0.f));
  out.stdError.assign(nv, 0.f);
  const int N = opt.lightSamples;
  parallelBlocks(nv, progress, "direct light", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (!mat.valid[i]) continue;
      SobolOwenStream seq(hash3(uint32_t(i), opt.seed, 0xd1u));
      glm::dvec3 sum(0.0);
      double sl = 0, sl2 = 0;
      for (int j = 0; j < N; ++j) {
        const glm::vec3 c = sampleDirectIrradiance(lights, caster, vertexLightPoint(origins[i], mat.n[i], eps), origins[i],
                                                   mat.n[i], seq.next(), eps);
        sum += glm::dvec3(c);
        const double l = luminance(c * mat.rho[i]);
        sl += l;
        sl2 += l * l;
      }
      const glm::vec3 H = glm::vec3(sum / double(N));
      out.H[i] = H;
      out.B[i] = mat.E[i] + mat.rho[i] * H;
      const double mean = sl / N, var = N > 1 ? std::max(0.0, (sl2 - N * mean * mean) / (N - 1)) : 0.0;
      out.stdError[i] = float(std::sqrt(var / N));
    }
  });
  double err2 = 0, lum = 0;
  size_t valid = 0;
  for (size_t i = 0; i < nv; ++i)
    if (mat.valid[i]) { err2 += double(out.stdError[i]) * out.stdError[i]; lum += luminance(out.B[i]); ++valid; }
  auto& st = out.stats;
  st.add("vertices", double(nv));
  st.add("emitter_faces", double(lights.faceCount()));
  st.add("emitted_power_W", lights.totalPower() * s.unit * s.unit);  // world units (Scene::unit)
  st.add("shadow_rays", double(valid) * N);
  st.add("seconds", timer.seconds());
  st.add("mean_luminance_B", valid ? lum / double(valid) : 0.0);
  st.add("rms_error_estimate", valid ? std::sqrt(err2 / double(valid)) : 0.0);
  st.note("direct light only (per-vertex light sampling)");
  size_t unlit = nv - valid;
  unlit -= copyOnlyAmong(s, [&](size_t i) { return !mat.valid[i]; });
  if (unlit) st.note(std::to_string(unlit) + " vertices without a usable face got 0");
  return out;
}

namespace detail {

// Direct irradiance from the emitters at points of the scene. With up to
// Luminaires::kMaxLuminaires luminaires (coplanar, edge-connected emitter
// triangles of one emission; gi/luminaires.h): the exact point-to-polygon
// factor of each times its visibility from stratified shadow rays (more in
// penumbra); with more: power-proportional light samples combined with
// cosine-weighted directions by MIS (one shadow ray each).
class DirectLight {
 public:
  // sampled: always the MIS light samples. portals: the light of the sky
  // through these openings' portals instead of the emitters'.
  DirectLight(const Scene& s, const RayCaster& c, bool sampled = false, const SkyOpenings* portals = nullptr)
      : s_(s), caster_(c), lights_(s), lums_(portals ? Luminaires(s, *portals) : Luminaires(s)),
        eps_(float(sceneScale(s).rayEpsilon)), portals_(portals != nullptr) {
    exact_ = !sampled && lums_.usable();
    unoccluded_ = pairwiseUnoccluded(s);
    if (exact_) {
      lumOfFace_.assign(s.faceCount(), kNoHit);
      for (size_t L = 0; L < lums_.count(); ++L) {
        const Luminaire& l = lums_.list()[L];
        for (uint32_t f : l.faces) lumOfFace_[f] = uint32_t(L);
        double r = 0;
        for (const glm::dvec3& p : l.corners) r = std::max(r, glm::length(p - l.origin));
        lumRadius_.push_back(r);
        targets_.push_back(lums_.target(L));
      }
    }
  }
  bool empty() const { return portals_ ? lums_.count() == 0 : lights_.empty(); }
  bool exact() const { return exact_; }
  float eps() const { return eps_; }
  // Points per patch for `lightSamples` shadow rays. Power sampling: one
  // each. Luminaires: at most one per kPatchPointRays rays (each point's
  // budget in penumbra), and only as many as the irradiance's variation over
  // the patch asks for: kPointsPerRatio x r / d, r the patch's radius and d
  // its distance from the nearest luminaire's bounding sphere (at least r);
  // one for a patch small against its distance to every light.
  static constexpr int kPatchPointRays = 64;
  static constexpr double kPointsPerRatio = 40.0;
  int maxPoints(int lightSamples) const { return exact_ ? std::max(1, lightSamples / kPatchPointRays) : lightSamples; }
  int points(int lightSamples, size_t face) const {
    const int most = maxPoints(lightSamples);
    if (!exact_ || most == 1) return most;
    const auto& t = s_.triangles[face];
    const glm::dvec3 a(s_.positions[t.x]), b(s_.positions[t.y]), c(s_.positions[t.z]), m = (a + b + c) / 3.0;
    const double r = std::max({glm::length(a - m), glm::length(b - m), glm::length(c - m)});
    double ratio = 0;
    for (size_t L = 0; L < lums_.count(); ++L)
      ratio = std::max(ratio, r / std::max(r, glm::length(m - lums_.list()[L].origin) - lumRadius_[L]));
    return std::clamp(int(std::ceil(kPointsPerRatio * ratio)), 1, most);
  }

  // Sample k of the point's padded sequence: dimensions 1 (light point) and 2
  // (direction) for the MIS samples; dimension 0 is left to the caller (the
  // point on a patch). With luminaires: `budget` shadow rays at most per
  // luminaire, keyed by `key`; light from the luminaire of face `skip` is left out.
  // x: the surface point, whose geometry counts; from: where its rays start
  // (x lifted off its surface).
  LuminaireEstimate estimate(const glm::vec3& x, const glm::vec3& from, const glm::vec3& n, const PaddedSobol& smp,
                             uint32_t k, int budget, uint32_t key, uint32_t skip,
                             LuminaireSums* sums = nullptr) const {
    if (!exact_) {
      LuminaireEstimate e;
      e.H = sampleDirectIrradianceMIS(lights_, s_, caster_, x, from, n, smp(k, 1), smp(k, 2), eps_);
      e.rays = 1;
      return e;
    }
    return luminaireIrradiance(lums_, caster_, x, from, n, budget, key, eps_, unoccluded_, luminaireOf(skip), sums);
  }
  // With luminaires: the one face f belongs to (kNoHit: none).
  uint32_t luminaireOf(uint32_t f) const { return f < lumOfFace_.size() ? lumOfFace_[f] : kNoHit; }
  size_t luminaires() const { return lums_.count(); }
  glm::vec3 emission(size_t L) const { return lums_.list()[L].E; }
  // With luminaires: the unoccluded F from the patch (corners p, unit normal
  // n) to luminaire L, averaged over the patch; *best: the patch's base
  // point of largest F.
  double patchFormFactor(size_t L, const glm::dvec3 p[3], const glm::dvec3& n, glm::dvec3* best) const {
    return meanOverTriangle(p, [&](const glm::dvec3& x) { return lums_.formFactor(L, x, n); }, targets_[L], eps_,
                            best);
  }

  // The log: luminaires found and the method used, and the shadow rays cast.
  void report(RunStats& st, uint64_t rays, uint64_t penumbra, uint64_t points) const {
    st.add("luminaires", double(lums_.count()));
    st.add("direct_shadow_rays", double(rays));
    const std::string found = std::to_string(lums_.count()) + " luminaire" + (lums_.count() == 1 ? "" : "s") + " from " +
                              std::to_string(lums_.emitterFaces()) + " emitter triangles";
    if (!exact_) {
      st.note("direct light: " + found + " (more than " + std::to_string(Luminaires::kMaxLuminaires) +
              "): power sampling with MIS");
      return;
    }
    char b[300];
    std::snprintf(b, sizeof b, "%s: exact form factor x visibility%s", found.c_str(),
                  unoccluded_ ? " (no shadow rays: nothing can occlude)" : "");
    std::string line = std::string("direct light: ") + b;
    if (!unoccluded_) {
      std::snprintf(b, sizeof b,
                    " (%d stratified shadow rays and one to each of up to %zu corners per luminaire, more in penumbra: "
                    "%.1f%% of %llu points)",
                    Luminaires::kFirstRays, Luminaires::kProbes,
                    points ? 100.0 * double(penumbra) / double(points) : 0.0, (unsigned long long)points);
      line += b;
    }
    st.note(line);
  }

 private:
  const Scene& s_;
  const RayCaster& caster_;
  EmitterSampler lights_;
  Luminaires lums_;
  float eps_;
  std::vector<uint32_t> lumOfFace_;
  std::vector<double> lumRadius_;
  std::vector<FormFactorTarget> targets_;
  bool portals_ = false;
  bool exact_ = true, unoccluded_ = false;  // unoccluded: an empty convex room needs no shadow rays
};

}  // namespace detail

using detail::DirectLight;

DirectLightAt::DirectLightAt(const Scene& s, const RayCaster& caster, int samples)
    : impl_(std::make_unique<DirectLight>(s, caster, true)), samples_(std::max(1, samples)) {}
DirectLightAt::~DirectLightAt() = default;
glm::vec3 DirectLightAt::operator()(const glm::vec3& x, const glm::vec3& n, uint32_t key) const {
  if (impl_->empty()) return glm::vec3(0.f);
  return (*this)(x, x + n * impl_->eps(), n, key);
}

glm::vec3 DirectLightAt::operator()(const glm::vec3& x, const glm::vec3& from, const glm::vec3& n, uint32_t key) const {
  if (impl_->empty()) return glm::vec3(0.f);
  const PaddedSobol smp(hash3(key, 0xd8u, 0x5au));
  glm::vec3 sum(0.f);
  for (int k = 0; k < samples_; ++k) sum += impl_->estimate(x, from, n, smp, uint32_t(k), 1, key, kNoHit).H;
  return sum / float(samples_);
}

namespace {

// A patch's mean direct irradiance from the luminaires, given its points'
// sums: sum_L E_L Fbar_L V_L, with Fbar_L the unoccluded factor to L
// averaged over the patch (meanOverTriangle: no noise where F varies
// steeply, as next to an edge the patch shares with L) and V_L the points'
// F-weighted visibility of L, sum_k F_L(x_k) V_L(x_k) / sum_k F_L(x_k)
// (the ratio estimator of Heitz, Hill and McGuire 2018, "Combining
// Analytic Direct Illumination and Stochastic Shadows": exact where nothing
// is hidden). Where no point sees L but part of the patch does (it
// straddles L's plane or horizon), V_L comes from the base point of largest
// F, with its own rays (counted in *rays).
glm::vec3 patchMean(const detail::DirectLight& direct, const Scene& s, size_t i, const glm::vec3& n,
                    const LuminaireSums& sums, int budget, uint32_t seed, uint64_t& rays) {
  const auto& t = s.triangles[i];
  const glm::dvec3 p[3] = {glm::dvec3(s.positions[t.x]), glm::dvec3(s.positions[t.y]), glm::dvec3(s.positions[t.z])};
  const uint32_t own = direct.luminaireOf(uint32_t(i));
  glm::dvec3 H(0.0);
  for (size_t L = 0; L < direct.luminaires(); ++L) {
    if (L == own) continue;
    glm::dvec3 best(0.0);
    const double F = direct.patchFormFactor(L, p, glm::dvec3(n), &best);
    if (!(F > 0.0)) continue;
    double V = 0.0;
    if (sums.F[L] > 0.0) {
      V = sums.FV[L] / sums.F[L];
    } else {
      LuminaireSums one(direct.luminaires());
      const PaddedSobol smp(hash3(uint32_t(i), seed, 0xd4u));
      const LuminaireEstimate e = direct.estimate(glm::vec3(best), glm::vec3(best) + n * direct.eps(), n, smp, 0, budget,
                                                  hash3(uint32_t(i), seed, 0xd9u), uint32_t(i), &one);
      rays += e.rays;
      if (one.F[L] > 0.0) V = one.FV[L] / one.F[L];
    }
    H += F * V * glm::dvec3(direct.emission(L));
  }
  return glm::vec3(H);
}

}  // namespace

std::vector<glm::vec3> patchDirectIrradiance(const Scene& s, const RayCaster& caster, int lightSamples, uint32_t seed,
                                             const Progress& progress, RunStats* stats, const SkyOpenings* portals) {
  if (lightSamples < 1) throw std::invalid_argument("light_samples must be >= 1");
  std::vector<glm::vec3> H(s.faceCount(), glm::vec3(0.f));
  if (portals && !portals->any()) return H;
  const DirectLight direct(s, caster, false, portals);
  if (direct.empty()) return H;
  const auto ok = usableFaceMask(s);
  const int budget = lightSamples / direct.maxPoints(lightSamples);
  std::atomic<uint64_t> rays{0}, penumbra{0}, allPoints{0};
  parallelBlocks(s.faceCount(), progress, "direct light", [&](size_t b, size_t e) {
    uint64_t r = 0, pen = 0, pts = 0;
    LuminaireSums sums;
    for (size_t i = b; i < e; ++i) {
      if (!ok[i]) continue;
      // A patch far from the lights gets few points (40 r / d), enough for
      // the factor, which varies little across it; not for a shadow edge
      // across it, whose share a few points' visibility guessed (a staircase
      // step's patch 20% lit read 4% of that, others +637%, whatever
      // light_samples; an outside audit). Where the points disagree (one in
      // penumbra, or one sees a luminaire that another does not), the patch
      // takes the most points light_samples allows.
      const int most = direct.maxPoints(lightSamples), first = std::min(most, std::max(2, direct.points(lightSamples, i)));
      int points = first;
      const glm::vec3 n = glm::normalize(faceNormalUnnormalized(s, i));
      // Point k on the patch (dimension 0) and its light sample (dimensions 1
      // and 2) from one padded sequence: independent of each other.
      const PaddedSobol smp(hash3(uint32_t(i), seed, 0xd3u));
      const FacePoints onFace(s, uint32_t(i), n, direct.eps(), caster);
      glm::dvec3 sum(0.0);
      if (direct.exact()) sums.F.assign(direct.luminaires(), 0.0), sums.FV.assign(direct.luminaires(), 0.0);
      std::vector<double> before;
      std::vector<uint8_t> lit, dark;
      bool mixed = false;
      if (direct.exact() && first < most) lit.assign(direct.luminaires(), 0), dark.assign(direct.luminaires(), 0);
      for (int k = 0; k < points; ++k) {
        if (!lit.empty()) before = sums.FV, before.insert(before.end(), sums.F.begin(), sums.F.end());
        const glm::vec3 x = onFace.at(smp(uint32_t(k), 0));
        const LuminaireEstimate est = direct.estimate(x, x + n * direct.eps(), n, smp, uint32_t(k), budget,
                                                      hash3(uint32_t(i), seed ^ uint32_t(k), 0xd5u), uint32_t(i), &sums);
        if (!direct.exact()) sum += glm::dvec3(est.H);  // with luminaires the sums give the patch's value
        r += est.rays;
        pen += est.penumbra;
        if (!lit.empty() && !mixed) {
          mixed = est.penumbra;
          const size_t nl = lit.size();
          for (size_t L = 0; L < nl && !mixed; ++L) {
            const double dF = sums.F[L] - before[nl + L], dFV = sums.FV[L] - before[L];
            if (!(dF > 0.0)) continue;
            if (dFV >= dF * (1.0 - 1e-9)) lit[L] = 1;
            else if (dFV <= dF * 1e-9) dark[L] = 1;
            else mixed = true;
            mixed = mixed || (lit[L] && dark[L]);
          }
          if (mixed) points = most;
        }
      }
      pts += uint64_t(points);
      H[i] = direct.exact() ? patchMean(direct, s, i, n, sums, budget, seed, r)
                            : glm::vec3(sum / double(points));
    }
    rays += r;
    penumbra += pen;
    allPoints += pts;
  });
  if (stats) direct.report(*stats, rays.load(), penumbra.load(), allPoints.load());
  return H;
}

std::vector<glm::vec3> seenPartDirectIrradiance(const Scene& s, const RayCaster& caster, int lightSamples, uint32_t seed,
                                                const std::vector<std::vector<glm::vec3>>& points,
                                                const SkyOpenings* portals) {
  if (lightSamples < 1) throw std::invalid_argument("light_samples must be >= 1");
  if (points.size() != s.faceCount()) throw std::logic_error("seen points: one list per face");
  std::vector<glm::vec3> H(s.faceCount(), glm::vec3(0.f));
  if (portals && !portals->any()) return H;
  const DirectLight direct(s, caster, false, portals);
  if (direct.empty()) return H;
  const int budget = lightSamples / direct.maxPoints(lightSamples);
  parallelBlocks(s.faceCount(), Progress(nullptr), "direct light of seen parts", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const size_t m = points[i].size();  // every one: a seen part's light changes fast beside what buries it
      if (m == 0) continue;
      const glm::vec3 n = glm::normalize(faceNormalUnnormalized(s, i));
      const PaddedSobol smp(hash3(uint32_t(i), seed, 0xdau));
      glm::dvec3 sum(0.0);
      for (size_t k = 0; k < m; ++k)
        sum += glm::dvec3(direct.estimate(points[i][k], points[i][k] + n * direct.eps(), n, smp, uint32_t(k), budget,
                                          hash3(uint32_t(i), seed ^ uint32_t(k), 0xdbu), uint32_t(i)).H);
      H[i] = glm::vec3(sum / double(m));
    }
  });
  return H;
}

namespace {
// A vertex's standard error from at least the mean variance of the vertices
// two rings around it (its own included). Power sampling picks a luminaire
// by its power, so a near one, whose light dominates, comes up rarely: a few
// samples' variance is skewed low at every vertex (1,600 emitting squares
// over a floor: z-scores 2.5 wide with the vertex's own variance), while the
// mean over the neighbours' samples, who see nearly the same luminaires,
// catches them.
void poolOverRings(const Scene& s, const std::vector<uint8_t>& valid, int samples, std::vector<float>& se) {
  const size_t nv = se.size();
  std::vector<double> var(nv);
  for (size_t v = 0; v < nv; ++v) var[v] = double(se[v]) * se[v] * samples;
  atLeastRingMean(VertexGraph::build(s), valid, var);
  for (size_t v = 0; v < nv; ++v)
    if (valid[v]) se[v] = float(std::sqrt(var[v] / samples));
}
}  // namespace

std::vector<glm::vec3> vertexDirectIrradiance(const Scene& s, const RayCaster& caster, int lightSamples, uint32_t seed,
                                              const Progress& progress, const VertexPart& part,
                                              const SkyOpenings* portals, std::vector<float>* stdError) {
  const VertexMaterial mat = vertexMaterial(s);
  std::vector<glm::vec3> H(s.vertexCount(), glm::vec3(0.f));
  if (stdError) stdError->assign(s.vertexCount(), 0.f);
  if (portals && !portals->any()) return H;
  const DirectLight direct(s, caster, false, portals);
  if (direct.empty()) return H;
  const std::vector<glm::vec3> origins = vertexRayOrigins(s, mat.n, direct.eps());
  // A vertex is one point: with luminaires, all of light_samples in penumbra.
  const int points = direct.exact() ? 1 : lightSamples, budget = lightSamples;
  parallelBlocks(s.vertexCount(), progress, "direct light at vertices", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (!mat.valid[i] || !part.contains(i, s.vertexCount())) continue;
      const PaddedSobol smp(hash3(uint32_t(i), seed, 0xd6u));
      glm::dvec3 sum(0.0);
      double sl = 0, sl2 = 0;
      for (int k = 0; k < points; ++k) {
        const glm::vec3 h =
            direct.estimate(vertexLightPoint(origins[i], mat.n[i], direct.eps()), origins[i], mat.n[i], smp, uint32_t(k), budget,
                            hash3(uint32_t(i), seed ^ uint32_t(k), 0xd7u),
                            kNoHit).H;
        sum += glm::dvec3(h);
        const double l = luminance(mat.rho[i] * h);  // of rho H, B's reflected light
        sl += l, sl2 += l * l;
      }
      H[i] = glm::vec3(sum / double(points));
      if (stdError && points > 1) {
        const double m = sl / points, var = std::max(0.0, (sl2 - points * m * m) / (points - 1));
        (*stdError)[i] = float(std::sqrt(var / points));
      }
    }
  });
  if (stdError && points > 1) poolOverRings(s, mat.valid, points, *stdError);
  return H;
}

std::vector<glm::vec3> finalGather(const Scene& s, const RayCaster& caster, const VertexMaterial& mat, int rays,
                                   uint32_t key, const std::function<glm::vec3(const GatherHit&)>& value,
                                   const VertexPart& part, const Progress& progress, std::vector<VertexRays>* lum) {
  const std::vector<glm::vec3> origins = vertexRayOrigins(s, mat.n, float(sceneScale(s).rayEpsilon));
  std::vector<glm::vec3> H(s.vertexCount(), glm::vec3(0.f));
  if (lum) lum->assign(s.vertexCount(), VertexRays{});
  parallelBlocks(s.vertexCount(), progress, "final gather at vertices", [&](size_t b, size_t e) {
    for (size_t v = b; v < e; ++v) {
      if (!mat.valid[v] || !part.contains(v, s.vertexCount())) continue;
      SobolOwenStream seq(hash3(uint32_t(v), key, 0xf9u));
      const Frame frame(mat.n[v]);
      glm::dvec3 sum(0.0);
      double syy = 0;  // of the rays' luminances
      Ray ray;
      ray.o = origins[v];
      for (int k = 0; k < rays; ++k) {
        ray.d = frame.toWorld(cosineHemisphere(seq.next()));
        ray.tfar = std::numeric_limits<float>::infinity();
        // One ray at a time: 8-wide packets from the vertex were no faster
        // (the 1M-triangle scan room: 59 s against 57 s).
        const Hit h = caster.intersect(ray);
        // The hit's front from the caster's geometric normal (winding order),
        // not from a table of face normals: on a large mesh that lookup was
        // a cache miss per ray.
        if (!h.valid() || !(glm::dot(ray.d, h.ng) < 0.f)) continue;
        const glm::vec3 x = value(GatherHit{h.face, ray.o + ray.d * h.t, h.t, uint32_t(v), uint32_t(k), ray.o, ray.d, h.u, h.v});
        sum += glm::dvec3(x);
        if (lum) {
          const double y = luminance(x);
          syy += y * y;
        }
      }
      H[v] = glm::vec3(sum / double(rays));
      if (lum) {
        const double sy = luminance(glm::vec3(sum)), m = sy / rays;
        const double var = rays > 1 ? std::max(0.0, syy / rays - m * m) * rays / (rays - 1) : 0.0;
        (*lum)[v] = VertexRays{uint32_t(rays), sy, var, glm::vec3(0.f)};
      }
    }
  });
  return H;
}

}  // namespace gi
