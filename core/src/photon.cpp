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
      {.name = "photons", .label = "Photons emitted",
       .help = "Number of photon paths shot from the lights (in proportion to their power); per pass when "
               "progressive. More photons: less noise and blur; memory grows linearly (about 56 bytes per stored "
               "photon with its kd-tree, 1-4 stored per path). A run whose photons would not fit in the memory "
               "available is refused once they pass it, before the machine runs out.",
       .type = ParamType::Int, .def = 200000, .min = 1, .max = 100000000},
      {.name = "k_nearest", .label = "Photons per estimate",
       .help = "The indirect light at a vertex is estimated from its k nearest photons (global map) on the same side "
               "of the surface: their power over the area of that surface within their radius (a disk on a plane, "
               "half of it at a crease). Where a face turning more than 20 degrees from the vertex normal (an edge "
               "between walls) or another object (a block standing on the floor, a lamp just below the ceiling) "
               "lies inside that radius, the photons tell another quantity than the vertex's value (the sphere "
               "counts what the vertex does not see): with the direct light computed apart, such a vertex takes a "
               "final gather of the photon map instead (gather_rays). More photons mean less noise (about "
               "1 / sqrt(k)) but more blur; k = 1 or 2 gives an estimate without a finite mean or variance.",
       .type = ParamType::Int, .def = 64, .min = 1, .max = 512},
      {.name = "caustic_k", .label = "Photons per caustic estimate",
       .help = "k for the caustic map (photons that reached a diffuse surface through mirrors or glass only). Its "
               "cone filter (Jensen 1996) keeps caustic edges sharp; smaller k: sharper and noisier (the relative "
               "noise is about 1 / sqrt(k)).",
       .type = ParamType::Int, .def = 128, .min = 1, .max = 512},
      {.name = "caustic_projection", .label = "Aim caustic photons at mirrors and glass",
       .help = "Shoot the caustic photons only towards the mirror and glass objects (Jensen's projection maps: from "
               "each light point, directions in the cones their bounding spheres subtend), so that small specular "
               "objects get many caustic photons. Off: the caustic map keeps the global photons that happened to "
               "pass through them.",
       .type = ParamType::Bool, .def = true},
      {.name = "max_radius", .label = "Maximum gather radius",
       .help = "Photons farther than this from a vertex are ignored (0 = no limit); vertices with no photon within "
               "it get only their direct light. Keep it well above the photon spacing sqrt(diffuse area / stored "
               "photons): below it an estimate holds 0 or 1 photon and reads 0 or many times too bright (the log "
               "warns). Absolute or % of the bbox diagonal.",
       .type = ParamType::Distance, .def = 0.05, .min = 0.0, .max = 1.0},
      {.name = "direct_light", .label = "Direct light by light sampling",
       .help = "Compute the direct light at each vertex by explicit light sampling (shadow rays to points on the "
               "emitters: soft shadows, no photon noise) and use the photons only for caustics and indirect light. "
               "Off: all light from the photon map (the classic noisy look).",
       .type = ParamType::Bool, .def = true},
      {.name = "light_samples", .label = "Shadow rays per vertex",
       .help = "Shadow rays for the direct light at each vertex. With up to 256 luminaires (coplanar, "
               "edge-connected emitter faces of one emission), the exact form factor to each times its visible "
               "fraction from 16 stratified rays (and its corners), up to this many in penumbra; with more, this "
               "many light points sampled in proportion to power.",
       .type = ParamType::Int, .def = 256, .min = 1, .max = 1 << 20},
      {.name = "final_gather", .label = "Final gather",
       .help = "For the indirect diffuse light, cast cosine-weighted rays from each vertex (through mirrors and "
               "glass) and read the global photon map where they land (Jensen's final gather): much smoother, at the "
               "cost of the rays. Caustics still come from the caustic map. Rays that leave the scene add nothing: "
               "the sky and the sun seen from the vertex are direct light (computed apart), seen through mirrors "
               "and glass they are caustics (carried by photons). Needs 'Direct light by light sampling' on; progressive mode "
               "uses it only where it hands over.",
       .type = ParamType::Bool, .def = false},
      {.name = "gather_rays", .label = "Final-gather rays per vertex",
       .help = "Rays per vertex for the final gather.",
       .type = ParamType::Int, .def = 64, .min = 1, .max = 1 << 20},
      {.name = "progressive", .label = "Progressive photon mapping",
       .help = "Shoot the photons in passes and keep, per vertex, a gather radius and the flux found in it; after "
               "each pass the radius shrinks so that a fraction alpha = 2/3 of the new photons is kept (Hachisuka, "
               "Ogaki and Jensen 2008). Bias and noise both go to zero as passes grow, with memory for one pass "
               "only. Replaces the k-nearest estimates and the final gather, but where a density estimate tells "
               "another quantity (at a crease, beside another surface: see k_nearest): with the direct light "
               "apart, those vertices take a final gather of the first passes' photons (200,000 paths).",
       .type = ParamType::Bool, .def = false},
      {.name = "passes", .label = "Progressive passes",
       .help = "Passes of 'Photons emitted' photons each (progressive mode).",
       .type = ParamType::Int, .def = 16, .min = 1, .max = 100000,
       .usedWhen = {{"progressive", {1}}}},
      {.name = "max_depth", .label = "Maximum bounces",
       .help = "Bounces a path may take, diffuse or specular, counted as the reference counts them: 0 = direct "
               "light only, k = light that reflected at most k times before the vertex (with the final gather, and "
               "at the vertices the other modes hand over to one (creases, another surface near), its rays are the "
               "last reflection; where they pass mirrors or glass on their way, those are not counted). "
               "Russian roulette ends most paths much earlier; the power still carried by cut paths is logged.",
       .type = ParamType::Int, .def = 32, .min = 0, .max = 1000},
  };
  for (const ParamSpec& p : SkySun::specs()) out.push_back(p);
  for (const ParamSpec& p : pointLightSpecs()) out.push_back(p);
  out.push_back(lightPathSplitSpec());
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
  o.outside = SkySun::fromParams(v);
  o.point = pointLightFromParams(v, origin);
  o.lightPathSplit = v.getBool("light_path_split");
  o.seed = uint32_t(v.getInt("seed"));
  return o;
}

