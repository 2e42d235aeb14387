#include "gi/ambient.h"

#include "ambient_internal.h"
#include "ambient_kernel.h"
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

using namespace ambient_detail;

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
  if (o.estimator == AOEstimator::Shared) {  // only the shared estimator reads them
    if (o.shareRings < 0 || o.shareRings > 64) throw std::invalid_argument("share_rings must lie in [0, 64]");
    if (!(o.shareNormalAngleDeg >= 0.f && o.shareNormalAngleDeg <= 180.f))
      throw std::invalid_argument("share_normal_angle must lie in [0, 180] degrees");
  }
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
    // Said in the mesh's own units (the options here are local: Scene::unit).
    const double u = scene.unit;
    if (o.maxDistance <= 10.0 * eps)
      st.warn("max_distance " + num(o.maxDistance * u) + " is within 10 ray offsets (rays start " + num(eps * u) +
              " off the surface): what it sees is where the rays start, not the shape");
    else if (o.maxDistance < 0.1 * median)
      st.warn("max_distance " + num(o.maxDistance * u) + " is below a tenth of the median edge length " + num(median * u) +
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
  // Too few rays for a usable value (said for occlusion only before: sky and
  // obscurance at 1 ray wrote 0 or 1 in silence; an outside audit).
  if (o.targetError == 0.0 && o.estimator == AOEstimator::PerVertex && o.raysPerVertex < 8) {
    const std::string n = std::to_string(o.raysPerVertex), se = num(0.5 / std::sqrt(double(o.raysPerVertex)));
    const std::string what =
        o.mode == AmbientMode::Occlusion
            ? "each vertex's value is one of " + std::to_string(o.raysPerVertex + 1) + " levels, its standard error up to " + se
        : o.mode == AmbientMode::Sky ? "each vertex's sky light rests on " + n + " rays, its standard error up to " + se +
                                           " of the sky's irradiance"
                                     : "each vertex's value rests on " + n + " rays, its standard error up to " + se;
    st.warn("rays_per_vertex = " + n + ": " + what + "; 16 rays or more give a usable estimate");
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
  checkCasterFor(scene, caster);
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
             : opt.targetError > 0.0 ? (opt.estimator == AOEstimator::Shared ? std::max(opt.minRays, kRound)
                                                                         : perVertexRaysWhenOpen(opt))
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
      const VertexOut o = kernel.run(uint32_t(part.meshIndex(i)), origins[i], normals[i], origins[i] - scene.positions[i]);  // keyed by the mesh's index
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
        const glm::vec3& p = scene.positions[i];
        const VertexOut a = kernel.run(key, oA, sides.n[0][k], oA - p), c = kernel.run(uint32_t(nv) + key, oB, sides.n[1][k], oB - p);
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
    st.note(std::to_string(twoSided) + " vertices on a two-sided surface or where faces turned opposite ways meet (their normals cancel) "
            "took the mean of their two sides" + std::string(opt.bentNormals ? " (their bent normals stay 0)" : ""));
  invalid -= copyOnlyAmong(scene, [&](size_t i) { return part.contains(i, nv) && status[i] == kInvalid; });
  if (invalid) st.note(std::to_string(invalid) + " vertices without a usable face, with NaN/Inf, or without a side to "
                          "cast from (a fold whose faces' normals cancel) got 0");
  if (rep.degenerateFaces + rep.invalidFaces + rep.facesOnNonFinite)
    st.note(std::to_string(rep.degenerateFaces + rep.invalidFaces + rep.facesOnNonFinite) + " degenerate/invalid faces ignored");
  warnMeaningless(scene, usable, opt, res, capped, st);
  return res;
}

}  // namespace gi
