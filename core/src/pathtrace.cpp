#include "gi/pathtrace.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "gi/color.h"
#include "gi/direct.h"
#include "gi/emitters.h"
#include "gi/sampling.h"
#include "gi/scene_setup.h"
#include "gi/sky.h"
#include "gi/specular.h"
#include "gi/vertex_graph.h"
#include "path_error_bars.h"
#include "path_integrator.h"

namespace gi {

std::vector<ParamSpec> PathTraceOptions::specs() {
  std::vector<ParamSpec> out = {
      {.name = "samples_per_vertex", .label = "Paths per vertex",
       .help = "Paths traced from each vertex when no target error is set. The error falls as 1/sqrt(N) (independent "
               "random numbers: the reported standard error is an honest error bar; it takes the larger of the "
               "vertex's own variance and its mesh ring's, so that light only rare paths find, a caustic or a light "
               "seen in a mirror, is covered where a vertex's own paths missed it).",
       .type = ParamType::Int, .def = 256, .min = 1, .max = 1 << 24},
      {.name = "target_relative_error", .label = "Target relative error",
       .help = "If > 0, each vertex traces as many paths as a pilot predicts it needs for a standard error of its "
               "radiosity below this fraction of it (or of a tenth of the scene's mean, for dark vertices), at most "
               "max_samples. The pilot (min_samples paths, then rounds to twice the target, each vertex at most "
               "min_samples or a quarter of max_samples, whichever is more) is left out of the result: a count "
               "decided from the paths it keeps would bias the mean (a vertex whose paths came out bright would "
               "stop early). So the target holds at most vertices (those above it are counted in the log, with "
               "honest error bars) and costs about 1.5 times the paths. With max_samples = min_samples "
               "there is no pilot: every vertex keeps min_samples paths.",
       .type = ParamType::Float, .def = 0.0, .min = 0.0, .max = 1.0},
      {.name = "min_samples", .label = "Minimum paths (adaptive)",
       .help = "Adaptive sampling: the pilot's first paths, and the fewest a vertex keeps.",
       .type = ParamType::Int, .def = 64, .min = 2, .max = 1 << 24},
      {.name = "max_samples", .label = "Maximum paths (adaptive)",
       .help = "Adaptive sampling: the most paths a vertex keeps (its pilot traces at most min_samples or a quarter "
               "as many, whichever is more, besides).",
       .type = ParamType::Int, .def = 65536, .min = 2, .max = 1 << 26},
      {.name = "max_depth", .label = "Maximum bounces",
       .help = "-1 (the default): no fixed limit, so the reference is unbiased: Russian roulette (survival = the "
               "largest channel of the path's throughput) ends paths, after about 1 / (1 - rho) bounces; a path still "
               "going after 100,000 bounces (caught between perfect mirrors) is cut, with a warning. k >= 0: paths "
               "end after k bounces (diffuse, glossy, mirror or glass; 0 = direct light only); the light of more bounces is missing (in a closed room of "
               "reflectance rho, a share rho^(k+1) of what a surface that does not emit reflects: 37% for rho = "
               "0.999 and k = 1000; rho^(k+2) of B in a furnace, where every surface also emits) and is not in "
               "the error bars: a warning says so when it may exceed them.",
       .type = ParamType::Int, .def = -1, .min = -1, .max = 100000},
  };
  for (const ParamSpec& p : SkySun::specs()) out.push_back(p);
  for (const ParamSpec& p : pointLightSpecs()) out.push_back(p);
  out.push_back(lightPathSplitSpec());
  out.push_back(seedSpec("paths"));
  out.push_back({.name = "traced_vertices", .label = "Traced vertices (0 = all)",
                 .help = "A reference that scales: trace only this many vertices, drawn at random without "
                         "replacement (uniformly over the mesh's vertices, from 'Sample seed'); cost is proportional "
                         "to the count (a 1% sample of a million vertices costs a hundredth of the whole). The other "
                         "vertices get 0 and the per-vertex attribute ReferenceTraced tells them apart (1 traced, 0 "
                         "not): compare other methods only where it is 1. 0 traces every vertex.",
                 .type = ParamType::Int, .def = 0, .min = 0, .max = 2000000000});
  out.push_back({.name = "traced_vertex_seed", .label = "Sample seed",
                 .help = "Which vertices 'Traced vertices' draws (the same seed, mesh and count: the same vertices, "
                         "for any thread count and split); independent of the paths' seed.",
                 .type = ParamType::Int, .def = 0, .min = 0, .max = 2147483647});
  out.push_back({.name = "traced_selected", .label = "Trace selected vertices only",
                 .help = "Trace only the selected vertices (MeshLab: the vertex selection; the command-line tool: "
                         "bit 0x20 of the PLY vertex property 'flags', as MeshLab saves a selection): a reference "
                         "where it matters, at a cost proportional to their count. The others get 0 and "
                         "ReferenceTraced 0. Not with 'Traced vertices' > 0; with no vertex selected the filter "
                         "stops with an error.",
                 .type = ParamType::Bool, .def = false});
  return out;
}

PathTraceOptions PathTraceOptions::fromParams(const ParamValues& v, const glm::dvec3& origin) {
  PathTraceOptions o;
  o.samplesPerVertex = v.getInt("samples_per_vertex");
  o.targetRelativeError = v.getFloat("target_relative_error");
  o.minSamples = v.getInt("min_samples");
  o.maxSamples = v.getInt("max_samples");
  o.maxDepth = v.getInt("max_depth");
  const SkySun out = SkySun::fromParams(v);
  o.skyRadiance = out.skyRadiance;
  o.sunDirection = out.sunDirection;
  o.sunIrradiance = out.sunIrradiance;
  o.sunAngularRadiusDeg = out.sunAngularRadiusDeg;
  o.point = pointLightFromParams(v, origin);
  o.lightPathSplit = v.getBool("light_path_split");
  o.seed = uint32_t(v.getInt("seed"));
  o.tracedVertices = size_t(v.getInt("traced_vertices"));
  o.tracedVertexSeed = uint32_t(v.getInt("traced_vertex_seed"));
  o.tracedSelected = v.getBool("traced_selected");
  return o;
}

namespace {

using reference::Cov;
using reference::quadratic;
using reference::ringVariance;
using reference::RingVariance;

// max_depth -1: no fixed limit, but a path caught between perfect mirrors
// (which Russian roulette never ends) stops here.
constexpr int kDepthCap = 100000;

struct Accum {
  uint32_t first = 0;  // the index of the first path counted here (after a discarded pilot)
  double n = 0, sumL = 0, sumL2 = 0, sumHL = 0, sumHL2 = 0;
  Cov sumHH{};  // H's channel products (as Cov)
  glm::dvec3 sumH{0.0};
  glm::dvec3 sumRH{0.0};  // rho H, on a two-sided surface (its sides' reflectances differ)
  glm::dvec3 sumPart[kPathKinds] = {glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0)};  // light_path_split

