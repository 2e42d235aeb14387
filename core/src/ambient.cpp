#include "gi/ambient.h"

#include "ambient_internal.h"
#include "gi/ao_strata.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

#include <tbb/parallel_sort.h>

#include "gi/color.h"
#include "gi/direct.h"
#include "gi/open_space.h"
#include "gi/sampling.h"
#include "gi/sky.h"

namespace gi {
namespace {

constexpr int kRound = 32;  // rays per adaptive round (a power of two keeps Sobol prefixes balanced)

// Whether the adaptive strata estimator runs (gi/ao_strata.h): occlusion only
// (obscurance is refused; the cone's ratio estimator and sky lighting stay
// per vertex).
bool strataRuns(const AmbientOptions& o) {
  return o.estimator == AOEstimator::Strata && o.mode == AmbientMode::Occlusion && !o.useCone;
}
// Its rounds to a target, and its grid: the fixed one, or the first round's.
StrataTarget strataTargetOf(const AmbientOptions& o) { return {o.targetError, o.minRays, o.maxRays}; }
StrataGrid firstStrataGrid(const AmbientOptions& o) {
  return StrataGrid::forRays(o.targetError > 0.0 ? o.minRays : o.raysPerVertex);
}

// A bent normal: the mean open direction, or the normal where none was open.
glm::vec3 bentOrNormal(const glm::vec3& sum, const glm::vec3& n) {
  return glm::length(sum) > 0.f ? glm::normalize(sum) : n;
}

// Running sums of per-ray contributions (a division-free Welford stand-in;
// values are in [0,1] so double sums lose nothing that matters).
struct Moments {
  double n = 0, sum = 0, sumSq = 0;
  void add(double x) { n += 1; sum += x; sumSq += x * x; }
  double mean() const { return n > 0 ? sum / n : 0.0; }
  double stdError() const {
    if (n < 2) return 1.0;
    const double m = sum / n;
    return std::sqrt(std::max(0.0, (sumSq - n * m * m) / (n - 1)) / n);
  }
};

struct VertexOut {
  float value = 0.f, stdError = 0.f;
  bool capped = false;  // to a target: the pilot asked for more than max_rays
  bool agreed = false;  // every ray gave the same value (the error is the Laplace bound)
  int rays = 0;
  glm::vec3 rgb{0.f}, bent{0.f};
};

class AmbientKernel {
 public:
  AmbientKernel(const RayCaster& c, const AmbientOptions& o) : caster_(c), o_(o) {
    tfar_ = o.maxDistance > 0.0 ? float(o.maxDistance) : std::numeric_limits<float>::infinity();
    // Sky lighting: the target is the sky's light's standard error in W/m^2,
    // the sky fraction's times the sky's irradiance (no sky: nothing to refine).
    const double sky = o.mode == AmbientMode::Sky ? double(o.skyIrradiance) * luminance(o.skyRadiantColor) : 1.0;
    target_ = sky > 0.0 ? o.targetError / sky : std::numeric_limits<double>::infinity();
    coneCos_ = std::cos(glm::radians(o.coneAngleDeg));
    sunCos_ = std::cos(glm::radians(o.sunAngularRadiusDeg));
    sunScale_ = sunDiskScale(o.sunAngularRadiusDeg);  // a facing surface gets E_sun (gi/sky.h)
    strata_ = strataRuns(o);
    grid_ = firstStrataGrid(o);
  }

  VertexOut run(uint32_t vi, const glm::vec3& org, const glm::vec3& n) const {
    const Frame frame(n);
    if (strata_) {
      VertexOut out;
      const uint32_t key = hash3(vi, o_.seed, 0x53u);
      const StrataEstimate e = o_.targetError > 0.0
                                   ? strataOcclusionToTarget(caster_, key, org, frame, tfar_, strataTargetOf(o_))
                                   : strataOcclusion(caster_, key, org, frame, tfar_, grid_);
      out.value = float(e.value);
      out.stdError = float(std::sqrt(e.variance));
      out.rays = e.rays;
      out.capped = e.capped;
      if (o_.bentNormals) out.bent = bentOrNormal(e.bent, n);
      return out;
    }
    if (!(o_.targetError > 0.0)) return finish(cast(hash3(vi, o_.seed, 0x41u), o_.raysPerVertex, 0.0, org, frame), vi, n, org);
    // To a target: a pilot on numbers of its own, rounds of kRound rays to
    // kPilotLooseness times the target (at most a quarter of max_rays),
    // sizes the count (gi/sampling.h); the count's rays, the vertex's
    // fixed-count rays, are the result, and the pilot is left out of it.
    // Stopping on the kept rays biased the mean low where light comes
    // through a small opening: a room lit through a window, -0.19 target
    // units at a target of 0.005.
    const int pilotMax = std::max(o_.minRays, o_.maxRays / 4);
    const VertexOut pilot = cast(hash3(vi, o_.seed, 0x4cu), pilotMax, kPilotLooseness * target_, org, frame);
    // Rays whose error bar falls as 1/sqrt(n) (their variance per ray), or,
    // where all the pilot's rays agreed, as the Laplace bound's 1/n.
    const double goal = target_ / std::sqrt(kPilotMargin);
    const double ratio = goal > 0.0 ? double(pilot.stdError) / goal : 0.0;
    const double want = std::ceil(pilot.agreed ? pilot.rays * ratio : pilot.rays * ratio * ratio);
    const int most = std::max(o_.minRays, o_.maxRays - pilot.rays);
    VertexOut out = cast(hash3(vi, o_.seed, 0x41u), int(std::clamp(want, double(o_.minRays), double(most))), 0.0,
                         org, frame);
    out.capped = want > most;
    out.rays += pilot.rays;
    return finish(out, vi, n, org);
  }

