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
#include "gi/specular.h"

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
               "largest reflectance channel) ends paths, after about 1 / (1 - rho) bounces; a path still going after "
               "100,000 bounces (caught between perfect mirrors) is cut, with a warning. k >= 0: paths end after k "
               "bounces (0 = direct light only); the light of more bounces is missing (in a closed room of "
               "reflectance rho, a share rho^(k+1): 37% for rho = 0.999 and k = 1000) and is not in the error bars: "
               "a warning says so when it may exceed them.",
       .type = ParamType::Int, .def = -1, .min = -1, .max = 100000},
      {.name = "sky_color", .label = "Sky colour",
       .help = "Colour of a uniform sky around the scene (sRGB).",
       .type = ParamType::Color, .defVec = glm::vec3(1.f)},
      {.name = "sky_irradiance", .label = "Sky irradiance (W/m^2)",
       .help = "Irradiance the sky gives an unoccluded surface (pi x its radiance); 0 = no sky.",
       .type = ParamType::Float, .def = 0.0, .min = 0.0, .max = 1e9},
      {.name = "sun_direction", .label = "Sun direction",
       .help = "Direction towards the sun.",
       .type = ParamType::Direction, .defVec = glm::vec3(0.3f, 1.f, 0.2f)},
      {.name = "sun_color", .label = "Sun colour",
       .help = "Colour of the sun (sRGB).",
       .type = ParamType::Color, .defVec = glm::vec3(1.f)},
      {.name = "sun_irradiance", .label = "Sun irradiance (W/m^2)",
       .help = "Irradiance of the sun on a surface facing it; 0 = no sun.",
       .type = ParamType::Float, .def = 0.0, .min = 0.0, .max = 1e9},
      {.name = "sun_angular_radius", .label = "Sun angular radius (deg)",
       .help = "0 gives a sharp directional light.",
       .type = ParamType::Float, .def = 0.27, .min = 0.0, .max = 45},
  };
  for (const ParamSpec& p : pointLightSpecs()) out.push_back(p);
  out.push_back(seedSpec("paths"));
  return out;
}

PathTraceOptions PathTraceOptions::fromParams(const ParamValues& v, const glm::dvec3& origin) {
  PathTraceOptions o;
  auto lin = [](glm::vec3 c) { return glm::vec3(srgbToLinear(c.r), srgbToLinear(c.g), srgbToLinear(c.b)); };
  o.samplesPerVertex = v.getInt("samples_per_vertex");
  o.targetRelativeError = v.getFloat("target_relative_error");
  o.minSamples = v.getInt("min_samples");
  o.maxSamples = v.getInt("max_samples");
  o.maxDepth = v.getInt("max_depth");
  o.skyRadiance = lin(v.getVec("sky_color")) * float(v.getFloat("sky_irradiance") / M_PI);
  o.sunDirection = v.getDirection("sun_direction");
  o.sunIrradiance = lin(v.getVec("sun_color")) * float(v.getFloat("sun_irradiance"));
  o.sunAngularRadiusDeg = float(v.getFloat("sun_angular_radius"));
  o.point = pointLightFromParams(v, origin);
  o.seed = uint32_t(v.getInt("seed"));
  return o;
}

namespace {

// max_depth -1: no fixed limit, but a path caught between perfect mirrors
// (which Russian roulette never ends) stops here.
constexpr int kDepthCap = 100000;

class Tracer {
 public:
  Tracer(const Scene& s, const RayCaster& c, const PathTraceOptions& o)
      : s_(s), caster_(c), o_(o), lights_(s), eps_(float(sceneScale(s).rayEpsilon)),
        maxDepth_(o.maxDepth < 0 ? kDepthCap : o.maxDepth) {
    faceN_.resize(s.faceCount());
    for (size_t f = 0; f < s.faceCount(); ++f) {
      const glm::vec3 n = faceNormalUnnormalized(s, f);
      const float l = glm::length(n);
      faceN_[f] = l > 0 ? n / l : glm::vec3(0.f, 0.f, 1.f);
    }
    sunCos_ = std::cos(glm::radians(o.sunAngularRadiusDeg));
    const float omega = 2.f * float(M_PI) * (1.f - sunCos_);
    hasSun_ = luminance(o.sunIrradiance) > 0.f;
    sunDisk_ = hasSun_ && o.sunAngularRadiusDeg > 0.f;
    sunPdf_ = sunDisk_ ? 1.f / omega : 0.f;
    sunL_ = sunDisk_ ? o.sunIrradiance / omega : glm::vec3(0.f);
    hasPoint_ = o.point.on();
    if (lights_.empty() && luminance(o.skyRadiance) <= 0.f && !hasSun_ && !hasPoint_)
      throw std::invalid_argument("the scene has no light: no emitter faces (select them or mark them by face "
                                  "quality), no sky, no sun and no point light");
  }

