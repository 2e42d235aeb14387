#include "gi/photon.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include <atomic>

#include <tbb/parallel_invoke.h>

#include "gi/color.h"
#include "gi/direct.h"
#include "gi/emitters.h"
#include "gi/sampling.h"
#include "gi/scene_setup.h"
#include "gi/specular.h"
#include "photon_map.h"
#include "photon_internal.h"
#include "photon_surface.h"

namespace gi {

std::vector<ParamSpec> PhotonOptions::specs() {
  std::vector<ParamSpec> out = {
      {"photons", "Photons emitted",
       "Number of photon paths shot from the lights (in proportion to their power); per pass when progressive. More "
       "photons: less noise and blur; memory grows linearly (about 50 bytes per stored photon with its kd-tree, 1-4 stored per path).",
       ParamType::Int, 200000, 1, 100000000},
      {"k_nearest", "Photons per estimate",
       "The indirect light at a vertex is estimated from its k nearest photons (global map) on the same side of the "
       "surface: their power over the area of that surface within their radius (a disk on a plane, half of it at a "
       "crease). More photons mean less noise (about 1 / sqrt(k)) but more blur; k = 1 or 2 gives an estimate "
       "without a finite mean or variance.",
       ParamType::Int, 64, 1, 512},
      {"caustic_k", "Photons per caustic estimate",
       "k for the caustic map (photons that reached a diffuse surface through mirrors or glass only). Its cone "
       "filter (Jensen 1996) keeps caustic edges sharp; smaller k: sharper and noisier (the relative noise is "
       "about 1 / sqrt(k)).",
       ParamType::Int, 128, 1, 512},
      {"caustic_projection", "Aim caustic photons at mirrors and glass",
       "Shoot the caustic photons only towards the mirror and glass objects (Jensen's projection maps: from each "
       "light point, directions in the cones their bounding spheres subtend), so that small specular objects get "
       "many caustic photons. Off: the caustic map keeps the global photons that happened to pass through them.",
       ParamType::Bool, 1},
      {"max_radius", "Maximum gather radius",
       "Photons farther than this from a vertex are ignored (0 = no limit); vertices with no photon within it get "
       "only their direct light. Keep it well above the photon spacing sqrt(diffuse area / stored photons): below "
       "it an estimate holds 0 or 1 photon and reads 0 or many times too bright (the log warns). Absolute or % of "
       "the bbox diagonal.",
       ParamType::Distance, 0.05, 0.0, 1.0},
      {"direct_light", "Direct light by light sampling",
       "Compute the direct light at each vertex by explicit light sampling (shadow rays to points on the emitters: "
       "soft shadows, no photon noise) and use the photons only for caustics and indirect light. Off: all light "
       "from the photon map (the classic noisy look).",
       ParamType::Bool, 1},
      {"light_samples", "Shadow rays per vertex", "Shadow rays for the direct light at each vertex.", ParamType::Int,
       256, 1, 1 << 20},
      {"final_gather", "Final gather",
       "For the indirect diffuse light, cast cosine-weighted rays from each vertex (through mirrors and glass) and "
       "read the global photon map where they land (Jensen's final gather): much smoother, at the cost of the "
       "rays. Caustics still come from the caustic map.",
       ParamType::Bool, 0},
      {"gather_rays", "Final-gather rays per vertex", "Rays per vertex for the final gather.", ParamType::Int, 64, 1,
       1 << 20},
      {"progressive", "Progressive photon mapping",
       "Shoot the photons in passes and keep, per vertex, a gather radius and the flux found in it; after each pass "
       "the radius shrinks so that a fraction alpha = 2/3 of the new photons is kept (Hachisuka, Ogaki and Jensen "
       "2008). Bias and noise both go to zero as passes grow, with memory for one pass only. Replaces the k-nearest "
       "estimates and the final gather.",
       ParamType::Bool, 0},
      {"passes", "Progressive passes", "Passes of 'Photons emitted' photons each (progressive mode).", ParamType::Int,
       16, 1, 100000},
      {"max_depth", "Maximum bounces",
       "Paths end after this many bounces, diffuse or specular (Russian roulette ends most much earlier; the power "
       "still carried by cut paths is logged).",
       ParamType::Int, 32, 1, 1000},
  };
  for (const ParamSpec& p : pointLightSpecs()) out.push_back(p);
  out.push_back(seedSpec("photon paths"));
  return out;
}

PhotonOptions PhotonOptions::fromParams(const ParamValues& v, const glm::dvec3& origin) {
  PhotonOptions o;
  o.photons = v.getInt("photons");
  o.kNearest = v.getInt("k_nearest");
  o.causticK = v.getInt("caustic_k");
  o.causticProjection = v.getBool("caustic_projection");
  o.maxRadius = v.getFloat("max_radius");
  o.maxDepth = v.getInt("max_depth");
  o.directLight = v.getBool("direct_light");
  o.lightSamples = v.getInt("light_samples");
  o.finalGather = v.getBool("final_gather");
  o.gatherRays = v.getInt("gather_rays");
  o.progressive = v.getBool("progressive");
  o.passes = v.getInt("passes");
  o.point = pointLightFromParams(v, origin);
  o.seed = uint32_t(v.getInt("seed"));
  return o;
}

namespace {

bool anySpecular(const Scene& s) {
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (isCausticSurface(s.faceMaterial(f))) return true;
  return false;
}

bool anyDiffuseReflection(const Scene& s) {
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (s.faceMaterial(f) == Material::Diffuse && luminance(s.faceRho(f)) > 0.f) return true;
  return false;
}

// Irradiance from the point or spot light at every vertex (one shadow ray each).
std::vector<glm::vec3> pointLightAtVertices(const Scene& s, const RayCaster& caster, const PointLight& L,
                                            const VertexMaterial& mat, const std::vector<glm::vec3>& origins) {
  std::vector<glm::vec3> H(s.vertexCount(), glm::vec3(0.f));
  if (!L.on()) return H;
  parallelBlocks(s.vertexCount(), Progress(nullptr), "", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i)
      if (mat.valid[i]) H[i] = pointLightIrradiance(L, caster, origins[i], mat.n[i]);
  });
  return H;
}

}  // namespace