namespace {

bool anyDiffuseReflection(const Scene& s) {
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (s.faceMaterial(f) == Material::Diffuse && luminance(s.faceRho(f)) > 0.f) return true;
  return false;
}

// Irradiance from the point or spot light at every vertex (one shadow ray each).
std::vector<glm::vec3> pointLightAtVertices(const Scene& s, const RayCaster& caster, const PointLight& L,
                                            const VertexMaterial& mat, const std::vector<glm::vec3>& origins, float eps) {
  std::vector<glm::vec3> H(s.vertexCount(), glm::vec3(0.f));
  if (!L.on()) return H;
  parallelBlocks(s.vertexCount(), Progress(nullptr), "", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i)
      if (mat.valid[i]) H[i] = pointLightIrradiance(L, caster, vertexLightPoint(origins[i], mat.n[i], eps), origins[i], mat.n[i]);
  });
  return H;
}

// Direct light by light sampling at every vertex (area emitters, the point
// or spot light, the sky and the sun), or none when the photons carry it.
// The sky through the mesh's openings (a window) is sampled through them as
// luminaires, as radiosity does (gi/sky.h).
// `stdError`: the sampled direct light's standard error per vertex (with
// more luminaires than light sampling takes one by one: its 1,600 squares
// read 9% off in RMS, up to 44%, with an error bar of 0; an outside audit).
std::vector<glm::vec3> directAtVertices(const PhotonRun& r, const Progress& progress, std::vector<float>& stdError) {
  std::vector<glm::vec3> Hd(r.s.vertexCount(), glm::vec3(0.f));
  stdError.assign(r.s.vertexCount(), 0.f);
  if (!r.opt.directLight) return Hd;
  Hd = vertexDirectIrradiance(r.s, r.caster, r.opt.lightSamples, r.opt.seed, progress, VertexPart(), nullptr, &stdError);
  const auto Hp = pointLightAtVertices(r.s, r.caster, r.opt.point, r.mat, r.origins, r.eps);
  const auto Ho = vertexSkySunIrradiance(r.s, r.caster, r.opt.outside, r.opt.lightSamples, r.opt.seed, VertexPart(),
                                         Progress(nullptr), &r.openings);
  for (size_t i = 0; i < Hd.size(); ++i) Hd[i] += Hp[i] + Ho[i];
  return Hd;
}