 private:
  // Rays of the Sobol sequence keyed by seqKey, at most maxN, in rounds of
  // kRound; with stopAt > 0 it stops once min_rays are cast and the
  // standard error is at most stopAt (per-ray units).
  VertexOut cast(uint32_t seqKey, int maxN, double stopAt, const glm::vec3& org, const Frame& frame) const {
    VertexOut out;
    const glm::vec3& n = frame.n;
    const Frame cone(o_.coneDirection);
    SobolOwenStream seq(seqKey);
    Ray rays[kRound];
    glm::vec3 dirs[kRound];
    float u0[kRound], u1[kRound], lx[kRound], ly[kRound], lz[kRound];
    uint8_t occ[kRound];
    Hit hits[kRound];
    const bool fan = o_.batch == BatchMode::Single && o_.mode != AmbientMode::Obscurance;
    Moments w;                 // per-ray values (or ratio residuals for the cone)
    double num = 0, den = 0;   // cone: sums of V cos and cos
    double numSq = 0, denSq = 0, numDen = 0;
    glm::vec3 bent(0.f);
    int done = 0;
    while (done < maxN) {
      const int m = std::min(kRound, maxN - done);
      seq.nextBlock(m, u0, u1);
      if (o_.useCone) {
        for (int j = 0; j < m; ++j) dirs[j] = cone.toWorld(uniformCone({u0[j], u1[j]}, coneCos_));
      } else {
        cosineHemisphereBlock(m, u0, u1, lx, ly, lz);
        for (int j = 0; j < m; ++j) dirs[j] = frame.t * lx[j] + frame.b * ly[j] + frame.n * lz[j];
      }
      if (!fan)
        for (int j = 0; j < m; ++j) { rays[j].o = org; rays[j].d = dirs[j]; rays[j].tnear = 0.f; rays[j].tfar = tfar_; }
      if (o_.mode == AmbientMode::Obscurance) caster_.intersectBatch(rays, size_t(m), hits);
      else if (fan) caster_.occludedFan(org, dirs, size_t(m), tfar_, occ);
      else caster_.occludedBatch(rays, size_t(m), occ);
      for (int j = 0; j < m; ++j) {
        double f;
        if (o_.mode == AmbientMode::Obscurance) {
          f = hits[j].valid() ? std::pow(std::min(1.0, double(hits[j].t) / o_.maxDistance), double(o_.falloffExponent)) : 1.0;
        } else {
          f = occ[j] ? 0.0 : 1.0;
        }
        if (o_.bentNormals && f > 0.0) bent += dirs[j] * float(f);
        if (o_.useCone) {
          const double c = std::max(0.f, glm::dot(n, dirs[j]));
          num += f * c; den += c; numSq += f * c * f * c; denSq += c * c; numDen += f * c * c;
        } else {
          w.add(f);
        }
      }
      done += m;
      if (!(stopAt > 0.0) || done < o_.minRays) continue;
      if (stdError(w, done, num, den, numSq, denSq, numDen) <= stopAt) break;
    }
    out.rays = done;
    if (o_.useCone) out.value = den > 0 ? float(num / den) : 0.f;
    else out.value = float(w.mean());
    out.stdError = float(stdError(w, done, num, den, numSq, denSq, numDen));
    out.agreed = !o_.useCone && w.n >= 1 && !(w.stdError() > 0.0);
    if (o_.bentNormals) out.bent = bentOrNormal(bent, n);
    return out;
  }