  // One-sample estimate of the irradiance at x (unit normal n, the lit side):
  // next-event estimation there, then the path continued by cosine-weighted
  // sampling, bounce after bounce in a loop (never recursion: a path between
  // white mirrors can run to max_depth = 100,000 bounces). beta is the path
  // throughput: what a radiance arriving at the current vertex adds to H.
  // cut: paths ended by the depth limit while they would have gone on.
  glm::vec3 irradiance(const glm::vec3& x0, const glm::vec3& n0, Rng& rng, uint64_t& rays, uint64_t& cut) const {
    glm::vec3 H(0.f);
    glm::vec3 beta(1.f);
    glm::vec3 x = x0, n = n0;
    int depth = 0;
    for (;;) {
      // A diffuse vertex x (normal n) at `depth` bounces from the start.
      H += beta * nextEvent(x, n, rng, rays);
      glm::vec3 w = Frame(n).toWorld(cosineHemisphere({rng.next(), rng.next()}));
      float pdfB = glm::dot(n, w) * 0.318309886f;
      if (!(pdfB > 0.f)) return H;
      beta *= float(M_PI);  // cos / pdf = pi
      // Follow w through mirrors and glass to the next diffuse vertex.
      // afterSpecular: the direction came from a mirror or glass (a delta
      // distribution next-event estimation cannot sample, so emitters and
      // the sun count fully).
      bool afterSpecular = false;
      for (;;) {
        Ray ray;
        ray.o = x;
        ray.d = w;
        ++rays;
        const Hit h = caster_.intersect(ray);
        if (!h.valid()) {
          glm::vec3 L = o_.skyRadiance;
          if (sunDisk_ && glm::dot(w, o_.sunDirection) >= sunCos_)
            L += sunL_ * (afterSpecular ? 1.f : powerHeuristic(pdfB, sunPdf_));
          return H + beta * L;
        }
        const glm::vec3 ng = faceN_[h.face];
        const Material m = s_.faceMaterial(h.face);
        if (!isSpecular(m)) {
          const float cosY = -glm::dot(ng, w);
          if (cosY <= 0.f) return H;  // a back face: black, as in the radiosity filter
          const glm::vec3 E = s_.faceEmission(h.face);
          if (E.r > 0.f || E.g > 0.f || E.b > 0.f) {
            const float pdfL = lights_.pdfArea(h.face) * h.t * h.t / cosY;
            H += beta * (E * 0.318309886f * (afterSpecular ? 1.f : powerHeuristic(pdfB, pdfL)));
          }
          const glm::vec3 rho = s_.faceRho(h.face);
          const float q = std::min(1.f, std::max({rho.r, rho.g, rho.b}));
          if (!(q > 0.f)) return H;
          if (depth >= maxDepth_) { ++cut; return H; }
          float scale = 1.f;
          if (depth >= 3) {  // Russian roulette
            if (rng.next() >= q) return H;
            scale = 1.f / q;
          }
          beta *= rho * 0.318309886f * scale;
          x = x + w * h.t + ng * eps_;
          n = ng;
          ++depth;
          break;
        }
        // A mirror or glass hit: continue in the sampled specular direction.
        if (depth >= maxDepth_) { ++cut; return H; }
        const glm::vec3 y = x + w * h.t;
        const float ior = s_.ior.empty() ? 1.5f : s_.ior[h.face];
        const SpecularEvent ev = scatterSpecular(m, w, ng, s_.faceRho(h.face), ior, rng.next());
        glm::vec3 weight = ev.weight * ev.radianceScale;
        if (depth >= 3) {  // Russian roulette on the tint (clear glass and white mirrors always continue)
          const float q = std::min(1.f, std::max({ev.weight.r, ev.weight.g, ev.weight.b}));
          if (!(q > 0.f) || (q < 1.f && rng.next() >= q)) return H;
          weight /= q;
        }
        beta *= weight;
        x = y + (glm::dot(ev.d, ng) > 0.f ? ng : -ng) * eps_;
        w = ev.d;
        pdfB = 0.f;
        afterSpecular = true;
        ++depth;
      }
    }
  }

