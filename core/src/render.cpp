// The eye pass's driver: tiles of pixels in parallel, primary rays of a tile
// cast together (one coherent batch per sample index), per-pixel means and
// sample variances, the optional per-vertex radiance towards the camera, and
// the log line.
#include "gi/render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "gi/color.h"
#include "gi/emitters.h"
#include "gi/memory_limit.h"
#include "gi/scene_setup.h"
#include "gi/specular.h"
#include "gi/vertex_graph.h"
#include "render_internal.h"

namespace gi {

const char* renderModeName(RenderMode m) { return kRenderModes.logName(m); }

namespace {

using eye::Context;
using eye::Counts;
using eye::Sampler;
using eye::SurfacePoint;

constexpr int kTile = 16;
// Peak memory per pixel of an image (measured: 4096 x 4096 at 1 sample per
// pixel peaks at 399 MB with Whitted and 407 MB path traced on the Cornell
// box, 23 bytes a pixel over the 18 MB of a 512 x 512 run), rounded up.
constexpr double kRenderBytesPerPixel = 24.0;

void validate(const RenderOptions& o) {
  if (int(o.mode) < 0 || int(o.mode) > 3) throw std::invalid_argument("unknown render mode");
  if (o.samplesPerPixel < 1) throw std::invalid_argument("samples_per_pixel must be >= 1");
  if (o.maxDepth < 0) throw std::invalid_argument("max_depth must be >= 0");
  // Only what the mode uses (the table's usedWhen): a value another mode
  // needs is not read here.
  const bool twoPass = o.mode == RenderMode::TwoPass;
  const bool causticMap = twoPass && (o.twoPass == TwoPassDiffuse::Caustics || o.twoPass == TwoPassDiffuse::FinalGather);
  if (o.mode == RenderMode::PathTraced && o.maxDiffuseBounces < -1)
    throw std::invalid_argument("max_diffuse_bounces must be >= -1 (-1: no limit)");
  if (o.lightSamples < 1) throw std::invalid_argument("light_samples must be >= 1");
  if (twoPass && o.twoPass == TwoPassDiffuse::FinalGather && o.gatherRays < 1)
    throw std::invalid_argument("gather_rays must be >= 1");
  if (causticMap && (o.causticPhotons < 1 || o.causticK < 1 || o.causticK > 512 || !(o.causticMaxRadius >= 0.0)))
    throw std::invalid_argument("caustic_photons must be >= 1, caustic_k in [1, 512] and caustic_max_radius >= 0");
  if (o.mode == RenderMode::Whitted && !(o.whittedMinWeight >= 0.f && o.whittedMinWeight <= 1.f))
    throw std::invalid_argument("whitted_min_weight must lie in [0, 1]");
  o.point.check();
  o.outside().check();
  if (!o.renderImage && !o.vertexRadiance) throw std::invalid_argument("neither an image nor vertex radiance was asked for");
}

// One sample of the radiance along `ray`, whose first surface point is sp:
// its hit (onRay: a camera's ray) or a point given apart from it (a vertex).
glm::vec3 sampleRadiance(const Context& ctx, RenderMode mode, const Ray& ray, const SurfacePoint& sp, bool onRay,
                         Sampler& smp, Counts& c, uint64_t& nonFinite) {
  const glm::vec3 L =
      mode == RenderMode::Whitted ? ctx.traceWhitted(ray, &sp, c, onRay) : ctx.traceSampled(ray, &sp, smp, c, onRay);
  if (finite3(L)) return L;
  ++nonFinite;
  return glm::vec3(0.f);
}

struct Tally {
  Counts counts;
  uint64_t nonFinite = 0;
};

// Each pixel's error bar takes the larger of its own sample variance and
// the mean of the variances of the 5 x 5 pixels around it (those inside the
// image), as a vertex's does over its mesh ring in the reference
// (core/src/path_error_bars.h). A few paths' sample variance is heavily
// skewed (most paths bring one value, a rare one much more): in a white
// furnace of radiance 0.640 everywhere, one pixel's 16 paths read 0.581 +-
// 0.00076, and 19.5% of the pixels lay beyond 3 of their standard errors at
// the default 16 samples (an outside audit). Neighbouring pixels see nearly
// the same light; where the light changes (an edge) the larger variance
// makes the bars wider, never narrower.
// One sample per pixel has no sample variance of its own: the error bar is
// then the spread of the pixels' values around it (their sample
// variance, each pixel one sample), which the image's own changes (edges)
// only widen. The file of error bars was all 0, an exact-looking result
// beside the noisiest image there is (an outside audit).
// At few samples a pixel the 5 x 5 pixels hold too few paths to find the
// rare bright ones: at 1 sample a pixel (25 paths) a furnace's bars were
// too narrow by half (mean z^2 4.68, 8.1% of the pixels beyond 3), the
// Cornell box's mean z^2 2.51; at 2 samples 1.30 and 0.84 (an outside
// audit); from 4 samples (100 paths) 0.5 to 0.8. The window now grows until
// it holds kPooledPaths paths (1 sample: 11 x 11, 2: 9 x 9, 3: 7 x 7).
constexpr int kPooledPixelRadius = 2;
constexpr int kPooledPaths = 100;
int pooledRadius(int spp) {
  int r = kPooledPixelRadius;
  while ((2 * r + 1) * (2 * r + 1) * std::max(spp, 1) < kPooledPaths) ++r;
  return r;
}

// The mean of v over the (2r + 1)^2 pixels around each pixel (those inside
// the image): rows, then columns.
std::vector<double> boxMean(int W, int H, const std::vector<double>& v, int r) {
  std::vector<double> across(v.size(), 0.0), mean(v.size(), 0.0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      double sum = 0;
      for (int u = std::max(0, x - r); u <= std::min(W - 1, x + r); ++u) sum += v[size_t(y) * size_t(W) + size_t(u)];
      across[size_t(y) * size_t(W) + size_t(x)] = sum;
    }
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      double sum = 0;
      for (int w = std::max(0, y - r); w <= std::min(H - 1, y + r); ++w) sum += across[size_t(w) * size_t(W) + size_t(x)];
      const double count = double(std::min(W - 1, x + r) - std::max(0, x - r) + 1) *
                           double(std::min(H - 1, y + r) - std::max(0, y - r) + 1);
      mean[size_t(y) * size_t(W) + size_t(x)] = sum / count;
    }
  return mean;
}

void poolPixelVariances(int W, int H, int spp, const Image* oneSample, std::vector<float>& se) {
  const size_t n = se.size();
  if (spp == 1) {
    if (!oneSample) return;
    std::vector<double> l(n), l2(n);
    for (size_t p = 0; p < n; ++p) l[p] = luminance(oneSample->px[p]), l2[p] = l[p] * l[p];
    const int r = pooledRadius(1);
    const std::vector<double> m = boxMean(W, H, l, r), m2 = boxMean(W, H, l2, r);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const double count = double(std::min(W - 1, x + r) - std::max(0, x - r) + 1) *
                             double(std::min(H - 1, y + r) - std::max(0, y - r) + 1);
        const size_t p = size_t(y) * size_t(W) + size_t(x);
        const double var = std::max(0.0, m2[p] - m[p] * m[p]) * (count > 1 ? count / (count - 1) : 1.0);
        se[p] = float(std::sqrt(var));
      }
    return;
  }
  std::vector<double> var(n);
  for (size_t p = 0; p < n; ++p) var[p] = double(se[p]) * se[p] * spp;
  const std::vector<double> mean = boxMean(W, H, var, pooledRadius(spp));
  for (size_t p = 0; p < n; ++p) se[p] = float(std::sqrt(std::max(var[p], mean[p]) / spp));
}