// The log's account of the vertices handed over to the final gather (none: nothing).
void reportHandOver(const PhotonOptions& opt, const HandOver& ho, const std::string& map, RunStats& st) {
  if (ho.crease + ho.otherSurface == 0) return;
  st.add("vertices_gathered_at_creases", double(ho.crease));
  st.add("vertices_gathered_beside_other_surfaces", double(ho.otherSurface));
  st.add("gather_near_hits_relit", double(ho.nearHits));
  st.note(std::to_string(ho.crease + ho.otherSurface) + " vertices gather " + map + " (" +
          std::to_string(opt.gatherRays) + " rays each) where a density estimate tells another quantity: " +
          std::to_string(ho.crease) + " at creases (it reads the faces on both sides), " +
          std::to_string(ho.otherSurface) +
          " where another surface rises inside its radius (an object standing on the surface, a lamp "
          "just below a ceiling, a wall: the sphere counts what the vertex does not see)");
}

PhotonEstimate progressiveEstimate(const PhotonRun& r, const Progress& progress, PhotonTraceStats& ts, RunStats& st) {
  ProgressiveResult pr = progressivePhotonMap(r, progress.sub(0.15, 1.0), ts);
  st.add("ppm_passes", double(r.opt.passes));
  st.add("ppm_mean_final_radius", pr.meanRadius * r.s.unit);
  st.add("ppm_mean_photons_per_vertex", pr.meanCount);
  st.add("kdtree_build_seconds", pr.buildSeconds);
  st.add("query_seconds", pr.querySeconds);
  st.add("trace_seconds", pr.traceSeconds);
  st.add("photon_memory_mb", pr.peakBytes / 1048576.0);
  if (r.opt.finalGather)
    st.note("final gather not used: progressive photon mapping estimates the photon light (but where it hands over)");
  if (pr.ho.gatherSeconds > 0) st.add("final_gather_seconds", pr.ho.gatherSeconds);
  if (pr.gatherPasses > 0)
    reportHandOver(r.opt, pr.ho,
                   pr.gatherStride > 1
                       ? "a map of every " + std::to_string(pr.gatherStride) + "th photon of the first pass"
                       : "a map of the first " + std::to_string(pr.gatherPasses) + " pass(es)' photons",
                   st);
  PhotonEstimate e{std::move(pr.H), std::move(pr.noise), pr.verticesWithoutPhotons, pr.check};
  for (int k = 0; k < kPathKinds; ++k) e.byPath[k] = std::move(pr.byPath[k]);
  return e;
}

PhotonMaps buildMaps(const PhotonRun& r, const std::vector<Photon>& photons, const std::vector<Photon>& causticPhotons,
                     const GatherSurface& surface, const PhotonTraceStats& ts, const std::vector<uint8_t>& hitsLeft) {
  PhotonMaps m;
  m.globalPaths = r.opt.directLight ? (1u << kIndirectPhoton) : 7u;
  const bool gather = r.opt.directLight && r.opt.finalGather;
  // Caustic photons (L S+ D) have their own map, shot by projection towards
  // the mirrors and glass, whenever the direct light is apart; otherwise one
  // map holds every photon. The (single-threaded) builds run side by side.
  tbb::parallel_invoke(
      [&] {
        // The final gather reads `all` at the points its rays reach, never the global map at the vertices.
        if (!gather) m.global = std::make_unique<PhotonMap>(photons, m.globalPaths, surface);
      },
      [&] {
        if (r.projection && !causticPhotons.empty())
          m.caustics = std::make_unique<PhotonMap>(causticPhotons, 1u << kCausticPhoton, surface);
        else if (r.opt.directLight && !r.projection && ts.caustic > 0)
          m.caustics = std::make_unique<PhotonMap>(photons, 1u << kCausticPhoton, surface);
      },
      [&] {
        if (gather) m.all = gatherMap(photons, surface, hitsLeft);
      });
  m.bytes = (photons.capacity() + causticPhotons.capacity()) * sizeof(Photon);
  for (const auto* map : {m.global.get(), m.caustics.get(), m.all.get()})
    if (map) m.bytes += map->memoryBytes();
  return m;
}