VertexRadiometry computePhotonMap(const Scene& s, const RayCaster& caster, const PhotonOptions& optWorld,
                                  const Progress& progress) {
  PhotonOptions opt = optWorld;  // distances and the point light in local units (Scene::unit)
  opt.maxRadius = optWorld.maxRadius / s.unit;
  opt.point = pointLightInLocalUnits(optWorld.point, s);
  if (opt.photons < 1 || opt.kNearest < 1 || opt.kNearest > 512 || opt.causticK < 1 || opt.causticK > 512 || opt.passes < 1)
    throw std::invalid_argument("photons and passes must be >= 1, k_nearest and caustic_k in [1, 512]");
  Timer timer;
  VertexRadiometry out;
  RunStats& st = out.stats;
  const VertexMaterial mat = vertexMaterial(s);
  const size_t nv = s.vertexCount();
  const float eps = float(sceneScale(s).rayEpsilon);
  const std::vector<glm::vec3> origins = vertexRayOrigins(s, mat.n, eps);
  const bool specular = anySpecular(s);
  // What the scene needs: photons carry caustics (specular faces) and
  // diffuse interreflection (rho > 0); with the direct light apart and
  // neither, there is nothing for them to do.
  const bool needPhotons = !opt.directLight || specular || anyDiffuseReflection(s);
  const bool projection = opt.directLight && specular && opt.causticProjection;  // caustic photons aimed at mirrors and glass
  const float r2max = opt.maxRadius > 0 ? float(opt.maxRadius * opt.maxRadius) : HUGE_VALF;

  Timer directTimer;
  std::vector<glm::vec3> Hd(nv, glm::vec3(0.f));
  if (opt.directLight) {
    Hd = vertexDirectIrradiance(s, caster, opt.lightSamples, opt.seed, progress.sub(0.0, 0.15));
    const auto Hp = pointLightAtVertices(s, caster, opt.point, mat, origins);
    for (size_t i = 0; i < nv; ++i) Hd[i] += Hp[i];
  }
  const double directSeconds = directTimer.seconds();

  std::vector<glm::vec3> Hphot(nv, glm::vec3(0.f));
  std::vector<double> noise(nv, 0.0);
  PhotonTraceStats ts;
  size_t noPhotonVertices = 0;
  PhotonGatherCheck check;
  // Which photons the vertex estimate reads: all, or all but the direct ones.
  const unsigned vertexPaths = opt.directLight ? (1u << kCausticPhoton) | (1u << kIndirectPhoton) : 7u;
  if (!needPhotons) {
    st.note("no photons traced: the direct light is computed apart and nothing reflects it (rho = 0 everywhere, no "
            "mirror or glass)");
    // Still fail clearly without any light.
    if (EmitterSampler(s).empty() && !opt.point.on())
      throw std::invalid_argument("the scene has no light: no emitter faces and no point or spot light");
  } else if (opt.progressive) {
    ProgressiveResult pr = progressivePhotonMap(s, caster, opt, mat, vertexPaths, projection, progress.sub(0.15, 1.0), ts);
    Hphot = std::move(pr.H);
    noise = std::move(pr.noise);
    noPhotonVertices = pr.verticesWithoutPhotons;
    check = pr.check;
    st.add("ppm_passes", double(opt.passes));
    st.add("ppm_mean_final_radius", pr.meanRadius * s.unit);
    st.add("ppm_mean_photons_per_vertex", pr.meanCount);
    st.add("kdtree_build_seconds", pr.buildSeconds);
    st.add("query_seconds", pr.querySeconds);
    st.add("trace_seconds", pr.traceSeconds);
    st.add("photon_memory_mb", pr.peakBytes / 1048576.0);
    if (opt.finalGather) st.note("final gather not used: progressive photon mapping estimates all photon light");
  } else {
    Timer traceTimer;
    std::vector<Photon> photons = tracePhotons(s, caster, opt, 0, size_t(opt.photons), progress.sub(0.15, 0.45), ts);
    // Caustic photons (L S+ D) have their own map, shot by projection towards
    // the mirrors and glass, whenever the direct light is apart; otherwise
    // one map holds every photon.
    std::vector<Photon> causticPhotons;
    if (projection) causticPhotons = traceCausticPhotons(s, caster, opt, 0, size_t(opt.photons), progress.sub(0.45, 0.55), ts);
    const double traceSeconds = traceTimer.seconds();
    Timer buildTimer;
    const GatherSurface surface(s);
    const unsigned globalPaths = opt.directLight ? (1u << kIndirectPhoton) : 7u;
    // The (single-threaded) kd-tree builds run side by side.
    std::unique_ptr<PhotonMap> globalMap, caustics, all;
    const bool gather = opt.directLight && opt.finalGather;
    tbb::parallel_invoke(
        [&] {
          // The final gather reads `all` at the points its rays reach, never the global map at the vertices.
          if (!gather) globalMap = std::make_unique<PhotonMap>(photons, globalPaths, surface);
        },
        [&] {
          if (projection && !causticPhotons.empty())
            caustics = std::make_unique<PhotonMap>(causticPhotons, 1u << kCausticPhoton, surface);
          else if (opt.directLight && !projection && ts.caustic > 0)
            caustics = std::make_unique<PhotonMap>(photons, 1u << kCausticPhoton, surface);
        },
        [&] {
          if (gather) all = std::make_unique<PhotonMap>(photons, 7u, surface);
        });
    const double buildSeconds = buildTimer.seconds();
    size_t mapBytes = (photons.capacity() + causticPhotons.capacity()) * sizeof(Photon);
    if (globalMap) mapBytes += globalMap->memoryBytes();
    if (caustics) mapBytes += caustics->memoryBytes();
    if (all) mapBytes += all->memoryBytes();
    Timer queryTimer;
    std::vector<glm::vec3> gathered;
    // Photons per global (or final-gather) estimate: how many held some, how many only a few.
    std::atomic<size_t> some{0}, few{0};
    auto count = [&](int used) {
      if (used > 0) some.fetch_add(1, std::memory_order_relaxed);
      if (used > 0 && used < kFewPhotons) few.fetch_add(1, std::memory_order_relaxed);
    };
    if (all) {
      gathered = specularFinalGather(s, caster, mat, origins, opt.gatherRays, opt.seed ^ 0x6au, eps,
                                     [&](uint32_t f, const glm::vec3& y, const glm::vec3& side) {
                                       int used = 0;
                                       const glm::vec3 H = all->irradiance(y, side, opt.kNearest, r2max,
                                                                           PhotonKernel::Uniform, nullptr, &used);
                                       count(used);
                                       return s.faceRho(f) * H;
                                     });
    }
    parallelBlocks(nv, progress.sub(0.55, 1.0), "density estimation", [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        if (!mat.valid[i]) continue;
        double e1 = 0, e2 = 0;
        int used = 0;
        glm::vec3 H = all ? gathered[i]
                          : globalMap->irradiance(s.positions[i], mat.n[i], opt.kNearest, r2max, PhotonKernel::Uniform, &e1,
                                                  &used);
        if (!all) count(used);
        if (caustics) H += caustics->irradiance(s.positions[i], mat.n[i], opt.causticK, r2max, PhotonKernel::Cone, &e2);
        Hphot[i] = H;
        noise[i] = std::sqrt(e1 * e1 + e2 * e2);
      }
    });
    for (size_t i = 0; i < nv; ++i)
      if (mat.valid[i] && luminance(Hphot[i]) <= 0.f) ++noPhotonVertices;
    st.add("trace_seconds", traceSeconds);
    st.add("kdtree_build_seconds", buildSeconds);
    st.add("query_seconds", queryTimer.seconds());
    st.add("photons_per_second", traceSeconds > 0 ? opt.photons / traceSeconds : 0.0);
    size_t globalCount = 0;
    for (const Photon& p : photons) globalCount += (globalPaths >> p.path) & 1u;
    st.add("photons_global_map", double(globalCount));
    check.surfaceArea = surface.totalArea();
    check.mapPhotons = all ? all->size() : globalMap->size();
    check.causticPhotons = caustics ? caustics->size() : 0;
    check.estimates = some.load();
    check.fewEstimates = few.load();
    check.kNearestEstimates = true;
    st.add("photons_caustic_map", caustics ? double(caustics->size()) : 0.0);
    st.add("photon_memory_mb", mapBytes / 1048576.0);
    if (!specular) st.note("no caustic map: the scene has no mirror, glass or glossy faces");
    else if (!opt.directLight) st.note("caustic photons read with the others (one map: the direct light is not apart)");
    if (all) st.note("final gather of the photon map (" + std::to_string(opt.gatherRays) + " rays per vertex)");
  }
  out.B.assign(nv, glm::vec3(0.f));
  if (opt.directLight) out.Bdirect.assign(nv, glm::vec3(0.f));
  out.H.assign(nv, glm::vec3(0.f));
  out.stdError.assign(nv, 0.f);
  double lum = 0, err2 = 0;
  size_t valid = 0;
  for (size_t i = 0; i < nv; ++i) {
    if (!mat.valid[i]) continue;
    out.H[i] = Hd[i] + Hphot[i];
    out.B[i] = mat.E[i] + mat.rho[i] * out.H[i];
    if (opt.directLight) out.Bdirect[i] = mat.E[i] + mat.rho[i] * Hd[i];
    out.stdError[i] = float(luminance(mat.rho[i]) * noise[i]);
    lum += luminance(out.B[i]);
    err2 += double(out.stdError[i]) * out.stdError[i];
    ++valid;
  }
  if (needPhotons) {
    st.add("photons_emitted", double(ts.emitted));
    if (projection) {
      st.add("caustic_photons_aimed", double(ts.causticEmitted));
      st.add("caustic_photons_stored", double(ts.causticStored));
      st.note("caustic photons aimed at the mirrors, glass and glossy objects (projection): " +
              std::to_string(ts.causticEmitted - ts.causticMissed) + " of " + std::to_string(ts.causticEmitted) +
              " hit them first");
    }
    st.add("photons_stored", double(ts.stored));
    st.add("diffuse_bounces", double(ts.diffuseBounces));
    st.add("specular_bounces", double(ts.specularBounces));
    if (ts.glossyBounces) st.add("glossy_bounces", double(ts.glossyBounces));
    st.add("total_internal_reflections", double(ts.totalInternal));
    st.add("emitted_power_W", ts.emittedPower * s.unit * s.unit);
    if (ts.lostAtMaxDepth)
      st.note(std::to_string(ts.lostAtMaxDepth) + " paths cut at max_depth, carrying " +
              std::to_string(ts.emittedPower > 0 ? 100.0 * ts.lostPower / double(ts.passes) / ts.emittedPower : 0.0) +
              "% of the emitted power");
    check.lostPowerFraction = ts.emittedPower > 0 ? ts.lostPower / double(ts.passes) / ts.emittedPower : 0.0;
    warnMeaninglessPhotonParameters(opt, check, st);
    if (noPhotonVertices)
      st.note(std::to_string(noPhotonVertices) + " vertices reached by no photon within the gather radius: direct light only");
  }
  st.add("direct_light_seconds", directSeconds);
  st.add("seconds", timer.seconds());
  st.add("mean_luminance_B", valid ? lum / double(valid) : 0.0);
  st.add("photon_noise_estimate", valid ? std::sqrt(err2 / double(valid)) : 0.0);
  st.note(opt.directLight ? "direct light by explicit light sampling at the vertices; photons give caustics and indirect light"
                          : "all light from the photon map");
  const size_t specOnly = std::count(mat.valid.begin(), mat.valid.end(), uint8_t(0));
  if (specular && specOnly)
    st.note(std::to_string(specOnly) + " vertices on mirror, glass or glossy faces only (or unusable) have no diffuse "
            "radiosity: 0");
  return out;
}

}  // namespace gi