 private:
  // Direct irradiance from every light, each sampled once (MIS with the
  // cosine-weighted direction for the lights a BSDF ray can also hit).
  glm::vec3 nextEvent(const glm::vec3& x, const glm::vec3& n, Rng& rng, uint64_t& rays) const {
    glm::vec3 H(0.f);
    Ray ray;
    ray.o = x;
    if (!lights_.empty()) {
      const glm::vec2 u{rng.next(), rng.next()};
      H += sampleLightMIS(lights_, caster_, x, n, u, eps_, &rays);
    }
    if (hasSun_) {
      const glm::vec3 w = sunDisk_ ? Frame(o_.sunDirection).toWorld(uniformCone({rng.next(), rng.next()}, sunCos_))
                                   : o_.sunDirection;
      const float cx = glm::dot(n, w);
      if (cx > 0.f) {
        ray.d = w;
        ray.tfar = std::numeric_limits<float>::infinity();
        ++rays;
        if (!caster_.occluded(ray)) {
          const float mis = sunDisk_ ? powerHeuristic(sunPdf_, cx * 0.318309886f) : 1.f;
          H += (sunDisk_ ? sunL_ * cx / sunPdf_ : o_.sunIrradiance * cx) * mis;
        }
      }
    }
    if (hasPoint_) {
      ++rays;
      H += pointLightIrradiance(o_.point, caster_, x, n);
    }
    return H;
  }

  const Scene& s_;
  const RayCaster& caster_;
  const PathTraceOptions& o_;
  EmitterSampler lights_;
  float eps_;
  int maxDepth_;
  std::vector<glm::vec3> faceN_;
  float sunCos_ = 1.f, sunPdf_ = 0.f;
  glm::vec3 sunL_{0.f};
  bool hasSun_ = false, sunDisk_ = false, hasPoint_ = false;
};

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
};

}  // namespace

PathTraceResult pathTrace(const Scene& s, const RayCaster& caster, const PathTraceOptions& optWorld,
                          const Progress& progress) {
  PathTraceOptions opt = optWorld;
  opt.point = pointLightInLocalUnits(optWorld.point, s);
  if (opt.samplesPerVertex < 1 || opt.minSamples < 2 || opt.maxSamples < opt.minSamples)
    throw std::invalid_argument("samples_per_vertex must be >= 1 and 2 <= min_samples <= max_samples");
  Timer timer;
  const Tracer tracer(s, caster, opt);
  const SceneReport rep = analyzeScene(s);
  if (rep.usableFaces() == 0) throw std::invalid_argument("the mesh has no usable triangles (" + rep.summary() + ")");
  const VertexMaterial mat = vertexMaterial(s);
  const std::vector<glm::vec3> origins = vertexRayOrigins(s, mat.n, float(rep.rayEpsilon));
  const size_t nv = s.vertexCount();
  std::vector<Accum> acc(nv);
  std::vector<uint64_t> rays(nv, 0), cut(nv, 0);
  auto trace = [&](size_t i, int count) {
    Accum& a = acc[i];
    for (int k = 0; k < count; ++k) {
      Rng rng(hash3(uint32_t(i), uint32_t(a.n), opt.seed ^ 0x9a7eu));
      const glm::vec3 H = tracer.irradiance(origins[i], mat.n[i], rng, rays[i], cut[i]);
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
  const VertexPart& part = opt.vertices;  // a split run traces its part of the vertices
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
      if (mat.valid[i]) { meanB += pilot[i]; ++valid; }
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
  double totalRays = 0, samples = 0, lum = 0, rel = 0, err2 = 0, totalCut = 0;
  size_t valid = 0;
  for (size_t i = 0; i < nv; ++i) {
    totalRays += double(rays[i]);
    totalCut += double(cut[i]);
    if (!mat.valid[i] || acc[i].n == 0) continue;
    res.H[i] = glm::vec3(acc[i].sumH / acc[i].n);
    res.B[i] = mat.E[i] + mat.rho[i] * res.H[i];
    res.stdError[i] = float(stdErr(acc[i]));
    Accum h;
    h.n = acc[i].n;
    h.sumL = acc[i].sumHL;
    h.sumL2 = acc[i].sumHL2;
    res.stdErrorH[i] = float(stdErr(h));
    res.samples[i] = int(acc[i].n);
    samples += acc[i].n;
    const double b = luminance(res.B[i]);
    lum += b;
    err2 += double(res.stdError[i]) * res.stdError[i];
    if (b > 0) rel += res.stdError[i] / b;
    ++valid;
  }
  auto& st = res.stats;
  st.add("vertices", double(nv));
  st.add("paths", samples);
  st.add("rays", totalRays);
  st.add("seconds", timer.seconds());
  st.add("rays_per_second", traceSeconds > 0 ? totalRays / traceSeconds : 0.0);
  st.add("mean_luminance_B", valid ? lum / double(valid) : 0.0);
  st.add("rms_std_error", valid ? std::sqrt(err2 / double(valid)) : 0.0);
  st.add("mean_relative_std_error", valid ? rel / double(valid) : 0.0);
  st.add("paths_cut_at_max_depth", totalCut);
  depthWarnings(s, opt, samples, totalCut, valid ? rel / double(valid) : 0.0, st);
  if (valid < part.count(nv)) st.note(std::to_string(part.count(nv) - valid) + " vertices without a usable diffuse face (isolated, or on mirrors or glass only) got 0");
  return res;
}

}  // namespace gi
