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
#include "path_integrator.h"

namespace gi {

std::vector<ParamSpec> PathTraceOptions::specs() {
  std::vector<ParamSpec> out = {
      {.name = "samples_per_vertex", .label = "Paths per vertex",
       .help = "Paths traced from each vertex when no target error is set. The error falls as 1/sqrt(N) (independent "
               "random numbers: the reported standard error is an honest error bar).",
       .type = ParamType::Int, .def = 256, .min = 1, .max = 1 << 24},
      {.name = "target_relative_error", .label = "Target relative error",
       .help = "If > 0, each vertex traces paths in rounds of 32 until the standard error of its radiosity is below "
               "this fraction of it (or of a tenth of the scene's mean, for dark vertices).",
       .type = ParamType::Float, .def = 0.0, .min = 0.0, .max = 1.0},
      {.name = "min_samples", .label = "Minimum paths (adaptive)",
       .help = "Adaptive sampling never stops before this many paths.",
       .type = ParamType::Int, .def = 64, .min = 2, .max = 1 << 24},
      {.name = "max_samples", .label = "Maximum paths (adaptive)",
       .help = "Adaptive sampling never traces more than this many paths.",
       .type = ParamType::Int, .def = 65536, .min = 2, .max = 1 << 26},
      {.name = "max_depth", .label = "Maximum bounces",
       .help = "-1 (the default): no fixed limit, so the reference is unbiased: Russian roulette (survival = the "
               "largest channel of the path's throughput) ends paths, after about 1 / (1 - rho) bounces; a path still "
               "going after 100,000 bounces (caught between perfect mirrors) is cut, with a warning. k >= 0: paths "
               "end after k bounces (diffuse, glossy, mirror or glass; 0 = direct light only); the light of more bounces is missing (in a closed room of "
               "reflectance rho, a share rho^(k+1): 37% for rho = 0.999 and k = 1000) and is not in the error bars: "
               "a warning says so when it may exceed them.",
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

// max_depth -1: no fixed limit, but a path caught between perfect mirrors
// (which Russian roulette never ends) stops here.
constexpr int kDepthCap = 100000;

// Paths the depth limit ended while they would have gone on: their further
// light is missing, a bias outside the error bars. No limit (-1): only paths
// caught between perfect mirrors reach the cap. A limit k: in a closed room
// of reflectance rho_max the light of more than k bounces is a share
// rho_max^(k+1) of B; warn when that may exceed the mean relative error.
void depthWarnings(const Scene& s, const PathTraceOptions& opt, double paths, double cut, double relErr,
                   RunStats& st) {
  if (!(cut > 0) || !(paths > 0)) return;
  char b[400];
  if (opt.maxDepth < 0) {
    std::snprintf(b, sizeof b,
                  "%.0f of %.0f paths (%.3g%%) were still going after %d bounces (caught between perfect mirrors?) "
                  "and were cut: their further light is missing",
                  cut, paths, 100.0 * cut / paths, kDepthCap);
    st.warn(b);
    return;
  }
  float rhoMax = 0.f;
  const auto ok = usableFaceMask(s);
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f]) rhoMax = std::max({rhoMax, s.faceRho(f).r, s.faceRho(f).g, s.faceRho(f).b});
  const double share = std::pow(std::min(1.0, double(rhoMax)), double(opt.maxDepth) + 1.0);
  if (share <= relErr) return;
  std::snprintf(b, sizeof b,
                "max_depth = %d cut %.0f of %.0f paths: the light of more bounces is missing (in a closed room of "
                "the largest reflectance here, %.4g, a share %.3g%% of B), more than the mean relative error "
                "%.3g%%, and is not in the error bars (-1 = no limit, unbiased)",
                opt.maxDepth, cut, paths, rhoMax, 100.0 * share, 100.0 * relErr);
  st.warn(b);
}

struct Accum {
  double n = 0, sumL = 0, sumL2 = 0, sumHL = 0, sumHL2 = 0;
  glm::dvec3 sumH{0.0};
  glm::dvec3 sumPart[kPathKinds] = {glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0)};  // light_path_split
};

}  // namespace