  // Bent normals are set by cast; sky lighting adds the sun.
  VertexOut finish(VertexOut out, uint32_t vi, const glm::vec3& n, const glm::vec3& org) const {
    if (o_.mode == AmbientMode::Sky) out = addSun(out, vi, n, org);
    return out;
  }

  double stdError(const Moments& w, int n, double num, double den, double numSq, double denSq, double numDen) const {
    if (!o_.useCone) {
      // Rays that all agreed (all 32 first rays of a vertex escaped, past a
      // thin occluder seen edge-on) have a sample variance of 0: then the
      // variance of a Bernoulli variable at the Laplace estimate
      // (sum + 1) / (n + 2) stands in, as in the shared estimator. Reporting
      // 0 stopped such vertices with errors of 20 reported standard errors.
      const double se = w.stdError();
      if (se > 0.0 || w.n < 1) return se;
      const double p = (w.sum + 1.0) / (w.n + 2.0);
      return std::sqrt(p * (1.0 - p) / w.n);
    }
    if (den <= 0.0 || n < 2) return 0.0;
    // Ratio estimator R = sum(f c) / sum(c): delta-method variance of mean(f c - R c) / mean(c).
    const double R = num / den, N = n;
    const double varRes = (numSq - 2 * R * numDen + R * R * denSq) / (N - 1);
    const double meanC = den / N;
    return std::sqrt(std::max(0.0, varRes) / N) / meanC;
  }

  VertexOut addSun(VertexOut out, uint32_t vi, const glm::vec3& n, const glm::vec3& org) const {
    const glm::vec3 sky = o_.skyRadiantColor * o_.skyIrradiance * out.value;
    glm::vec3 sun(0.f);
    int sunRays = 0;
    double sunErr = 0.0;
    if (o_.sunIrradiance > 0.f && glm::dot(n, o_.sunDirection) > -std::sin(glm::radians(o_.sunAngularRadiusDeg)) - 1e-6f) {
      // Distributed ray tracing over the sun's disk: uniform directions in its cone.
      const Frame sf(o_.sunDirection);
      SobolOwenStream seq(hash3(vi, o_.seed, 0x5u));
      Ray rays[kRound];
      uint8_t occ[kRound];
      Moments w;
      for (int done = 0; done < o_.sunRays; done += kRound) {
        const int m = std::min(kRound, o_.sunRays - done);
        for (int j = 0; j < m; ++j) {
          rays[j].o = org; rays[j].d = sf.toWorld(uniformCone(seq.next(), sunCos_));
          rays[j].tnear = 0.f; rays[j].tfar = tfar_;  // max_distance: farther geometry does not occlude
        }
        caster_.occludedBatch(rays, size_t(m), occ);
        for (int j = 0; j < m; ++j) w.add(occ[j] ? 0.0 : std::max(0.f, glm::dot(n, rays[j].d)));
      }
      sunRays = o_.sunRays;
      sun = o_.sunColor * float(o_.sunIrradiance * sunScale_ * w.mean());
      sunErr = o_.sunIrradiance * sunScale_ * w.stdError() * luminance(o_.sunColor);
    }
    const double skyErr = double(out.stdError) * o_.skyIrradiance * luminance(o_.skyRadiantColor);
    out.rgb = sky + sun;
    out.value = luminance(out.rgb);
    out.stdError = float(std::sqrt(skyErr * skyErr + sunErr * sunErr));
    out.rays += sunRays;
    return out;
  }