// Photon mapping proper (Jensen 1996): trace, build the maps, estimate at
// the vertices.
PhotonEstimate kNearestEstimate(const PhotonRun& r, const Progress& progress, PhotonTraceStats& ts, RunStats& st,
                                PhotonMapContents* contents) {
  const PhotonOptions& opt = r.opt;
  Timer traceTimer;
  const bool gather = opt.directLight && opt.finalGather;
  // It was dropped without a word (an outside audit): said, as progressive
  // mode says it.
  if (opt.finalGather && !opt.directLight)
    st.note("final gather not used: without the direct light computed apart, every photon is read at the vertices "
            "(the gather's rays would have to find the lights too)");
  // Crease vertices gather (the direct light apart; all light from photons
  // would need the gather to see the lights too).
  std::vector<uint8_t> crease;
  if (opt.directLight && !gather) crease = creaseVertices(r.s, r.mat);
  // The hits each photon's path had left: a final gather, here or at the
  // vertices handed over to it, leaves out those with none.
  std::vector<uint8_t> hitsLeft;
  std::vector<Photon> photons = tracePhotons(r.s, r.caster, opt, 0, size_t(opt.photons), progress.sub(0.15, 0.45), ts,
                                             opt.directLight ? &hitsLeft : nullptr);
  std::vector<Photon> causticPhotons;
  if (r.projection)
    causticPhotons = traceCausticPhotons(r.s, r.caster, whileHolding(opt, photons.size()), 0, size_t(opt.photons),
                                         progress.sub(0.45, 0.55), ts);
  const double traceSeconds = traceTimer.seconds();
  Timer buildTimer;
  const GatherSurface surface(r.s);
  PhotonMaps maps = buildMaps(r, photons, causticPhotons, surface, ts, hitsLeft);
  const double buildSeconds = buildTimer.seconds();
  if (contents) {
    // The same membership as the trees': `all` (final gather) or the global
    // paths, and the caustic map from the projection or the global trace.
    const bool all = bool(maps.all);
    const unsigned globalMask = all ? 7u : maps.global ? maps.globalPaths : 0u;
    for (size_t i = 0; i < photons.size(); ++i)
      if (((globalMask >> photons[i].path) & 1u) && !(all && hitsLeft[i] == 0)) contents->global.push_back(photons[i]);
    if (maps.caustics) {
      for (const Photon& p : r.projection && !causticPhotons.empty() ? causticPhotons : photons)
        if (p.path == kCausticPhoton) contents->caustic.push_back(p);
    }
  }
  // What the paths carried past their last allowed hit is lost, in every
  // mode. The final gather's map leaves that hit's photons out, but its rays
  // are the reflection there: a photon left out at y stands for light that
  // would reach the vertex after reflecting at y, rho times its power, the
  // power the path carried on (an outside audit: counting the photon's own
  // power said rho^k instead of rho^(k+1) lost, 100% at max_depth 0, where
  // the result equals the reference's).
  ts.lostPower += ts.lastHitCutPower, ts.lostRGB += ts.lastHitCutRGB;
  Timer queryTimer;
  HandOver ho;
  PhotonEstimate e = estimateAtVertices(r, maps, photons, surface, hitsLeft, crease, ho, progress.sub(0.55, 1.0));
  st.add("trace_seconds", traceSeconds);
  st.add("kdtree_build_seconds", buildSeconds + ho.buildSeconds);
  st.add("query_seconds", queryTimer.seconds() - ho.buildSeconds);
  if (ho.gatherSeconds > 0) st.add("final_gather_seconds", ho.gatherSeconds);
  st.add("photons_per_second", traceSeconds > 0 ? opt.photons / traceSeconds : 0.0);
  size_t globalCount = 0;
  for (const Photon& p : photons) globalCount += (maps.globalPaths >> p.path) & 1u;
  st.add("photons_global_map", double(globalCount));
  e.check.surfaceArea = surface.totalArea();
  e.check.mapPhotons = maps.global ? maps.global->size() : maps.all->size();
  for (size_t f = 0; f < r.s.faceCount() && !e.check.reflects; ++f)
    e.check.reflects = r.s.faceMaterial(f) == Material::Diffuse && luminance(r.s.faceRho(f)) > 0.f;
  e.check.causticPhotons = maps.caustics ? maps.caustics->size() : 0;
  e.check.kNearestEstimates = true;
  st.add("photons_caustic_map", maps.caustics ? double(maps.caustics->size()) : 0.0);
  st.add("photon_memory_mb", maps.bytes / 1048576.0);
  if (!r.specular) st.note("no caustic map: the scene has no mirror, glass or glossy faces");
  else if (!opt.directLight) st.note("caustic photons read with the others (one map: the direct light is not apart)");
  if (gather) {
    st.note("final gather of the photon map (" + std::to_string(opt.gatherRays) + " rays per vertex)");
    st.add("gather_near_hits_relit", double(ho.nearHits));
  } else {
    reportHandOver(opt, ho,
                   maps.thinnedStride > 1 ? "a map of every " + std::to_string(maps.thinnedStride) + "th photon"
                                          : std::string("the photon map"),
                   st);
  }
  return e;
}