void renderImage(const Scene& s, const RayCaster& caster, const RenderOptions& o, const Context& ctx,
                 const Progress& progress, RenderResult& res, Tally& tally) {
  const Camera& cam = o.camera;
  const int W = cam.width(), H = cam.height();
  res.image = Image(W, H);
  res.stdError.assign(res.image.px.size(), 0.f);
  res.seesEmitter.assign(res.image.px.size(), 0);
  const int tx = (W + kTile - 1) / kTile, ty = (H + kTile - 1) / kTile;
  const size_t nTiles = size_t(tx) * size_t(ty);
  std::vector<Tally> tileTally(nTiles);
  const bool qmc = o.mode != RenderMode::PathTraced;
  const uint32_t salt = 0x5e11u + uint32_t(o.mode);
  const int spp = o.samplesPerPixel;
  auto renderTile = [&](size_t t) {
    const int x0 = int(t % size_t(tx)) * kTile, y0 = int(t / size_t(tx)) * kTile;
    const int x1 = std::min(W, x0 + kTile), y1 = std::min(H, y0 + kTile);
    const size_t n = size_t(x1 - x0) * size_t(y1 - y0);
    std::vector<Ray> rays(n);
    std::vector<Hit> hits(n);
    std::vector<Sampler> smp;
    smp.reserve(n);
    std::vector<glm::dvec3> sum(n, glm::dvec3(0.0));
    std::vector<double> sl(n, 0.0), sl2(n, 0.0);
    Tally& tl = tileTally[t];
    for (int k = 0; k < spp; ++k) {
      // The tile's primary rays for sample k, cast as one batch (packets).
      smp.clear();
      size_t i = 0;
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x, ++i) {
          const uint32_t pixel = uint32_t(y) * uint32_t(W) + uint32_t(x);
          smp.emplace_back(hash3(pixel, o.seed, salt), uint32_t(k), qmc);
          const glm::vec2 u = smp[i].next2D(), lens = smp[i].next2D();
          rays[i] = cam.ray({float(x) + u.x, float(y) + u.y}, lens, s.origin, s.unit);
        }
      caster.intersectBatch(rays.data(), n, hits.data());
      tl.counts.primary += n;
      i = 0;
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x, ++i) {
          const SurfacePoint sp = ctx.surfaceAt(rays[i], hits[i]);
          if (k == 0 && sp.valid() && ctx.emits(sp.face) && glm::dot(sp.n, rays[i].d) < 0.f)
            res.seesEmitter[size_t(y) * size_t(W) + size_t(x)] = 1;
          const glm::vec3 L = sampleRadiance(ctx, o.mode, rays[i], sp, true, smp[i], tl.counts, tl.nonFinite);
          sum[i] += glm::dvec3(L);
          const double l = luminance(L);
          sl[i] += l;
          sl2[i] += l * l;
        }
    }
    size_t i = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x, ++i) {
        const size_t p = size_t(y) * size_t(W) + size_t(x);
        res.image.px[p] = glm::vec3(sum[i] / double(spp));
        if (spp > 1) {
          const double m = sl[i] / spp, var = std::max(0.0, (sl2[i] - spp * m * m) / (spp - 1));
          res.stdError[p] = float(std::sqrt(var / spp));
        }
      }
  };
  // Slices of tiles between progress reports (MeshLab's callback runs on this thread only).
  const size_t threads = size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
  const size_t slice = std::max<size_t>(4 * threads, nTiles / 50);
  progress.report(0.0, "tracing eye rays");
  for (size_t b0 = 0; b0 < nTiles; b0 += slice) {
    const size_t b1 = std::min(nTiles, b0 + slice);
    tbb::parallel_for(tbb::blocked_range<size_t>(b0, b1, 1), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t t = r.begin(); t != r.end(); ++t) renderTile(t);
    });
    progress.report(double(b1) / double(nTiles), "tracing eye rays");
  }
  for (const Tally& t : tileTally) {
    tally.counts.add(t.counts);
    tally.nonFinite += t.nonFinite;
  }
  poolPixelVariances(W, H, spp, o.mode == RenderMode::PathTraced ? &res.image : nullptr, res.stdError);
}