  const RayCaster& caster_;
  const AmbientOptions& o_;
  float tfar_, coneCos_, sunCos_, sunScale_;
  bool strata_;       // the adaptive strata estimator (gi/ao_strata.h)
  StrataGrid grid_;
  double target_;  // the adaptive stop, in the units of the per-ray values
};

// The parameter table refuses all of these; a library caller filling
// AmbientOptions directly gets the same refusals. Returns the options with
// the cone's and the sun's directions scaled to unit length.
AmbientOptions checkedOptions(const AmbientOptions& in) {
  AmbientOptions o = in;
  auto finiteColour = [](const glm::vec3& c) { return finite3(c) && c.r >= 0.f && c.g >= 0.f && c.b >= 0.f; };
  if (!(o.targetError >= 0.0) || !std::isfinite(o.targetError))
    throw std::invalid_argument("target_error must be a finite number >= 0");
  if (o.targetError > 0.0 && (o.minRays < 1 || o.maxRays < 1))
    throw std::invalid_argument("min_rays and max_rays must be >= 1");
  if (o.targetError > 0.0 && o.minRays > o.maxRays)
    throw std::invalid_argument("min_rays (" + std::to_string(o.minRays) + ") exceeds max_rays (" + std::to_string(o.maxRays) + ")");
  if (o.mode == AmbientMode::Obscurance && !(o.maxDistance > 0.0))
    throw std::invalid_argument("obscurance needs a maximum distance > 0 (its falloff is relative to it)");
  if (!(o.maxDistance >= 0.0)) throw std::invalid_argument("max_distance must be >= 0");
  if (o.raysPerVertex < 1) throw std::invalid_argument("rays_per_vertex must be >= 1");
  if (o.estimator == AOEstimator::Strata && o.mode == AmbientMode::Obscurance)
    throw std::invalid_argument("the adaptive strata estimator tests visibility only; obscurance (hit distances) "
                                "needs the per-vertex or shared estimator");
  if (strataRuns(o) && o.targetError > 0.0) {
    // Rounds never pass max_rays (gi/ao_strata.h), so the first round, cast
    // twice (the pilot's and the result's), must fit with every stratum split.
    const StrataGrid first = firstStrataGrid(o);
    if (8 * int64_t(first.strata()) > int64_t(o.maxRays))
      throw std::invalid_argument("adaptive strata: the first round (" + std::to_string(first.rows) + " x " +
                                  std::to_string(first.cols) + " strata for min_rays " + std::to_string(o.minRays) +
                                  "), cast for the pilot and for the result, may cast " +
                                  std::to_string(8 * first.strata()) + " rays with every stratum split, above "
                                  "max_rays " + std::to_string(o.maxRays) + "; raise max_rays or lower min_rays");
  }
  if (o.shareRings < 0 || o.shareRings > 64) throw std::invalid_argument("share_rings must lie in [0, 64]");
  if (!(o.shareNormalAngleDeg >= 0.f && o.shareNormalAngleDeg <= 180.f))
    throw std::invalid_argument("share_normal_angle must lie in [0, 180] degrees");
  if (o.mode == AmbientMode::Obscurance && !(o.falloffExponent > 0.f && std::isfinite(o.falloffExponent)))
    throw std::invalid_argument("the falloff exponent must be a finite number > 0");
  if (o.useCone) {
    if (!(o.coneAngleDeg > 0.f && o.coneAngleDeg <= 180.f))
      throw std::invalid_argument("cone_angle must lie in (0, 180] degrees");
    const auto d = unitKeepingBits(o.coneDirection);
    if (!d) throw std::invalid_argument("cone_direction must be a finite, nonzero vector");
    o.coneDirection = *d;
  }
  if (o.mode == AmbientMode::Sky) {
    if (!(o.skyIrradiance >= 0.f && std::isfinite(o.skyIrradiance)) ||
        !(o.sunIrradiance >= 0.f && std::isfinite(o.sunIrradiance)))
      throw std::invalid_argument("sky_irradiance and sun_irradiance must be finite numbers >= 0");
    if (!finiteColour(o.skyRadiantColor) || !finiteColour(o.sunColor))
      throw std::invalid_argument("the sky's and the sun's colours must be finite and >= 0");
    if (o.sunIrradiance > 0.f) {
      const auto d = unitKeepingBits(o.sunDirection);
      if (!d) throw std::invalid_argument("sun_direction must be a finite, nonzero vector");
      o.sunDirection = *d;
      if (!(o.sunAngularRadiusDeg >= 0.f && o.sunAngularRadiusDeg <= 90.f))
        throw std::invalid_argument("sun_angular_radius must lie in [0, 90] degrees");
      if (o.sunRays < 1) throw std::invalid_argument("sun_rays must be >= 1");
    }
  }
  return o;
}

// Warnings for settings that make the result meaningless (RunStats::warn);
// usable = usableFaceMask(scene).
// capped: to a target, the vertices whose count max_rays cut.
void warnMeaningless(const Scene& scene, const std::vector<uint8_t>& usable, const AmbientOptions& o,
                     const AmbientResult& res, const std::vector<uint8_t>& capped, RunStats& st) {
  auto num = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return std::string(buf);
  };
  if (o.maxDistance > 0.0) {
    // Rays start eps off the surface (and eps into the face at lopsided one-rings).
    const double eps = sceneScale(scene).rayEpsilon;
    std::vector<float> edges;
    for (size_t f = 0; f < scene.faceCount(); ++f)
      if (usable[f])
        for (int k = 0; k < 3; ++k)
          edges.push_back(glm::length(scene.positions[scene.triangles[f][k]] - scene.positions[scene.triangles[f][(k + 1) % 3]]));
    float median = 0.f;
    if (!edges.empty()) {
      std::nth_element(edges.begin(), edges.begin() + edges.size() / 2, edges.end());
      median = edges[edges.size() / 2];
    }
    if (o.maxDistance <= 10.0 * eps)
      st.warn("max_distance " + num(o.maxDistance) + " is within 10 ray offsets (rays start " + num(eps) +
              " off the surface): what it sees is where the rays start, not the shape");
    else if (o.maxDistance < 0.1 * median)
      st.warn("max_distance " + num(o.maxDistance) + " is below a tenth of the median edge length " + num(median) +
              ": within it a vertex sees only its own faces, so the result shows the angles between neighbouring faces, "
              "not the rest of the mesh");
  }
  if (o.mode == AmbientMode::Sky) {
    if (!(o.skyIrradiance > 0.f) && !(o.sunIrradiance > 0.f))
      st.warn("sky_irradiance and sun_irradiance are both 0: no light, every vertex is black");
    if (o.sunIrradiance > 0.f && !(o.sunAngularRadiusDeg > 0.f) && o.sunRays > 1)
      st.warn("sun_angular_radius 0 is a point sun: all " + std::to_string(o.sunRays) +
              " sun rays per vertex follow one direction (hard shadows; one ray gives the same)");
  }
  if (o.targetError > 0.0) {
    size_t unmet = 0, traced = 0;
    float worst = 0.f;
    for (size_t i = 0; i < res.rays.size(); ++i) {
      if (res.rays[i] == 0) continue;
      ++traced;
      if (capped[i] && res.stdError[i] > o.targetError) {
        ++unmet;
        worst = std::max(worst, res.stdError[i]);
      }
    }
    if (unmet * 10 > traced)
      st.warn(std::to_string(unmet) + " of " + std::to_string(traced) + " vertices stopped at max_rays " +
              std::to_string(o.maxRays) + " with their standard error above target_error " + num(o.targetError) +
              " (up to " + num(worst) + "): the target is not met; raise max_rays or the target");
  }
}

}  // namespace