PathTraceResult pathTrace(const Scene& s, const RayCaster& caster, const PathTraceOptions& optWorld,
                          const Progress& progress) {
  PathTraceOptions opt = optWorld;
  opt.point = pointLightInLocalUnits(optWorld.point, s);
  opt.point.check();
  if (opt.samplesPerVertex < 1 || opt.minSamples < 2 || opt.maxSamples < opt.minSamples)
    throw std::invalid_argument("samples_per_vertex must be >= 1 and 2 <= min_samples <= max_samples");
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
    throw std::invalid_argument("the scene has no light: no emitter faces (select them or mark them by face "
                                "quality), no sky, no sun and no point light");
  const SceneReport rep = analyzeScene(s);
  if (rep.usableFaces() == 0) throw std::invalid_argument("the mesh has no usable triangles (" + rep.summary() + ")");
  const VertexMaterial mat = vertexMaterial(s);
  const std::vector<glm::vec3> origins = vertexRayOrigins(s, mat.n, float(rep.rayEpsilon));
  const size_t nv = s.vertexCount();
  std::vector<Accum> acc(nv);
  std::vector<paths::Counts> counts(nv);
  auto trace = [&](size_t i, int count) {
    Accum& a = acc[i];
    for (int k = 0; k < count; ++k) {
      // Independent numbers keyed by (vertex, path, seed): honest error bars, any thread count.
      paths::Sampler smp(hash3(uint32_t(i), opt.seed, 0x9a7eu), uint32_t(a.n), false);
      glm::vec3 parts[kPathKinds] = {glm::vec3(0.f), glm::vec3(0.f), glm::vec3(0.f)};
      const glm::vec3 H = float(M_PI) * tracer.traceFromSurface(origins[i], mat.n[i], smp, counts[i],
                                                                opt.lightPathSplit ? parts : nullptr);
      for (int p = 0; p < kPathKinds; ++p) a.sumPart[p] += glm::dvec3(float(M_PI) * parts[p]);
      const double l = luminance(mat.rho[i] * H);
      a.n += 1;
      a.sumL += l;
      a.sumL2 += l * l;
      a.sumH += glm::dvec3(H);
      const double lh = luminance(H);
      a.sumHL += lh;
      a.sumHL2 += lh * lh;
    }
  };
  auto stdErr = [](const Accum& a) {
    if (a.n < 2) return 0.0;
    const double m = a.sumL / a.n;
    return std::sqrt(std::max(0.0, (a.sumL2 - a.n * m * m) / (a.n - 1)) / a.n);
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
  } else if (opt.tracedVertices > 0 && opt.tracedVertices < nv) {
    part.subset = randomVertexSubset(nv, opt.tracedVertices, opt.tracedVertexSeed);
  }
  if (adaptive && !part.all() && !part.sumOverParts)
    throw std::logic_error("an adaptive reference split over parts needs their sum (VertexPart::sumOverParts)");
  Timer traceTimer;
  if (!adaptive) {
    parallelBlocks(nv, progress, "tracing paths", [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i)
        if (mat.valid[i] && part.contains(i, nv)) trace(i, opt.samplesPerVertex);
    });
  } else {
    // Pilot pass, then rounds of 32 paths for the vertices still above target.
    parallelBlocks(nv, progress.sub(0.0, 0.2), "tracing paths (pilot)", [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i)
        if (mat.valid[i] && part.contains(i, nv)) trace(i, opt.minSamples);
    });
    // The pilot's mean B over all vertices, summed in vertex order: the same
    // bits in one process and in a split run (each part fills its vertices).
    std::vector<double> pilot(nv, 0.0);
    for (size_t i = 0; i < nv; ++i)
      if (mat.valid[i] && part.contains(i, nv)) pilot[i] = luminance(mat.E[i]) + acc[i].sumL / acc[i].n;
    if (!part.all()) part.sumOverParts(pilot);
    double meanB = 0;
    size_t valid = 0;
    for (size_t i = 0; i < nv; ++i)
      if (mat.valid[i] && part.inSubset(i)) { meanB += pilot[i]; ++valid; }
    meanB = valid ? meanB / double(valid) : 0.0;
    const double floorB = 0.1 * meanB;
    parallelBlocks(nv, progress.sub(0.2, 1.0), "tracing paths (adaptive)", [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        if (!mat.valid[i] || !part.contains(i, nv)) continue;
        while (acc[i].n < opt.maxSamples) {
          const double B = luminance(mat.E[i]) + acc[i].sumL / acc[i].n;
          if (stdErr(acc[i]) <= opt.targetRelativeError * std::max(B, floorB)) break;
          trace(i, std::min(32, opt.maxSamples - int(acc[i].n)));
        }
      }
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
  double totalRays = 0, samples = 0, lum = 0, rel = 0, err2 = 0, totalCut = 0;
  size_t valid = 0;
  for (size_t i = 0; i < nv; ++i) {
    totalRays += double(counts[i].rays());
    totalCut += double(counts[i].cutAtMaxDepth);
    if (!mat.valid[i] || acc[i].n == 0) continue;
    res.H[i] = glm::vec3(acc[i].sumH / acc[i].n);
    res.B[i] = mat.E[i] + mat.rho[i] * res.H[i];
    if (opt.lightPathSplit) {
      // rho H_k per kind, from the same paths: they sum to B - E within float rounding.
      res.split.emitted[i] = mat.E[i];
      res.split.direct[i] = mat.rho[i] * glm::vec3(acc[i].sumPart[kPathDirect] / acc[i].n);
      res.split.caustic[i] = mat.rho[i] * glm::vec3(acc[i].sumPart[kPathCaustic] / acc[i].n);
      res.split.indirect[i] = mat.rho[i] * glm::vec3(acc[i].sumPart[kPathIndirect] / acc[i].n);
    }
    res.stdError[i] = float(stdErr(acc[i]));
    Accum h;
    h.n = acc[i].n;
    h.sumL = acc[i].sumHL;
    h.sumL2 = acc[i].sumHL2;
    res.stdErrorH[i] = float(stdErr(h));
    res.samples[i] = int(acc[i].n);
    res.traced[i] = 1;
    samples += acc[i].n;
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
  st.add("rays", totalRays);
  st.add("seconds", timer.seconds());
  st.add("rays_per_second", traceSeconds > 0 ? totalRays / traceSeconds : 0.0);
  st.add("mean_luminance_B", valid ? lum / double(valid) : 0.0);
  st.add("rms_std_error", valid ? std::sqrt(err2 / double(valid)) : 0.0);
  st.add("mean_relative_std_error", valid ? rel / double(valid) : 0.0);
  st.add("paths_cut_at_max_depth", totalCut);
  depthWarnings(s, opt, samples, totalCut, valid ? rel / double(valid) : 0.0, st);
  if (const std::string w = paths::unsampledLightPaths(s, lights); !w.empty()) st.warn(w);
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
  if (valid < part.count(nv))
    st.note(std::to_string(part.count(nv) - valid) + " vertices without a usable diffuse face (isolated, or on mirror, "
            "glass or glossy faces only: no diffuse radiosity) or without a normal (on a two-sided surface the faces' "
            "normals cancel: no side to trace from) got 0");
  return res;
}

}  // namespace gi