// The photons' statistics and the warnings for meaningless parameters.
void photonStats(const PhotonRun& r, const PhotonTraceStats& ts, PhotonEstimate& e, RunStats& st) {
  st.add("photons_emitted", double(ts.emitted));
  if (r.projection) {
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
  st.add("emitted_power_W", ts.emittedPower * r.s.unit * r.s.unit);
  if (ts.pointOnSurface)
    st.note("the point light lies on a surface (within the ray epsilon): its light towards the surface's back is "
            "absorbed there, the rest leaves from past it");
  if (ts.lostAtMaxDepth)
    st.note(std::to_string(ts.lostAtMaxDepth) + " paths cut at max_depth, carrying " +
            std::to_string(ts.emittedPower > 0 ? 100.0 * ts.lostPower / double(ts.passes) / ts.emittedPower : 0.0) +
            "% of the emitted power");
  e.check.lostPowerFraction = ts.emittedPower > 0 ? ts.lostPower / double(ts.passes) / ts.emittedPower : 0.0;
  st.add("lost_power_fraction", e.check.lostPowerFraction);
  for (int c = 0; c < 3; ++c)
    if (ts.emittedRGB[c] > 0 && ts.lostRGB[c] / ts.emittedRGB[c] > e.check.lostChannelShare)
      e.check.lostChannelShare = ts.lostRGB[c] / ts.emittedRGB[c], e.check.lostChannel = c;
  warnMeaninglessPhotonParameters(r.opt, e.check, r.s.unit, st);
  if (e.verticesWithoutPhotons)
    st.note(std::to_string(e.verticesWithoutPhotons) + " vertices reached by no photon within the gather radius: " +
            (r.opt.directLight ? "direct light only" : "0 (all their light would come from photons)"));
}

// B = E + rho (H_direct + H_photons) at the vertices, with the photons'
// noise carried to B, and (direct light apart) Bdirect = E + rho H_direct,
// which the two-pass view reads; the mean luminance and the rms noise for the log.
struct Totals {
  double meanLuminance = 0, rmsNoise = 0;
};
// Over the vertices `counted` marks.
Totals totalsOver(const std::vector<glm::vec3>& B, const std::vector<float>& stdError,
                  const std::vector<uint8_t>& counted) {
  double lum = 0, err2 = 0;
  size_t n = 0;
  for (size_t i = 0; i < counted.size(); ++i) {
    if (!counted[i]) continue;
    lum += luminance(B[i]);
    err2 += double(stdError[i]) * stdError[i];
    ++n;
  }
  return {n ? lum / double(n) : 0.0, n ? std::sqrt(err2 / double(n)) : 0.0};
}
Totals combine(const VertexMaterial& mat, const std::vector<glm::vec3>& Hd, const std::vector<float>& HdError,
               const PhotonEstimate& e, bool directApart, VertexRadiometry& out) {
  const size_t nv = Hd.size();
  out.B.assign(nv, glm::vec3(0.f));
  if (directApart) out.Bdirect.assign(nv, glm::vec3(0.f));
  out.H.assign(nv, glm::vec3(0.f));
  out.stdError.assign(nv, 0.f);
  for (size_t i = 0; i < nv; ++i) {
    if (!mat.valid[i]) continue;
    out.H[i] = Hd[i] + e.H[i];
    out.B[i] = mat.E[i] + mat.rho[i] * out.H[i];
    if (directApart) out.Bdirect[i] = mat.E[i] + mat.rho[i] * Hd[i];
    if (!out.split.empty()) {
      // rho H_k per kind; they sum to B - E within float rounding.
      auto part = [&](int k) { return e.byPath[k].empty() ? glm::vec3(0.f) : e.byPath[k][i]; };
      out.split.emitted[i] = mat.E[i];
      out.split.direct[i] = mat.rho[i] * (Hd[i] + part(kPathDirect));
      out.split.caustic[i] = mat.rho[i] * part(kPathCaustic);
      out.split.indirect[i] = mat.rho[i] * part(kPathIndirect);
    }
    const double hd = i < HdError.size() ? double(HdError[i]) : 0.0;
    out.stdError[i] = float(std::sqrt(double(e.noise[i]) * e.noise[i] + hd * hd));  // both of rho H's luminance
  }
  return totalsOver(out.B, out.stdError, mat.valid);
}


// The photon map at every vertex with a normal (computePhotonMap splits the
// two-sided ones first).
VertexRadiometry photonMapAtVertices(const Scene& s, const RayCaster& caster, const PhotonOptions& optWorld,
                                     const Progress& progress, PhotonMapContents* maps) {
  PhotonOptions opt = optWorld;  // distances and the point light in local units (Scene::unit)
  opt.maxRadius = optWorld.maxRadius / s.unit;
  opt.point = pointLightInLocalUnits(optWorld.point, s);
  opt.point.check();
  if (opt.photons < 1 || opt.kNearest < 1 || opt.kNearest > 512 || opt.causticK < 1 || opt.causticK > 512 ||
      (opt.progressive && opt.passes < 1))
    throw std::invalid_argument("photons and passes must be >= 1, k_nearest and caustic_k in [1, 512]");
  requireInRange(PhotonOptions::specs(), "gather_rays", opt.gatherRays);  // 0 gave NaN at every gathered vertex
  opt.outside.check();
  Timer timer;
  VertexRadiometry out;
  RunStats& st = out.stats;
  const VertexMaterial mat = vertexMaterial(s);
  const size_t nv = s.vertexCount();
  const float eps = float(sceneScale(s).rayEpsilon);
  const std::vector<glm::vec3> origins = vertexRayOrigins(s, mat.n, eps);
  const bool specular = anyFaceMaterial(s, isCausticSurface);
  // What the scene needs: photons carry caustics (specular faces) and
  // diffuse interreflection (rho > 0); with the direct light apart and
  // neither, there is nothing for them to do.
  const bool needPhotons = !opt.directLight || specular || anyDiffuseReflection(s);
  // Caustic photons aimed at mirrors and glass. Not with a sky or a sun: the
  // global photons then carry every caustic (the projection aims from points
  // on the lights, which the sky and the sun have not).
  const bool projection = opt.directLight && specular && opt.causticProjection && !opt.outside.any();
  // Which photons the vertex estimate reads: all, or all but the direct ones.
  const unsigned vertexPaths = opt.directLight ? (1u << kCausticPhoton) | (1u << kIndirectPhoton) : 7u;
  const float r2max = opt.maxRadius > 0 ? float(opt.maxRadius * opt.maxRadius) : HUGE_VALF;
  // The sky's openings: its direct light through their portals, and where
  // they are the only way in, the sky's and the sun's photons aimed at them.
  const SkyOpenings openings = findSkyOpenings(s, caster, opt.outside, opt.seed);
  openings.report(st);
  const bool aimed = aimAtOpenings(openings, s, opt);
  const PhotonRun run{s, caster, opt, mat, origins, eps, specular, projection, vertexPaths, r2max, openings};

  Timer directTimer;
  std::vector<float> HdError;
  const std::vector<glm::vec3> Hd = directAtVertices(run, progress.sub(0.0, 0.15), HdError);
  const double directSeconds = directTimer.seconds();
  PhotonTraceStats ts;
  PhotonEstimate photons;
  if (!needPhotons) {
    st.note("no photons traced: the direct light is computed apart and nothing reflects it (rho = 0 everywhere, no "
            "mirror or glass)");
    // Still fail clearly without any light.
    if (EmitterSampler(s).empty() && !opt.point.on() && !opt.outside.any())
      throw std::invalid_argument("the scene has no light: no emitter faces, no point or spot light, no sky and no sun");
    photons.H.assign(nv, glm::vec3(0.f));
    photons.noise.assign(nv, 0.0);
  } else if (opt.progressive) {
    photons = progressiveEstimate(run, progress, ts, st);
  } else {
    photons = kNearestEstimate(run, progress, ts, st, maps);
  }
  if (opt.lightPathSplit) out.split.assign(nv);
  const Totals totals = combine(mat, Hd, HdError, photons, opt.directLight, out);
  if (needPhotons) photonStats(run, ts, photons, st);
  st.add("direct_light_seconds", directSeconds);
  st.add("seconds", timer.seconds());
  st.add("mean_luminance_B", totals.meanLuminance);
  st.add("photon_noise_estimate", totals.rmsNoise);
  st.note(opt.directLight ? "direct light by explicit light sampling at the vertices; photons give caustics and indirect light"
                          : "all light from the photon map");
  if (opt.outside.any() && specular && opt.causticProjection && opt.directLight)
    st.note("caustic_projection not used: with a sky or a sun the global photons carry every caustic");
  if (opt.outside.any() && !aimed) st.note("sky and sun photons enter from a disk covering the scene's bounding sphere");
  if (aimed) {
    st.add("outside_photon_aim_radius", opt.outsideAimRadius * s.unit);
    st.note("sky and sun photons aimed at the sky openings (the only way in): from a disk of their sphere's radius");
  }
  const size_t specOnly = std::count(mat.valid.begin(), mat.valid.end(), uint8_t(0));
  if (specOnly)
    st.note(std::to_string(specOnly) + " vertices on mirror, glass or glossy faces only, unusable, or without a normal "
            "have no diffuse radiosity: 0");
  return out;
}

}  // namespace