// For each vertex, the radiance it sends towards the camera: an eye ray
// arriving at the vertex (visible or not) from the camera's side, shaded
// with the vertex normal (a smooth surface's reflection) on the incident
// face seen most frontally; 0 for vertices facing away from the camera.
// Path traced with 2 or more samples, each vertex's standard error as a
// pixel's: its own sample variance, or its two rings' mean variance where
// that is larger (a few paths' variance is skewed low; see
// poolPixelVariances).
std::vector<glm::vec3> vertexRadiance(const Scene& s, const RenderOptions& o, const Context& ctx,
                                      const Progress& progress, Tally& tally, std::vector<float>& stdError) {
  const size_t nv = s.vertexCount();
  const auto ok = usableFaceMask(s);
  const std::vector<glm::vec3> faceN = unitFaceNormals(s);
  std::vector<glm::vec3> vn = vertexNormalsForRays(s);
  for (glm::vec3& n : vn)
    if (glm::dot(n, n) > 0.f) n = glm::normalize(n);
  // Each vertex's eye ray arrives at the point the per-vertex filters start
  // their rays from, less its lift along the normal (which the paths add):
  // pulled into its faces by the ray offset, so that at a border vertex
  // (a wall's edge beside another wall) the light from the other wall is not
  // lost through the seam.
  const std::vector<glm::vec3> lifted = vertexRayOrigins(s, vn, ctx.eps());
  std::vector<uint32_t> start(nv + 1, 0), faces;
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f])
      for (int k = 0; k < 3; ++k) ++start[s.triangles[f][k] + 1];
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  faces.resize(start[nv]);
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f])
      for (int k = 0; k < 3; ++k) faces[fill[s.triangles[f][k]]++] = uint32_t(f);
  std::vector<glm::vec3> out(nv, glm::vec3(0.f));
  const int spp = o.samplesPerPixel;
  const bool errorBars = o.mode == RenderMode::PathTraced && spp > 1;
  std::vector<double> var(errorBars ? nv : 0, 0.0);
  std::vector<uint8_t> traced(nv, 0);
  std::mutex m;
  const bool qmc = o.mode != RenderMode::PathTraced;
  parallelBlocks(nv, progress, "radiance towards the camera", [&](size_t b, size_t e) {
    Tally local;
    for (size_t v = b; v < e; ++v) {
      if (start[v] == start[v + 1]) continue;
      const glm::vec3 toCam = glm::vec3(o.camera.towardsCamera(s.toWorld(s.positions[v])));
      uint32_t best = faces[start[v]];
      for (uint32_t j = start[v]; j < start[v + 1]; ++j)
        if (glm::dot(faceN[faces[j]], toCam) > glm::dot(faceN[best], toCam)) best = faces[j];
      SurfacePoint sp;
      sp.x = lifted[v] - ctx.eps() * vn[v];
      sp.face = best;
      sp.n = glm::dot(vn[v], faceN[best]) > 0.5f ? vn[v] : faceN[best];
      // Facing away: nothing leaves it towards the camera on its outer side
      // (a glass vertex would start an eye ray inside the glass, beyond the
      // critical angle where no light can come from).
      if (!(glm::dot(sp.n, toCam) > 0.f)) continue;
      const auto& t = s.triangles[best];
      sp.u = t.y == v ? 1.f : 0.f;
      sp.v = t.z == v ? 1.f : 0.f;
      Ray ray;
      ray.o = sp.x;
      ray.d = -toCam;
      glm::dvec3 sum(0.0);
      double sl = 0, sl2 = 0;
      for (int k = 0; k < spp; ++k) {
        Sampler smp(hash3(uint32_t(v), o.seed, 0x7e47u), uint32_t(k), qmc);
        const glm::vec3 L = sampleRadiance(ctx, o.mode, ray, sp, false, smp, local.counts, local.nonFinite);
        sum += glm::dvec3(L);
        const double l = luminance(L);
        sl += l, sl2 += l * l;
      }
      out[v] = glm::vec3(sum / double(spp));
      traced[v] = 1;
      if (errorBars) var[v] = std::max(0.0, (sl2 - sl * sl / spp) / (spp - 1));
    }
    std::lock_guard<std::mutex> lock(m);
    tally.counts.add(local.counts);
    tally.nonFinite += local.nonFinite;
  });
  if (errorBars) {
    atLeastRingMean(VertexGraph::build(s, &ok), traced, var);
    stdError.assign(nv, 0.f);
    for (size_t v = 0; v < nv; ++v) stdError[v] = float(std::sqrt(var[v] / spp));
  }
  return out;
}

}  // namespace

