// The per-vertex estimators of computeAmbient (ambient.cpp), one vertex at
// a time: the Sobol rays of the per-vertex estimator (to a fixed count, or
// to a target through a pilot left out, gi/sampling.h) and the adaptive
// strata (gi/ao_strata.h), with the sun's rays for sky lighting.
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>

#include "ambient_internal.h"
#include "gi/ambient.h"
#include "gi/ao_strata.h"
#include "gi/color.h"
#include "gi/raycaster.h"
#include "gi/sampling.h"
#include "gi/sky.h"

namespace gi::ambient_detail {

inline constexpr int kRound = 32;  // rays per adaptive round (a power of two keeps Sobol prefixes balanced)

// Whether the adaptive strata estimator runs (gi/ao_strata.h): occlusion only
// (obscurance is refused; the cone's ratio estimator and sky lighting stay
// per vertex).
inline bool strataRuns(const AmbientOptions& o) {
  return o.estimator == AOEstimator::Strata && o.mode == AmbientMode::Occlusion && !o.useCone;
}
// Its rounds to a target, and its grid: the fixed one, or the first round's.
inline StrataTarget strataTargetOf(const AmbientOptions& o) { return {o.targetError, o.minRays, o.maxRays}; }
inline StrataGrid firstStrataGrid(const AmbientOptions& o) {
  return StrataGrid::forRays(o.targetError > 0.0 ? o.minRays : o.raysPerVertex);
}

// The per-vertex estimator's count to a target (per-ray units) from its
// pilot (pilotRays rays, their standard error): rays whose error bar falls as
// 1/sqrt(n) (their variance per ray), or, where all the pilot's rays agreed,
// as the Laplace bound's 1/n; within [min_rays, what max_rays leaves]
// (capped: the prediction was cut there).
inline int perVertexCount(const AmbientOptions& o, double target, int pilotRays, double pilotStdError, bool agreed,
                          bool* capped = nullptr) {
  const double goal = target / std::sqrt(kPilotMargin);
  const double ratio = goal > 0.0 ? pilotStdError / goal : 0.0;
  const double want = std::ceil(agreed ? pilotRays * ratio : pilotRays * ratio * ratio);
  const int most = std::max(o.minRays, o.maxRays - pilotRays);
  if (capped) *capped = want > most;
  return int(std::clamp(want, double(o.minRays), double(most)));
}

// The rays a vertex whose every ray is open casts with the per-vertex
// estimator to a target (AmbientKernel::run): the pilot's rounds until the
// Laplace bound of n agreeing rays, sqrt(p (1 - p) / n) with p = (n + 1) /
// (n + 2), is within twice the target, then the count it predicts. The
// open-vertex proofs pay where this is large.
inline int perVertexRaysWhenOpen(const AmbientOptions& o) {
  auto laplace = [](int n) { return std::sqrt(laplaceVariance(n, n) / n); };
  const int pilotMax = std::max(o.minRays, o.maxRays / 4);
  int n = 0;
  while (n < pilotMax) {
    n += std::min(kRound, pilotMax - n);
    if (n >= o.minRays && laplace(n) <= kPilotLooseness * o.targetError) break;
  }
  return n + perVertexCount(o, o.targetError, n, laplace(n), true);
}

// A bent normal: the mean open direction, or the normal where none was open.
inline glm::vec3 bentOrNormal(const glm::vec3& sum, const glm::vec3& n) {
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

  // offset = org - the vertex's position (obscurance measures its distances from the vertex).
  VertexOut run(uint32_t vi, const glm::vec3& org, const glm::vec3& n, const glm::vec3& offset = glm::vec3(0.f)) const {
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
    if (!(o_.targetError > 0.0)) return finish(cast(hash3(vi, o_.seed, 0x41u), o_.raysPerVertex, 0.0, org, frame, offset), vi, n, org);
    // To a target: a pilot on numbers of its own, rounds of kRound rays to
    // kPilotLooseness times the target (at most min_rays or a quarter of
    // max_rays, whichever is more),
    // sizes the count (gi/sampling.h); the count's rays, the vertex's
    // fixed-count rays, are the result, and the pilot is left out of it.
    // Stopping on the kept rays biased the mean low where light comes
    // through a small opening: a room lit through a window, -0.19 target
    // units at a target of 0.005 (4 seeds).
    const int pilotMax = std::max(o_.minRays, o_.maxRays / 4);
    const VertexOut pilot = cast(hash3(vi, o_.seed, 0x4cu), pilotMax, kPilotLooseness * target_, org, frame, offset);
    bool capped = false;
    const int count = perVertexCount(o_, target_, pilot.rays, pilot.stdError, pilot.agreed, &capped);
    VertexOut out = cast(hash3(vi, o_.seed, 0x41u), count, 0.0, org, frame, offset);
    out.capped = capped;
    out.rays += pilot.rays;
    return finish(out, vi, n, org);
  }

 private:
  // Rays of the Sobol sequence keyed by seqKey, at most maxN, in rounds of
  // kRound; with stopAt > 0 it stops once min_rays are cast and the
  // standard error is at most stopAt (per-ray units).
  VertexOut cast(uint32_t seqKey, int maxN, double stopAt, const glm::vec3& org, const Frame& frame,
                 const glm::vec3& offset) const {
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
          f = obscuranceOf(hits[j], dirs[j], offset, o_.maxDistance, double(o_.falloffExponent));
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
      if (o_.mode == AmbientMode::Obscurance && w.n >= 1) {
        // Obscurance's rays take values in [0, 1]: one ray that met a wall
        // just inside max_distance (0.9986) beside 255 open ones gave a
        // sample variance a thousandth of the all-open vertex's Laplace
        // bound, and errors of 611 reported standard errors where a closer
        // hit was merely unseen (an outside audit). The variance is that of
        // the rays with two more, one fully hidden (0) and one open (1): the
        // Laplace bound where the rays agree, or nearly, and the sample
        // variance within O(1/n) elsewhere.
        const double n = w.n + 2.0, m = (w.sum + 1.0) / n;
        const double var = std::max(0.0, (w.sumSq + 1.0 - n * m * m) / (n - 1.0));
        return std::sqrt(var / w.n);
      }
      const double se = w.stdError();
      if (se > 0.0 || w.n < 1) return se;
      return std::sqrt(laplaceVariance(w.sum, w.n) / w.n);
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
      int lit = 0;
      for (int done = 0; done < o_.sunRays; done += kRound) {
        const int m = std::min(kRound, o_.sunRays - done);
        for (int j = 0; j < m; ++j) {
          rays[j].o = org; rays[j].d = sf.toWorld(uniformCone(seq.next(), sunCos_));
          rays[j].tnear = 0.f; rays[j].tfar = tfar_;  // max_distance: farther geometry does not occlude
        }
        caster_.occludedBatch(rays, size_t(m), occ);
        for (int j = 0; j < m; ++j) {
          lit += !occ[j];
          w.add(occ[j] ? 0.0 : std::max(0.f, glm::dot(n, rays[j].d)));
        }
      }
      sunRays = o_.sunRays;
      sun = o_.sunColor * float(o_.sunIrradiance * sunScale_ * w.mean());
      // Rays that all agree (all blocked, or all lit with nearly one cosine)
      // say little of a shadow's edge nearby: the Laplace bound of their
      // visibility, times the disk's cosine, stands in as for AO's rays (an
      // outside audit: 8 sun rays, all blocked, in a penumbra read 0.334
      // low with an error of 0.024) -- unless the sky's rays all escaped
      // (nothing above to cast a shadow; an open plane stays exact). A sharp
      // sun's rays are one ray: exact.
      double perRay = o_.sunAngularRadiusDeg > 0.f ? w.stdError() : 0.0;
      if (o_.sunAngularRadiusDeg > 0.f && w.n >= 1 && (lit == 0 || lit == w.n) && out.value < 1.f) {
        perRay = std::max(perRay, std::max(0.0, double(glm::dot(n, o_.sunDirection))) * std::sqrt(laplaceVariance(lit, w.n) / w.n));
      }
      sunErr = o_.sunIrradiance * sunScale_ * perRay * luminance(o_.sunColor);
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

}  // namespace gi::ambient_detail