// gi/photon.h; the openings as findSkyOpenings found them (no cosine rays kept: gi/sky.h).
bool aimAtOpenings(const SkyOpenings& openings, const Scene& s, PhotonOptions& opt) {
  if (!opt.outside.any() || !openings.any() || openings.rest) return false;
  glm::dvec3 lo(HUGE_VAL), hi(-HUGE_VAL);
  for (const SkyPortal& p : openings.portals)
    for (const glm::dvec3& c : p.corners) lo = glm::min(lo, c), hi = glm::max(hi, c);
  const glm::dvec3 centre = 0.5 * (lo + hi);
  double r = 0;
  for (const SkyPortal& p : openings.portals)
    for (const glm::dvec3& c : p.corners) r = std::max(r, glm::length(c - centre));
  opt.outsideAimCentre = glm::vec3(centre);
  opt.outsideAimRadius = float(r * 1.001 + sceneScale(s).rayEpsilon);
  return true;
}

VertexRadiometry computePhotonMap(const Scene& s, const RayCaster& caster, const PhotonOptions& opt,
                                  const Progress& progress, PhotonMapContents* maps) {
  checkCasterFor(s, caster);
  // A vertex of a two-sided surface (each face with a reversed copy) has no
  // normal: it is split into its two sides, each estimated as a vertex of
  // its own (the same place, the side's normal, reflectance and emission;
  // the same faces, so the caster still fits), and takes their mean, as the
  // reference and ambient occlusion do there.
  const VertexMaterial mat = vertexMaterial(s);
  const VertexSides sides = twoSidedVertices(s, mat);
  const Scene split = sides.vertex.empty() ? Scene() : splitSides(s, sides);
  VertexRadiometry out = photonMapAtVertices(sides.vertex.empty() ? s : split, caster, opt, progress, maps);
  if (const auto w = emitterOrientationWarning(s, caster, opt.point.on() || opt.outside.any())) out.stats.warn(*w);
  if (sides.vertex.empty()) return out;
  for (auto* v : {&out.B, &out.Bdirect, &out.H, &out.split.emitted, &out.split.direct, &out.split.caustic,
                  &out.split.indirect})
    mergeSides(*v, sides);
  mergeSideErrors(out.stdError, sides);
  // The run's means over the scene's vertices (the split scene counted each side).
  std::vector<uint8_t> counted = mat.valid;
  for (uint32_t v : sides.vertex) counted[v] = 1;
  const Totals totals = totalsOver(out.B, out.stdError, counted);
  out.stats.set("mean_luminance_B", totals.meanLuminance);
  out.stats.set("photon_noise_estimate", totals.rmsNoise);
  out.stats.note(std::to_string(sides.vertex.size()) + " vertices on a two-sided surface or where faces turned opposite ways meet (their faces' normals cancel) "
                 "took the mean of their two sides (the counts of estimates above count each side)");
  return out;
}

}  // namespace gi