RenderResult render(const Scene& s, const RayCaster& caster, const RenderOptions& optWorld, const Progress& progress) {
  checkCasterFor(s, caster);
  // Lengths and the point light in the scene's local units (Scene::unit); the
  // camera stays in world coordinates and maps its rays itself.
  RenderOptions o = optWorld;
  o.point = pointLightInLocalUnits(optWorld.point, s);
  o.causticMaxRadius = optWorld.causticMaxRadius / s.unit;
  validate(o);
  // One limit for the run. The image is checked first and the two-pass
  // mode's caustic photons get what it leaves: each checked alone against
  // the machine's figure, both could fit where together they do not (the
  // image is allocated after the photons, so the kernel's figure would not
  // count it yet).
  const size_t limit = memoryLimitOrAvailable(o.memoryLimitBytes);
  double imageBytes = 0;
  if (o.renderImage) {
    imageBytes = double(o.camera.width()) * double(o.camera.height()) * kRenderBytesPerPixel;
    requireMemory(imageBytes, limit,
                  "an image of " + std::to_string(o.camera.width()) + " x " + std::to_string(o.camera.height()) +
                      " pixels",
                  "lower width and height (about " + std::to_string(int(kRenderBytesPerPixel)) +
                      " bytes a pixel: the radiance, its error, the sRGB copy and the files' buffers)");
  }
  Timer timer;
  const auto ok = usableFaceMask(s);
  if (std::none_of(ok.begin(), ok.end(), [](uint8_t x) { return x != 0; }))
    throw std::invalid_argument("the mesh has no usable triangles");
  RenderResult res;
  RunStats& st = res.stats;
  const bool twoPass = o.mode == RenderMode::TwoPass;
  eye::TwoPassData tp;
  if (twoPass) {
    const eye::PhotonMemory pm{limit == 0 ? 0 : size_t(std::max(1.0, double(limit) - imageBytes)), imageBytes};
    eye::prepareTwoPass(tp, s, caster, o, pm, progress.sub(0.0, 0.2), st);
  }
  const Context ctx(s, caster, o, twoPass ? &tp : nullptr);
  if (!ctx.anyLight() && !(twoPass && o.twoPass == TwoPassDiffuse::Map))
    throw std::invalid_argument("the scene has no light: no emitter faces that emit (select them or mark them by face "
                                "quality, with emitter_intensity above 0 and an emitter_color that is not black), no "
                                "sky, no sun and no point light");
  Tally tally;
  const Progress main = progress.sub(twoPass ? 0.2 : 0.0, o.vertexRadiance && o.renderImage ? 0.9 : 1.0);
  Timer traceTimer;
  if (o.renderImage) renderImage(s, caster, o, ctx, main, res, tally);
  if (o.vertexRadiance)
    res.vertexRadiance =
        vertexRadiance(s, o, ctx, o.renderImage ? progress.sub(0.9, 1.0) : main, tally, res.vertexStdError);
  const double traceSeconds = traceTimer.seconds();

  const Counts& c = tally.counts;
  st.add("samples_per_pixel", o.samplesPerPixel);
  if (o.renderImage) {
    st.add("width", o.camera.width());
    st.add("height", o.camera.height());
  }
  st.add("primary_rays", double(c.primary));
  st.add("shadow_rays", double(c.shadow));
  st.add("specular_rays", double(c.specular));
  st.add("glossy_rays", double(c.glossy));
  st.add("diffuse_rays", double(c.diffuse));
  if (c.gather) st.add("gather_rays", double(c.gather));
  if (c.gatherNear) st.add("gather_near_hits_relit", double(c.gatherNear));
  st.add("rays", double(c.rays()));
  st.add("seconds", timer.seconds());
  st.add("rays_per_second", traceSeconds > 0 ? double(c.rays()) / traceSeconds : 0.0);
  if (o.renderImage) {
    double lum = 0, err2 = 0, rel = 0;
    size_t relN = 0;
    const size_t n = res.image.px.size();
    for (size_t p = 0; p < n; ++p) {
      const double l = luminance(res.image.px[p]);
      lum += l;
      err2 += double(res.stdError[p]) * res.stdError[p];
      if (l > 0) { rel += res.stdError[p] / l; ++relN; }
    }
    st.add("mean_radiance", lum / double(n));
    // Every pixel black: nothing lit in view (an eye inside an object sees
    // only back faces, which are black; or the camera looks away).
    if (n > 0 && !(lum > 0)) {
      // Whitted's and the distributed view's shadow rays stop at mirrors
      // and glass, and their paths have no diffuse bounce: a room lit only
      // through a glass window is black there (an outside audit: the
      // warning named only the camera).
      const bool specular = anyFaceMaterial(s, isCausticSurface);
      const bool direct = o.mode == RenderMode::Whitted || o.mode == RenderMode::Distributed ||
                          (o.mode == RenderMode::PathTraced && o.maxDiffuseBounces == 0);
      st.warn(std::string("the image is black: no eye ray reached a lit surface (is the camera inside an object, or "
                          "looking away from the scene?") +
              (specular && direct ? " Or is the light in view only reached through mirrors or glass? This mode's "
                                    "shadow rays stop at them and it follows no diffuse bounce: try the path-traced "
                                    "or two-pass mode)"
                                  : ")"));
    }
    st.add("rms_std_error", std::sqrt(err2 / double(n)));
    st.add("mean_relative_std_error", relN ? rel / double(relN) : 0.0);
    if (o.mode == RenderMode::PathTraced)
      paths::depthWarnings(s, o.maxDepth, o.maxDepth, double(n) * o.samplesPerPixel, double(c.cutAtMaxDepth),
                           relN ? rel / double(relN) : 0.0, "raise max_depth, up to 100,000", st);
  }
  st.note(std::string("mode ") + renderModeName(o.mode));
  // A lens whose blur at the scene's centre exceeds the whole image: every
  // pixel averages light from across the scene or beyond it (an aperture of
  // 10 focused 0.1 from an eye 800 from the Cornell box gave a black image
  // blamed on the camera's place; an outside audit). Blur radius A |1/F -
  // 1/z| at depth z, in the image plane at distance 1.
  if (const Camera& cam = o.camera; o.renderImage && !cam.orthographic() && cam.apertureRadius() > 0.0) {
    const SceneReport rep = analyzeScene(s, /*duplicateFaces=*/false);
    const double z = glm::dot(0.5 * (rep.bboxMin + rep.bboxMax) - cam.eye(), cam.forward());
    const double blur = z > 0.0 ? cam.apertureRadius() * std::fabs(1.0 / cam.focusDistance() - 1.0 / z) *
                                      cam.pixelsPerTangent()
                                : 0.0;
    if (blur > double(std::max(cam.width(), cam.height()))) {
      char b[400];
      std::snprintf(b, sizeof b,
                    "depth of field: the scene's centre, %.3g away, blurs into a disk %.3g pixels wide, wider than "
                    "the image (aperture_radius %.3g, focus_distance %.3g): the picture is a blur; focus on the "
                    "scene (focus_distance 0: the target's distance) or narrow the aperture",
                    z, 2.0 * blur, cam.apertureRadius(), cam.focusDistance());
      st.warn(b);
    }
  }
  if (o.mode == RenderMode::PathTraced && o.samplesPerPixel < 2) 
    st.warn("one sample per pixel: each pixel's error bar is the spread of the 11 x 11 pixels around it (wider "
            "where the image changes; more samples give each pixel its own)");
  // The distributed view's shadow rays stop at glass as the path tracer's
  // do: a point light inside a glass sphere left its image unchanged without
  // a word (an outside sweep, 5 December 2026).
  if (o.mode == RenderMode::PathTraced || o.mode == RenderMode::Distributed) {
    paths::LightSettings lights;
    lights.point = o.point;
    lights.sunIrradiance = o.sunIrradiance;
    lights.sunAngularRadiusDeg = o.sunAngularRadiusDeg;
    if (const std::string w = paths::unsampledLightPaths(s, lights, o.mode == RenderMode::PathTraced, o.samplesPerPixel);
        !w.empty())
      st.warn(w);
  }
  if (o.mode != RenderMode::PathTraced)
    st.note("error estimate from the spread of QMC pixel samples (an upper bound rather than an error bar)");
  if (o.mode == RenderMode::Whitted) {
    st.add("area_lights", double(ctx.areaLightCount()));
    if (luminance(o.skyRadiance) > 0.f) st.note("Whitted: the sky is seen but lights no diffuse surface");
    if (anyFaceMaterial(s, [](Material m) { return m == Material::Glossy; }))
      st.note("Whitted: glossy faces reflect one ray in the mirror direction weighted by their Fresnel factor (a "
              "sharp mirror; the distributed and path-traced modes sample their lobe)");
    if (o.sunIrradiance != glm::vec3(0.f) && o.sunAngularRadiusDeg > 0.f)
      st.note("Whitted: the sun lights as a point at infinity (sharp shadows)");
    if (c.belowWeight) st.note(std::to_string(c.belowWeight) + " branches below whitted_min_weight not traced");
  }
  if (o.mode == RenderMode::Distributed || (twoPass && o.twoPass != TwoPassDiffuse::Map))
    st.note("no diffuse interreflection traced" + std::string(twoPass ? " (the first pass gives it)" : ""));
  if (c.cutAtMaxDepth)
    st.note(std::to_string(c.cutAtMaxDepth) + " paths cut at max_depth " + std::to_string(o.maxDepth));
  if (tally.nonFinite) st.warn(std::to_string(tally.nonFinite) + " samples with a non-finite radiance dropped");
  const bool otherLights = o.point.on() || luminance(o.skyRadiance) > 0.f || luminance(o.sunIrradiance) > 0.f;
  if (const auto w = emitterOrientationWarning(s, caster, otherLights)) st.warn(*w);
  return res;
}

}  // namespace gi