AmbientResult computeAmbient(const Scene& scene, const RayCaster& caster, const AmbientOptions& optWorld,
                             const Progress& progress) {
  AmbientOptions opt = checkedOptions(optWorld);
  opt.maxDistance = optWorld.maxDistance / scene.unit;  // local units (Scene::unit)
  Timer timer;
  // Which faces the ray caster builds: one pass over the faces for the
  // analysis, the normals, the ray origins and the shared estimator's graph.
  const std::vector<uint8_t> usable = usableFaceMask(scene);
  const SceneReport rep = analyzeScene(scene, /*duplicateFaces=*/false, &usable);  // AO does not depend on them
  if (rep.usableFaces() == 0) throw std::invalid_argument("the mesh has no usable triangles (" + rep.summary() + ")");
  const size_t nv = scene.vertexCount();
  const std::vector<glm::vec3> normals = vertexNormalsForRays(scene, &usable);

  // Which vertices need rays: valid ones, one per (position, normal) class, not provably open.
  enum : uint8_t { kTrace, kInvalid, kDuplicate, kOpen, kOtherPart, kTwoSided };
  std::vector<uint8_t> status(nv, kTrace);
  std::vector<uint32_t> rep_of(nv);
  for (size_t i = 0; i < nv; ++i) {
    rep_of[i] = uint32_t(i);
    const glm::vec3& n = normals[i];
    const glm::vec3& p = scene.positions[i];
    const bool ok = finite3(p) && finite3(n) &&
                    glm::dot(n, n) > 0.5f;
    if (!ok) status[i] = kInvalid;
  }
  // A vertex of a two-sided surface (each face with a reversed copy) has no
  // normal: it gets the mean of its two sides, each computed per vertex.
  std::vector<uint8_t> noNormal(nv, 0);
  for (size_t i = 0; i < nv; ++i) noNormal[i] = status[i] == kInvalid && finite3(scene.positions[i]);
  const VertexSides sides = vertexSides(scene, noNormal, usable);
  for (uint32_t v : sides.vertex) status[v] = kTwoSided;
  size_t duplicates = 0, open = 0, invalid = 0;
  if (opt.mergeDuplicates) {
    // Sorted by the bits of their six coordinates (+ 0 folds -0 into 0), in
    // parallel; each run of equal keys is represented by its lowest index.
    struct Keyed { std::array<uint32_t, 6> k; uint32_t i; };
    std::vector<Keyed> keys;
    keys.reserve(nv);
    for (size_t i = 0; i < nv; ++i) {
      if (status[i] != kTrace) continue;
      const auto& p = scene.positions[i];
      const auto& n = normals[i];
      const float v[6] = {p.x + 0.f, p.y + 0.f, p.z + 0.f, n.x + 0.f, n.y + 0.f, n.z + 0.f};
      Keyed k;
      std::memcpy(k.k.data(), v, sizeof v);
      k.i = uint32_t(i);
      keys.push_back(k);
    }
    tbb::parallel_sort(keys.begin(), keys.end(), [](const Keyed& a, const Keyed& b) { return a.k != b.k ? a.k < b.k : a.i < b.i; });
    for (size_t k = 1, first = 0; k < keys.size(); ++k) {
      if (keys[k].k != keys[first].k) { first = k; continue; }
      status[keys[k].i] = kDuplicate;
      rep_of[keys[k].i] = keys[first].i;
      ++duplicates;
    }
  }
  const VertexPart& part = opt.vertices;
  if (!part.all()) {
    // A split run computes its part and the representatives its duplicates copy.
    std::vector<uint8_t> need(nv, 0);
    for (size_t i = 0; i < nv; ++i)
      if (part.contains(i, nv)) need[rep_of[i]] = 1;
    for (size_t i = 0; i < nv; ++i)
      if (status[i] == kTrace && !need[i]) status[i] = kOtherPart;
  }
  // Vertices whose rays provably all escape get 1 without rays: nothing
  // above the tangent plane within max_distance, or, for rays of any length,
  // in the whole scene. The first costs about 6 to 9 of a vertex's rays, so
  // it runs where a sample says it pays (OpenSpaceTest::plan). The second
  // costs about as much as 50 to 100 of an open vertex's rays (measured on
  // the bunny, bunny_fine and scan_118k: 0.35 to 0.45 microseconds a
  // vertex), so it runs where an open vertex would cast at least 128 rays,
  // and for the per-vertex estimator only (the shared one casts just its
  // first round there, and those rays serve its neighbours' pools).
  const bool hemisphereRays = opt.mode != AmbientMode::Sky && !opt.useCone;
  // (An open vertex under adaptive strata also splits its horizon row: 3 rays a column.)
  const bool strata = strataRuns(opt);
  const int openVertexRays =
      strata ? (opt.targetError > 0.0 ? strataRaysWhenOpen(strataTargetOf(opt)) : strataRaysWhenOpen(firstStrataGrid(opt)))
             : opt.targetError > 0.0 ? std::max(opt.minRays, kRound)
                                     : opt.raysPerVertex;
  const bool openWithin = opt.skipOpenVertices && hemisphereRays && opt.maxDistance > 0.0;
  const bool openEverywhere = opt.skipOpenVertices && hemisphereRays && !(opt.maxDistance > 0.0) &&
                              opt.estimator != AOEstimator::Shared && openVertexRays >= 128;
  double proofSeconds = -1.0;  // the proof's time, its tree included (-1: not run)
  std::string proofNote;       // why it was not run
  if (openWithin || openEverywhere) {
    const Timer proofTimer;
    std::unique_ptr<OpenSpaceTest> within;
    std::unique_ptr<SceneBelowTest> everywhere;
    if (openWithin) within = std::make_unique<OpenSpaceTest>(scene, float(rep.rayEpsilon), normals, &usable, false);
    else everywhere = std::make_unique<SceneBelowTest>(scene, float(rep.rayEpsilon), normals, &usable);
    std::vector<uint32_t> candidates;  // of the whole run, so that every part decides alike
    for (size_t i = 0; within && i < nv; ++i)
      if (status[i] == kTrace || status[i] == kOtherPart) candidates.push_back(uint32_t(i));
    const OpenSpaceTest::Plan plan =
        within ? within->plan(candidates, float(opt.maxDistance), openVertexRays) : OpenSpaceTest::Plan{true};
    const bool prove = plan.pays;
    if (!prove) proofNote = plan.whyNot(openVertexRays);
    std::vector<uint8_t> isOpen(nv, 0);
    parallelBlocks(prove ? nv : 0, progress.sub(0.0, 0.05), "finding open vertices", [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        if (status[i] != kTrace) continue;
        isOpen[i] = (within ? within->openWithin(uint32_t(i), float(opt.maxDistance))
                            : everywhere->sceneBelow(uint32_t(i))) ? 1 : 0;
      }
    });
    for (size_t i = 0; i < nv; ++i)
      if (isOpen[i]) { status[i] = kOpen; ++open; }
    proofSeconds = proofTimer.seconds();
  }

  AmbientResult res;
  std::vector<uint8_t> capped(nv, 0);  // to a target: the vertices whose count max_rays cut
  res.value.assign(nv, 0.f);
  res.stdError.assign(nv, 0.f);
  res.rays.assign(nv, 0);
  if (opt.mode == AmbientMode::Sky) res.rgb.assign(nv, glm::vec3(0.f));
  if (opt.bentNormals) res.bentNormal = normals;
  const AmbientKernel kernel(caster, opt);
  const std::vector<glm::vec3> origins = vertexRayOrigins(scene, normals, float(rep.rayEpsilon), &usable);
  // The shared estimator pools neighbours' rays; the cone's ratio estimator and sky lighting stay per vertex.
  const bool shared = opt.estimator == AOEstimator::Shared && opt.mode != AmbientMode::Sky && !opt.useCone;
  if (opt.estimator == AOEstimator::Shared && !shared)
    res.stats.note("the cone's ratio estimator is computed per vertex (not shared)");
  if (opt.estimator == AOEstimator::Strata && opt.useCone)
    res.stats.note("the cone's ratio estimator is computed per vertex (not in adaptive strata)");
  Timer traceTimer;
  SharedStats shareStats;
  // The progress bar's share of the two-sided vertices (two casts each).
  const double splitAt = 1.0 - 0.95 * double(2 * sides.vertex.size()) / double(nv + sides.vertex.size());
  if (shared) {
    // Pooling reads every vertex that casts rays in the whole run; this part casts its own.
    std::vector<uint8_t> poolable(nv, 0), mine(nv, 0);
    for (size_t i = 0; i < nv; ++i) {
      poolable[i] = status[i] == kTrace || status[i] == kOtherPart;
      mine[i] = status[i] == kTrace;
      if (status[i] == kOpen) {
        res.value[i] = 1.f;
        if (opt.bentNormals) res.bentNormal[i] = normals[i];
      }
    }
    shareStats = computeSharedAmbient(scene, caster, opt, normals, origins, poolable, mine, usable, res,
                                       progress.sub(0.05, splitAt));
    // Its rounds stop at the target or at max_rays.
    for (size_t i = 0; i < nv; ++i) capped[i] = res.rays[i] >= opt.maxRays;
  }
  parallelBlocks(shared ? 0 : nv, progress.sub(0.05, splitAt), "casting rays", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (status[i] == kOpen) {
        res.value[i] = 1.f;  // provably nothing within reach above the tangent plane
        if (opt.bentNormals) res.bentNormal[i] = normals[i];
        continue;
      }
      if (status[i] != kTrace) continue;
      const VertexOut o = kernel.run(uint32_t(part.meshIndex(i)), origins[i], normals[i]);  // keyed by the mesh's index
      res.value[i] = o.value;
      res.stdError[i] = o.stdError;
      res.rays[i] = o.rays;
      capped[i] = o.capped;
      if (opt.mode == AmbientMode::Sky) res.rgb[i] = o.rgb;
      if (opt.bentNormals) res.bentNormal[i] = o.bent;
    }
  });
  if (!sides.vertex.empty()) {
    std::vector<glm::vec3> sideNormal = normals;
    for (size_t k = 0; k < sides.vertex.size(); ++k) sideNormal[sides.vertex[k]] = sides.n[0][k];
    const float eps = float(rep.rayEpsilon);
    const std::vector<glm::vec3> sideOrigins = vertexRayOrigins(scene, sideNormal, eps, &usable);
    parallelBlocks(sides.vertex.size(), progress.sub(splitAt, 1.0), "casting rays (two-sided)", [&](size_t b, size_t e) {
      for (size_t k = b; k < e; ++k) {
        const uint32_t i = sides.vertex[k];
        if (!part.contains(i, nv)) continue;
        const glm::vec3 oA = sideOrigins[i], oB = oA + eps * (sides.n[1][k] - sides.n[0][k]);
        // Side B's rays keyed apart from every vertex's own (indices below nv).
        const uint32_t key = uint32_t(part.meshIndex(i));
        const VertexOut a = kernel.run(key, oA, sides.n[0][k]), c = kernel.run(uint32_t(nv) + key, oB, sides.n[1][k]);
        res.value[i] = 0.5f * (a.value + c.value);
        res.stdError[i] = 0.5f * std::sqrt(a.stdError * a.stdError + c.stdError * c.stdError);
        res.rays[i] = a.rays + c.rays;
        capped[i] = a.capped || c.capped;
        if (opt.mode == AmbientMode::Sky) res.rgb[i] = 0.5f * (a.rgb + c.rgb);
      }
    });
  }
  const double traceSeconds = traceTimer.seconds();
  for (size_t i = 0; i < nv; ++i) {
    if (status[i] == kDuplicate) {
      const uint32_t r = rep_of[i];
      res.value[i] = res.value[r]; res.stdError[i] = res.stdError[r];
      if (!res.rgb.empty()) res.rgb[i] = res.rgb[r];
      if (opt.bentNormals) res.bentNormal[i] = res.bentNormal[r];
    } else if (status[i] == kInvalid) {
      ++invalid;
      res.value[i] = 0.f;  // no hemisphere (isolated, NaN, or degenerate-only vertex)
    }
  }
  if (!part.all()) {  // counts over this part's vertices: the parts' counts add up to the whole's
    duplicates = open = invalid = 0;
    for (size_t i = 0; i < nv; ++i)
      if (part.contains(i, nv)) duplicates += status[i] == kDuplicate, open += status[i] == kOpen, invalid += status[i] == kInvalid;
  }
  // Summary (sequential: deterministic).
  double rays = 0, sum = 0, var = 0;
  size_t counted = 0;
  for (size_t i = 0; i < nv; ++i) {
    rays += res.rays[i];
    if (status[i] == kInvalid || !part.contains(i, nv)) continue;
    sum += res.value[i]; var += double(res.stdError[i]) * res.stdError[i]; ++counted;
  }
  auto& st = res.stats;
  st.add("vertices", double(nv));
  st.add("rays", rays);
  st.add("seconds", timer.seconds());
  const double castSeconds = shared ? shareStats.castSeconds : traceSeconds;
  st.add("rays_per_second", castSeconds > 0 ? rays / castSeconds : 0.0);
  st.add("mean", counted ? sum / double(counted) : 0.0);
  st.add("rms_error_estimate", counted ? std::sqrt(var / double(counted)) : 0.0);
  st.add("skipped_open", double(open));
  if (proofSeconds >= 0.0) st.add("open_proof_seconds", proofSeconds);
  if (!proofNote.empty()) st.note(proofNote);
  st.add("skipped_duplicates", double(duplicates));
  st.add("skipped_invalid", double(invalid));
  if (shared) {
    st.add("rays_per_vertex", nv ? rays / double(nv) : 0.0);
    st.add("shared_vertices_mean", shareStats.meanPooledVertices);
    st.add("shared_rings_mean", shareStats.meanRings);
    st.add("rounds", shareStats.rounds);
    st.add("pooling_seconds", shareStats.poolSeconds);
  }
  if (strata) {
    size_t traced = 0;
    for (size_t i = 0; i < nv; ++i) traced += res.rays[i] > 0;
    const double perTraced = traced ? rays / double(traced) : 0.0;
    st.add("rays_per_vertex", perTraced);  // per vertex that cast rays
    char buf[200];
    const StrataGrid first = firstStrataGrid(opt);
    if (opt.targetError > 0.0)
      std::snprintf(buf, sizeof buf, "adaptive strata to a standard error of %g: grids from %d x %d, quartered "
                    "each round, split where occlusion edges cross them: %.1f rays per vertex that cast rays",
                    opt.targetError, first.rows, first.cols, perTraced);
    else
      std::snprintf(buf, sizeof buf, "adaptive strata: %d x %d per vertex, split where occlusion edges cross them: "
                    "%.1f rays per vertex that cast rays", first.rows, first.cols, perTraced);
    st.note(buf);
  }
  if (open)
    st.note(std::to_string(open) + (opt.maxDistance > 0.0 ? " vertices provably open within max_distance"
                                                           : " vertices provably open (the whole scene below their "
                                                             "tangent plane)") + " got 1 without rays");
  if (duplicates) st.note(std::to_string(duplicates) + " duplicate vertices (same position and normal) computed once");
  size_t twoSided = 0;
  for (uint32_t v : sides.vertex) twoSided += part.contains(v, nv);
  if (twoSided)
    st.note(std::to_string(twoSided) + " vertices on a two-sided surface (each face with a reversed copy: no normal) "
            "took the mean of their two sides" + std::string(opt.bentNormals ? " (their bent normals stay 0)" : ""));
  if (invalid) st.note(std::to_string(invalid) + " vertices without a usable face, with NaN/Inf, or without a side to "
                          "cast from (a fold whose faces' normals cancel) got 0");
  if (rep.degenerateFaces + rep.invalidFaces + rep.facesOnNonFinite)
    st.note(std::to_string(rep.degenerateFaces + rep.invalidFaces + rep.facesOnNonFinite) + " degenerate/invalid faces ignored");
  warnMeaningless(scene, usable, opt, res, capped, st);
  return res;
}

}  // namespace gi