  // One sample: l = luminance(rho H), and the irradiance H.
  void add(double l, const glm::vec3& H) {
    n += 1;
    sumL += l;
    sumL2 += l * l;
    sumH += glm::dvec3(H);
    const glm::dvec3 h(H);
    sumHH[0] += h.x * h.x;
    sumHH[1] += h.y * h.y;
    sumHH[2] += h.z * h.z;
    sumHH[3] += h.x * h.y;
    sumHH[4] += h.x * h.z;
    sumHH[5] += h.y * h.z;
    const double lh = luminance(H);
    sumHL += lh;
    sumHL2 += lh * lh;
  }
};

// The sample covariance per path of H's channels.
Cov sampleCov(const Accum& a) {
  Cov c{};
  if (a.n < 2) return c;
  const glm::dvec3 m = a.sumH / a.n;
  const double mm[6] = {m.x * m.x, m.y * m.y, m.z * m.z, m.x * m.y, m.x * m.z, m.y * m.z};
  for (int k = 0; k < 6; ++k) c[size_t(k)] = (a.sumHH[size_t(k)] - a.n * mm[k]) / (a.n - 1);
  return c;
}

}  // namespace

PathTraceResult pathTrace(const Scene& s, const RayCaster& caster, const PathTraceOptions& optWorld,
                          const Progress& progress) {
  checkCasterFor(s, caster);
  PathTraceOptions opt = optWorld;
  opt.point = pointLightInLocalUnits(optWorld.point, s);
  opt.point.check();
  if (opt.samplesPerVertex < 1 || opt.minSamples < 2 || opt.maxSamples < opt.minSamples)
    throw std::invalid_argument("samples_per_vertex must be >= 1 and 2 <= min_samples <= max_samples");
  {  // the table's ranges, for a library caller (a NaN sky made every vertex NaN with a standard error of 0)
    const std::vector<ParamSpec> t = PathTraceOptions::specs();
    requireInRange(t, "target_relative_error", opt.targetRelativeError);
    requireInRange(t, "max_depth", opt.maxDepth);
    opt.outside().check();
  }
  Timer timer;
  // The shared integrator (path_integrator.h): every vertex continues,
  // Russian roulette, one light sample per light at every vertex.
  paths::LightSettings lights;
  lights.skyRadiance = opt.skyRadiance;
  lights.sunDirection = opt.sunDirection;
  lights.sunIrradiance = opt.sunIrradiance;
  lights.sunAngularRadiusDeg = opt.sunAngularRadiusDeg;
  lights.point = opt.point;
  paths::PathRules rules;
  rules.maxDepth = opt.maxDepth < 0 ? kDepthCap : opt.maxDepth;
  const paths::Integrator tracer(s, caster, lights, rules);
  if (!tracer.anyLight())
    throw std::invalid_argument("the scene has no light: no emitter faces that emit (select them or mark them by "
                                "face quality, with emitter_intensity above 0 and an emitter_color that is not black), "
                                "no sky, no sun and no point light");
  const SceneReport rep = analyzeScene(s);
  if (rep.usableFaces() == 0) throw std::invalid_argument("the mesh has no usable triangles (" + rep.summary() + ")");
  const VertexMaterial mat = vertexMaterial(s);
  const size_t nv = s.vertexCount();
  // A vertex on a two-sided surface has no normal: it gets the mean of its
  // two sides, each path traced from both (as radiosity's patch average
  // there takes its faces on both sides).
  const VertexSides sides = twoSidedVertices(s, mat);
  std::vector<uint8_t> traceable = mat.valid;
  std::vector<glm::vec3> rayNormal = mat.n;
  for (size_t k = 0; k < sides.vertex.size(); ++k) {
    traceable[sides.vertex[k]] = 1;
    rayNormal[sides.vertex[k]] = sides.n[0][k];
  }
  const float eps = float(rep.rayEpsilon);
  const std::vector<glm::vec3> origins = vertexRayOrigins(s, rayNormal, eps);
  std::vector<Accum> acc(nv);
  std::vector<paths::Counts> counts(nv);
  auto traceTwoSided = [&](size_t i, int32_t slot, int count) {
    Accum& a = acc[i];
    const glm::vec3 o[2] = {origins[i], origins[i] + eps * (sides.n[1][size_t(slot)] - sides.n[0][size_t(slot)])};
    for (int k = 0; k < count; ++k) {
      paths::Sampler smp(hash3(uint32_t(i), opt.seed, 0x9a7eu), a.first + uint32_t(a.n), false);
      glm::vec3 H(0.f), RH(0.f);
      for (int sd = 0; sd < 2; ++sd) {
        glm::vec3 parts[kPathKinds] = {glm::vec3(0.f), glm::vec3(0.f), glm::vec3(0.f)};
        const glm::vec3 h = float(M_PI) * tracer.traceFromSurface(vertexLightPoint(o[sd], sides.n[sd][size_t(slot)], eps), o[sd],
                                                                  sides.n[sd][size_t(slot)], smp, counts[i],
                                                                  opt.lightPathSplit ? parts : nullptr);
        const glm::vec3 rho = sides.rho[sd][size_t(slot)];
        for (int p = 0; p < kPathKinds; ++p) a.sumPart[p] += glm::dvec3(0.5f * float(M_PI) * rho * parts[p]);
        H += 0.5f * h;
        RH += 0.5f * rho * h;
      }
      a.add(luminance(RH), H);
      a.sumRH += glm::dvec3(RH);
    }
  };
  auto trace = [&](size_t i, int count) {
    if (sides.slot[i] >= 0) return traceTwoSided(i, sides.slot[i], count);
    Accum& a = acc[i];
    for (int k = 0; k < count; ++k) {
      // Independent numbers keyed by (vertex, path, seed): honest error bars, any thread count.
      paths::Sampler smp(hash3(uint32_t(i), opt.seed, 0x9a7eu), a.first + uint32_t(a.n), false);
      glm::vec3 parts[kPathKinds] = {glm::vec3(0.f), glm::vec3(0.f), glm::vec3(0.f)};
      const glm::vec3 H = float(M_PI) * tracer.traceFromSurface(vertexLightPoint(origins[i], mat.n[i], eps), origins[i], mat.n[i], smp, counts[i],
                                                                opt.lightPathSplit ? parts : nullptr);
      for (int p = 0; p < kPathKinds; ++p) a.sumPart[p] += glm::dvec3(float(M_PI) * parts[p]);
      a.add(luminance(mat.rho[i] * H), H);
    }
  };
  // The sample variance per path of luminance(B) (of luminance(H) with `h`).
  auto sampleVar = [](const Accum& a, bool h = false) {
    if (a.n < 2) return 0.0;
    const double s1 = h ? a.sumHL : a.sumL, s2 = h ? a.sumHL2 : a.sumL2, m = s1 / a.n;
    return std::max(0.0, (s2 - a.n * m * m) / (a.n - 1));
  };
  const bool adaptive = opt.targetRelativeError > 0;
  // A split run traces its part of the vertices; a sample narrows it.
  VertexPart part = opt.vertices;
  if (opt.tracedSelected) {
    if (opt.tracedVertices > 0)
      throw std::invalid_argument("traced_selected and traced_vertices > 0 both choose the traced vertices: use one");
    if (!opt.selectedVertices || opt.selectedVertices->size() != nv)
      throw std::logic_error("traced_selected needs the selection of every vertex");
    part.subset = opt.selectedVertices;
    // A selection of vertices none of which can be traced (an isolated
    // vertex, a mirror's) traced nothing and wrote zeros with exit 0 (an
    // outside audit): refused, as an empty selection is.
    bool any = false;
    for (size_t i = 0; i < nv && !any; ++i) any = (*opt.selectedVertices)[i] && traceable[i];
    if (!any)
      throw std::invalid_argument("traced_selected is on but no selected vertex lies on a diffuse face that can be "
                                  "traced (the selection holds only vertices no usable face uses, or mirror, glass "
                                  "or glossy ones): select vertices of the diffuse surfaces");
  } else if (opt.tracedVertices > 0 && opt.tracedVertices < nv) {
    part.subset = randomVertexSubset(nv, opt.tracedVertices, opt.tracedVertexSeed);
  }
  if (!part.all() && !part.sumOverParts)
    throw std::logic_error("a reference split over parts needs their sum (VertexPart::sumOverParts): the error bars "
                           "read the neighbours' variances");
  const VertexGraph graph = VertexGraph::build(s);
  // The variances per path of every vertex's luminance(B) and luminance(H),
  // the other parts' included, and H's pooled over the vertex's ring
  // (ringVariance): the error bars' variances.
  struct PooledVariance {
    std::vector<double> B, H;
    std::vector<uint32_t> vertices;
  };
  auto pooled = [&]() {
    // Only the covariances of H and the path counts are exchanged.
    std::vector<double> all(7 * nv, 0.0);
    for (size_t i = 0; i < nv; ++i)
      if (acc[i].n >= 2 && part.contains(i, nv)) {
        const Cov c = sampleCov(acc[i]);
        for (int k = 0; k < 6; ++k) all[6 * i + size_t(k)] = c[size_t(k)];
        all[6 * nv + i] = acc[i].n;
      }
    if (!part.all()) part.sumOverParts(all);
    const std::vector<double> paths(all.begin() + 6 * nv, all.end());
    RingVariance ring = ringVariance(graph, all.data(), paths);
    const glm::dvec3& lum = kLuminanceWeights;
    PooledVariance p;
    p.B.assign(nv, 0.0);
    p.H.assign(nv, 0.0);
    for (size_t i = 0; i < nv; ++i) {
      if (!(acc[i].n >= 2) || !part.contains(i, nv)) continue;
      p.H[i] = std::max(sampleVar(acc[i], true), quadratic(ring.mean[i], lum));
      // A two-sided vertex's B mixes its sides' reflectances: the pool is
      // weighted by their mix in its own estimate (rho H over H, per channel).
      glm::dvec3 rho(mat.rho[i]);
      if (sides.slot[i] >= 0)
        for (int c = 0; c < 3; ++c)
          if (acc[i].sumH[c] > 0) rho[c] = acc[i].sumRH[c] / acc[i].sumH[c];
      const double own = sampleVar(acc[i], false), pool = quadratic(ring.mean[i], rho * lum);
      p.B[i] = ring.vertices[i] > 1 ? std::max(own, pool) : own;
    }
    p.vertices = std::move(ring.vertices);
    return p;
  };
  Timer traceTimer;
  int rounds = 0;         // adaptive: the pilot's rounds
  double floorB = 0;      // adaptive: the error target's floor, a tenth of the pilot's mean B
  double pilotPaths = 0;  // adaptive: the pilot's paths, traced and left out
  double pilotRays = 0;   // and their rays
  if (!adaptive) {
    parallelBlocks(nv, progress, "tracing paths", [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i)
        if (traceable[i] && part.contains(i, nv)) trace(i, opt.samplesPerVertex);
    });
  } else {
    // A pilot, left out of the estimate, then each vertex's count, traced
    // afresh (gi/sampling.h, kPilotMargin): the rounds that stopped when the
    // kept paths' own error bar met the target biased the mean (a room lit
    // through a window, 6 seeds: +9.7% at a target of 0.3 with 64-path
    // pilots, -12.5% at 0.2 with 16).
    // The pilot: min_samples paths, then rounds to kPilotLooseness times the
    // target (about a quarter of the paths), each vertex at most min_samples
    // or a quarter of max_samples, whichever is more: its B and variance then
    // size the count well.
    parallelBlocks(nv, progress.sub(0.0, 0.05), "tracing paths (pilot)", [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i)
        if (traceable[i] && part.contains(i, nv)) trace(i, opt.minSamples);
    });
    // The pilot's mean B over all vertices, summed in vertex order: the same
    // bits in one process and in a split run (each part fills its vertices).
    std::vector<double> pilot(nv, 0.0);
    for (size_t i = 0; i < nv; ++i)
      if (traceable[i] && part.contains(i, nv)) pilot[i] = luminance(mat.E[i]) + acc[i].sumL / acc[i].n;
    if (!part.all()) part.sumOverParts(pilot);
    double meanB = 0;
    size_t valid = 0;
    for (size_t i = 0; i < nv; ++i)
      if (traceable[i] && part.inSubset(i)) { meanB += pilot[i]; ++valid; }
    meanB = valid ? meanB / double(valid) : 0.0;
    floorB = 0.1 * meanB;
  }
  // With max_samples = min_samples the count cannot vary: the first pass's
  // paths are the result, fixed in advance (no pilot to leave out).
  if (adaptive && opt.maxSamples > opt.minSamples) {
    const double pilotTarget = kPilotLooseness * opt.targetRelativeError;
    const double pilotCap = std::max(double(opt.minSamples), std::floor(0.25 * opt.maxSamples));
    // The pilot's rounds: every vertex whose error bar (its ring's pooled
    // variance, as reported) is above the loose target traces what that
    // error bar predicts it needs, at least 32 and at most as many as it has,
    // then the pools are formed again (a vertex that met it goes on when its
    // neighbours' later paths raise its pool's variance). Each part runs the
    // same rounds (the count of vertices still going is summed over them).
    for (int round = 0;; ++round) {
      const std::vector<double> var = pooled().B;
      std::vector<double> going(1, 0.0);
      const double f0 = 1.0 - std::ldexp(1.0, -round), f1 = 1.0 - std::ldexp(1.0, -round - 1);
      std::atomic<size_t> active{0};
      parallelBlocks(nv, progress.sub(0.05 + 0.2 * f0, 0.05 + 0.2 * f1), "tracing paths (pilot)",
                     [&](size_t b, size_t e) {
                       for (size_t i = b; i < e; ++i) {
                         if (!traceable[i] || !part.contains(i, nv) || acc[i].n >= pilotCap) continue;
                         const double B = luminance(mat.E[i]) + acc[i].sumL / acc[i].n;
                         const double goal = pilotTarget * std::max(B, floorB);
                         if (var[i] <= goal * goal * acc[i].n) continue;
                         const double n = goal > 0 ? std::ceil(var[i] / (goal * goal)) - acc[i].n : acc[i].n;
                         const double more = std::clamp(n, 32.0, std::max(32.0, acc[i].n));
                         trace(i, int(std::min(more, pilotCap - acc[i].n)));
                         active.fetch_add(1, std::memory_order_relaxed);
                       }
                     });
      going[0] = double(active.load());
      if (!part.all()) part.sumOverParts(going);
      if (going[0] == 0) {
        rounds = round;
        break;
      }
    }
    // Each vertex's count: what the pilot's error bar predicts for the
    // target, with a margin of kPilotMargin for the pilot's own error, at
    // least min_samples and at most max_samples. Then the pilot is dropped.
    const std::vector<double> var = pooled().B;
    std::vector<int> count(nv, 0);
    for (size_t i = 0; i < nv; ++i) {
      if (!traceable[i] || !part.contains(i, nv)) continue;
      const double B = luminance(mat.E[i]) + acc[i].sumL / acc[i].n;
      const double goal = opt.targetRelativeError * std::max(B, floorB);
      // No variance (no light reached the pilot's paths, nor its ring's):
      // min_samples, as a vertex that meets the target at once.
      const double n = !(var[i] > 0) ? double(opt.minSamples)
                       : goal > 0    ? std::ceil(kPilotMargin * var[i] / (goal * goal))
                                     : double(opt.maxSamples);
      count[i] = int(std::clamp(n, double(opt.minSamples), double(opt.maxSamples)));
      pilotPaths += acc[i].n * (sides.slot[i] >= 0 ? 2.0 : 1.0);
      pilotRays += double(counts[i].rays());
      counts[i] = paths::Counts{};  // the log's paths cut at max_depth are the kept paths'
      Accum fresh;
      fresh.first = uint32_t(acc[i].n);
      acc[i] = fresh;
    }
    parallelBlocks(nv, progress.sub(0.25, 1.0), "tracing paths (adaptive)", [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i)
        if (count[i] > 0) trace(i, count[i]);
    });
  }
  const double traceSeconds = traceTimer.seconds();
  PathTraceResult res;
  res.B.assign(nv, glm::vec3(0.f));
  res.H.assign(nv, glm::vec3(0.f));
  res.stdError.assign(nv, 0.f);
  res.stdErrorH.assign(nv, 0.f);
  res.samples.assign(nv, 0);
  res.traced.assign(nv, 0);
  if (opt.lightPathSplit) res.split.assign(nv);
  const PooledVariance var = pooled();
  // Traced vertices whose pool holds no other traced vertex within 4 rings
  // (a sample of the vertices): their error bars are their own paths' alone.
  size_t isolated = 0;
  for (size_t i = 0; i < nv; ++i) isolated += part.contains(i, nv) && var.vertices[i] == 1;
  double totalRays = 0, samples = 0, lum = 0, rel = 0, err2 = 0, totalCut = 0;
  // Adaptive: the vertices whose error bar ended above the target, those at
  // max_samples (unmet) and the others (above: their pilot read less
  // variance than their kept paths).
  size_t valid = 0, unmet = 0, above = 0;
  for (size_t i = 0; i < nv; ++i) {
    totalRays += double(counts[i].rays());
    totalCut += double(counts[i].cutAtMaxDepth);
    if (!traceable[i] || acc[i].n == 0) continue;
    const bool twoSided = sides.slot[i] >= 0;
    res.H[i] = glm::vec3(acc[i].sumH / acc[i].n);
    res.B[i] = mat.E[i] + (twoSided ? glm::vec3(acc[i].sumRH / acc[i].n) : mat.rho[i] * res.H[i]);
    if (opt.lightPathSplit) {
      // rho H_k per kind, from the same paths: they sum to B - E within float
      // rounding (a two-sided vertex's parts carry their side's rho already).
      const glm::vec3 rho = twoSided ? glm::vec3(1.f) : mat.rho[i];
      res.split.emitted[i] = mat.E[i];
      res.split.direct[i] = rho * glm::vec3(acc[i].sumPart[kPathDirect] / acc[i].n);
      res.split.caustic[i] = rho * glm::vec3(acc[i].sumPart[kPathCaustic] / acc[i].n);
      res.split.indirect[i] = rho * glm::vec3(acc[i].sumPart[kPathIndirect] / acc[i].n);
    }
    res.stdError[i] = float(std::sqrt(var.B[i] / acc[i].n));
    if (adaptive) {  // the target, on the variance reported
      const double goal = opt.targetRelativeError * std::max(luminance(mat.E[i]) + acc[i].sumL / acc[i].n, floorB);
      if (var.B[i] > goal * goal * acc[i].n) ++(acc[i].n >= opt.maxSamples ? unmet : above);
    }
    res.stdErrorH[i] = float(std::sqrt(var.H[i] / acc[i].n));
    res.samples[i] = int(acc[i].n) * (twoSided ? 2 : 1);
    res.traced[i] = 1;
    samples += acc[i].n * (twoSided ? 2.0 : 1.0);  // a two-sided sample is a path from either side
    const double b = luminance(res.B[i]);
    lum += b;
    err2 += double(res.stdError[i]) * res.stdError[i];
    if (b > 0) rel += res.stdError[i] / b;
    ++valid;
  }
  auto& st = res.stats;
  st.add("vertices", double(nv));
  st.add("traced_vertices", double(valid));
  st.add("paths", samples);
  st.add("rays", totalRays + pilotRays);
  st.add("seconds", timer.seconds());
  st.add("rays_per_second", traceSeconds > 0 ? (totalRays + pilotRays) / traceSeconds : 0.0);
  st.add("mean_luminance_B", valid ? lum / double(valid) : 0.0);
  st.add("rms_std_error", valid ? std::sqrt(err2 / double(valid)) : 0.0);
  st.add("mean_relative_std_error", valid ? rel / double(valid) : 0.0);
  st.add("paths_cut_at_max_depth", totalCut);
  if (adaptive) {
    st.add("pilot_rounds", rounds);
    st.add("pilot_paths", pilotPaths);
    st.add("vertices_above_target", double(above));
  }
  paths::depthWarnings(s, opt.maxDepth < 0 ? -1 : opt.maxDepth, kDepthCap, samples, totalCut,
                       valid ? rel / double(valid) : 0.0, "-1 = no limit, unbiased", st);
  if (unmet > 0) {
    // Said as ambient occlusion and the sky say it (an outside sweep, 5
    // December 2026: a target of 1e-6 ran every vertex to max_samples in
    // silence).
    char b[300];
    std::snprintf(b, sizeof b,
                  "%zu of %zu traced vertices stopped at max_samples (%d paths) with their error above "
                  "target_relative_error %.3g: raise max_samples or the target",
                  unmet, valid, opt.maxSamples, opt.targetRelativeError);
    st.warn(b);
  }
  if (above > 0) {
    char b[300];
    std::snprintf(b, sizeof b,
                  "%zu of %zu traced vertices ended with their error bar above target_relative_error %.3g (their "
                  "pilot read less variance than the paths kept; the count is not raised after the fact, which "
                  "would bias the mean)",
                  above, valid, opt.targetRelativeError);
    st.note(b);
  }
  if (!adaptive && opt.samplesPerVertex < 2 && valid > 0)
    st.warn("one path per vertex gives no error estimate: StdError and StdErrorH are written as 0 (unknown, not "
            "exact); an error map's z-scores need 2 or more");
  // The paths a traced vertex kept, on average (fixed: every vertex's).
  if (const std::string w = paths::unsampledLightPaths(s, lights, true, valid ? samples / double(valid) : 0.0); !w.empty())
    st.warn(w);
  if (opt.tracedSelected)
    st.note("traced the " + std::to_string(std::count(part.subset->begin(), part.subset->end(), uint8_t(1))) +
            " selected of the " + std::to_string(nv) + " vertices; the others are 0, with ReferenceTraced 0");
  else if (part.subset)
    st.note("traced a random sample of " + std::to_string(opt.tracedVertices) + " of the " + std::to_string(nv) +
            " vertices (traced_vertex_seed " + std::to_string(opt.tracedVertexSeed) +
            "); the others are 0, with ReferenceTraced 0");
  else if (opt.tracedVertices >= nv && opt.tracedVertices > 0)
    st.note("traced_vertices " + std::to_string(opt.tracedVertices) + " is not below the " + std::to_string(nv) +
            " vertices: all traced");
  if (isolated)
    st.note(std::to_string(isolated) + " traced vertices have no other traced vertex within 4 rings: their error "
            "bars are their own paths' alone, which can miss light that only rare paths find (a caustic, a light "
            "seen in a mirror)");
  size_t twoSidedTraced = 0;
  for (uint32_t v : sides.vertex) twoSidedTraced += part.contains(v, nv) && acc[v].n > 0;
  if (twoSidedTraced)
    st.note(std::to_string(twoSidedTraced) + " vertices on a two-sided surface or where faces turned opposite ways meet (their faces' normals cancel) took the "
            "mean of their two sides (each sample a path from either side)");
  size_t untraced = part.count(nv) - valid;
  untraced -= copyOnlyAmong(s, [&](size_t i) { return part.contains(i, nv) && res.traced[i] == 0; });
  if (untraced)
    st.note(std::to_string(untraced) + " vertices without a usable diffuse face (isolated, or on mirror, "
            "glass or glossy faces only: no diffuse radiosity) or without a side to trace from (a fold whose faces' "
            "normals cancel) got 0");
  const bool otherLights = opt.point.on() || luminance(opt.skyRadiance) > 0.f || luminance(opt.sunIrradiance) > 0.f;
  if (const auto w = emitterOrientationWarning(s, caster, otherLights)) st.warn(*w);
  return res;
}

}  // namespace gi
