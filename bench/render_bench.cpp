// The ray-traced view's benchmark engine (driven by bench/render_bench.py):
// the caustic Cornell box with its glossy block (scenes::causticCornellGlossy:
// glass sphere, mirror, GGX block of roughness 0.2 and colour sRGB 255,200,120),
// seen by the filter's default framing camera.
//   render_bench reference W H SPP SEED STEM   a long path-traced image: STEM.pfm (radiance),
//                                              STEM_se.pfm (per-pixel standard error of the luminance)
//   render_bench run W H STEM MODE A B SEED    one run of a mode against the reference STEM:
//                                              MODE pt (A = spp), twopass / gather (A = photons,
//                                              B = spp), distributed (A = spp), whitted (A = spp)
//   render_bench throughput W H SPP REPEATS    primary and secondary rays per second against a bare
//                                              Embree loop over the same rays; packets and streams
// Each prints one JSON object. The error of an image: over the pixels that
// show no light source (lightFreeMask), the RMS of its luminance minus the
// reference's, relative to the reference's mean; also with the reference's
// own variance (its per-pixel standard errors squared) taken out, an
// unbiased estimate of the error against the exact image.
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "gi/color.h"
#include "gi/image.h"
#include "gi/photon.h"
#include "gi/render.h"
#include "gi/run.h"
#include "gi/scenes.h"
#include "gi/specular.h"

using namespace gi;

namespace {

Scene benchScene() {
  const glm::vec3 F0(srgbToLinear(1.f), srgbToLinear(200.f / 255.f), srgbToLinear(120.f / 255.f));
  return scenes::causticCornellGlossy(50.0, 10.0, 5, 1.5f, 0.2f, F0);
}

struct Bounds {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
};
Bounds bounds(const Scene& s) {
  Bounds b;
  for (const auto& p : s.positions) {
    b.lo = glm::min(b.lo, s.toWorld(p));
    b.hi = glm::max(b.hi, s.toWorld(p));
  }
  return b;
}

RenderOptions baseOptions(const Scene& s, int w, int h, RenderMode mode, int spp, uint32_t seed) {
  RenderOptions o;
  const Bounds b = bounds(s);
  o.camera = Camera::frame(b.lo, b.hi, {0, 0, 1}, {0, 1, 0}, 39.3, w, h);
  o.mode = mode;
  o.samplesPerPixel = spp;
  o.seed = seed;
  return o;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The pixels measured: not those that show a light source, directly or in
// a mirror or glass (4 x 4 rays per pixel followed through both branches of
// every mirror and glass hit, 8 deep), nor their 8 neighbours. Those are the
// same in every mode but for antialiasing, and so much brighter than the
// rest that their antialiasing noise would swamp the measure.
std::vector<uint8_t> lightFreeMask(const Scene& s, const RayCaster& c, const Camera& cam) {
  const int W = cam.width(), H = cam.height();
  std::vector<uint8_t> sees(size_t(W) * size_t(H), 0), keep(sees.size(), 1);
  const std::vector<glm::vec3> n = unitFaceNormals(s);
  const float eps = float(sceneScale(s).rayEpsilon);
  auto reaches = [&](Ray r) {
    std::vector<std::pair<Ray, int>> stack{{r, 0}};
    while (!stack.empty()) {
      auto [ray, depth] = stack.back();
      stack.pop_back();
      const Hit h = c.intersect(ray);
      if (!h.valid()) continue;
      const Material m = s.faceMaterial(h.face);
      const glm::vec3 x = ray.o + ray.d * h.t, ng = n[h.face];
      if (!isSpecular(m)) {
        if (luminance(s.faceEmission(h.face)) > 0.f && glm::dot(ng, ray.d) < 0.f) return true;
        continue;
      }
      if (depth >= 8) continue;
      for (float u : {0.f, 0.99999f}) {  // the reflected and (glass) the refracted branch
        const SpecularEvent ev = scatterSpecular(m, ray.d, ng, glm::vec3(1.f), s.ior.empty() ? 1.5f : s.ior[h.face], u);
        Ray next;
        next.o = x + (glm::dot(ev.d, ng) > 0.f ? ng : -ng) * eps;
        next.d = ev.d;
        stack.push_back({next, depth + 1});
        if (m == Material::Mirror) break;
      }
    }
    return false;
  };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int k = 0; k < 16 && !sees[size_t(y) * size_t(W) + size_t(x)]; ++k)
        if (reaches(cam.ray({x + (k % 4 + 0.5f) / 4.f, y + (k / 4 + 0.5f) / 4.f}, {0.5f, 0.5f}, s.origin, s.unit)))
          sees[size_t(y) * size_t(W) + size_t(x)] = 1;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx >= 0 && yy >= 0 && xx < W && yy < H && sees[size_t(yy) * size_t(W) + size_t(xx)])
            keep[size_t(y) * size_t(W) + size_t(x)] = 0;
        }
  return keep;
}

// What each pixel's centre ray sees first, for the error map
// (bench/render_error_map.py): channel 0 the surface, 0..5 a diffuse face by
// its normal (floor +y, ceiling -y, left wall +x, right wall -x, back wall z,
// other), 6 an emitter, 7 glossy, 8 mirror, 9 glass, 10 nothing; channel 1
// the distance from the hit to the second-nearest plane of the scene's
// bounding box (small: near an edge or corner of the room).
Image surfaceClasses(const Scene& s, const RayCaster& c, const Camera& cam) {
  const Bounds b = bounds(s);
  const glm::dvec3 lo = b.lo - s.origin, hi = b.hi - s.origin;
  const std::vector<glm::vec3> n = unitFaceNormals(s);
  Image out(cam.width(), cam.height());
  for (int y = 0; y < cam.height(); ++y)
    for (int x = 0; x < cam.width(); ++x) {
      const Ray ray = cam.ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}, s.origin, s.unit);
      const Hit h = c.intersect(ray);
      glm::vec3& px = out.at(x, y);
      if (!h.valid()) { px = {10.f, 0.f, 0.f}; continue; }
      const glm::dvec3 p = glm::dvec3(ray.o + ray.d * h.t);
      double d[6] = {p.x - lo.x, hi.x - p.x, p.y - lo.y, hi.y - p.y, p.z - lo.z, hi.z - p.z};
      std::sort(d, d + 6);
      px.y = float(d[1]);
      const Material m = s.faceMaterial(h.face);
      const glm::vec3 fn = n[h.face];
      if (m == Material::Glossy) px.x = 7.f;
      else if (m == Material::Mirror) px.x = 8.f;
      else if (m == Material::Glass) px.x = 9.f;
      else if (luminance(s.faceEmission(h.face)) > 0.f) px.x = 6.f;
      else if (fn.y > 0.9f) px.x = 0.f;
      else if (fn.y < -0.9f) px.x = 1.f;
      else if (fn.x > 0.9f) px.x = 2.f;
      else if (fn.x < -0.9f) px.x = 3.f;
      else if (std::abs(fn.z) > 0.9f) px.x = 4.f;
      else px.x = 5.f;
    }
  return out;
}

struct ImageError {
  double rel = 0, relCorrected = 0, refMean = 0;
  size_t pixels = 0;
};
ImageError imageError(const Image& img, const Image& ref, const Image& refSe, const std::vector<uint8_t>& keep) {
  double d2 = 0, se2 = 0, sum = 0;
  size_t n = 0;
  for (size_t p = 0; p < img.px.size(); ++p) {
    if (!keep[p]) continue;
    const double d = luminance(img.px[p]) - luminance(ref.px[p]);
    d2 += d * d;
    se2 += double(refSe.px[p].r) * refSe.px[p].r;
    sum += luminance(ref.px[p]);
    ++n;
  }
  ImageError e;
  e.pixels = n;
  e.refMean = sum / double(n);
  e.rel = std::sqrt(d2 / double(n)) / e.refMean;
  e.relCorrected = std::sqrt(std::max(0.0, d2 - se2) / double(n)) / e.refMean;
  return e;
}

int reference(int w, int h, int spp, uint32_t seed, const std::string& stem) {
  const Scene s = benchScene();
  const auto caster = makeEmbreeCaster(s);
  const RenderOptions o = baseOptions(s, w, h, RenderMode::PathTraced, spp, seed);
  Timer t;
  const RenderResult r = render(s, *caster, o);
  writePfm(stem + ".pfm", r.image);
  Image se(w, h);
  for (size_t p = 0; p < se.px.size(); ++p) se.px[p] = glm::vec3(r.stdError[p]);
  writePfm(stem + "_se.pfm", se);
  const std::vector<uint8_t> keep = lightFreeMask(s, *caster, o.camera);
  double se2 = 0, sum = 0, n = 0;
  for (size_t p = 0; p < se.px.size(); ++p)
    if (keep[p]) { se2 += double(r.stdError[p]) * r.stdError[p]; sum += luminance(r.image.px[p]); ++n; }
  std::printf("{\"width\": %d, \"height\": %d, \"spp\": %d, \"seed\": %u, \"seconds\": %.4f, \"rays\": %.0f, "
              "\"relative_rms_std_error\": %.6g, \"mean\": %.6g, \"pixels_measured\": %.0f}\n",
              w, h, spp, seed, t.seconds(), r.stats.get("rays"), std::sqrt(se2 / n) / (sum / n), sum / n, n);
  return 0;
}

int run(int w, int h, const std::string& stem, const std::string& mode, int a, int b, uint32_t seed, int causticK) {
  const Scene s = benchScene();
  const auto caster = makeEmbreeCaster(s);
  const Image ref = readPfm(stem + ".pfm"), refSe = readPfm(stem + "_se.pfm");
  RenderOptions o = baseOptions(s, w, h, RenderMode::PathTraced, a, seed);
  double firstSeconds = 0;
  Timer t;
  if (mode == "distributed") o.mode = RenderMode::Distributed;
  if (mode == "whitted") o.mode = RenderMode::Whitted;
  if (mode == "twopass" || mode == "gather") {
    // Photon mapping as the filter runs it by default (k 64, caustic k 128,
    // gather radius 5% of the diagonal, direct light by 256 shadow rays per
    // vertex), then the eye pass reading the same caustic photons.
    const Bounds bb = bounds(s);
    const double radius = 0.05 * glm::length(bb.hi - bb.lo);
    PhotonOptions po;
    po.photons = a;
    po.maxRadius = radius;
    po.seed = seed;
    const VertexRadiometry first = computePhotonMap(s, *caster, po);
    firstSeconds = t.seconds();
    o.mode = RenderMode::TwoPass;
    o.twoPass = mode == "gather" ? TwoPassDiffuse::FinalGather : TwoPassDiffuse::Caustics;
    o.samplesPerPixel = b;
    o.causticPhotons = a;
    o.causticK = causticK > 0 ? causticK : po.causticK;
    o.causticMaxRadius = radius;
    o.firstPassB = first.B;
    o.firstPassBdirect = first.Bdirect;  // as the filter passes it on (RadiosityDirect)
  }
  const RenderResult r = render(s, *caster, o);
  const double seconds = t.seconds();
  if (const char* keepImage = std::getenv("RENDER_BENCH_IMAGE")) writePfm(keepImage, r.image);
  const std::vector<uint8_t> keep = lightFreeMask(s, *caster, o.camera);
  if (const char* maskPath = std::getenv("RENDER_BENCH_MASK")) {
    Image m(w, h);
    for (size_t p = 0; p < m.px.size(); ++p) m.px[p] = glm::vec3(float(keep[p]));
    writePfm(maskPath, m);
  }
  if (const char* classPath = std::getenv("RENDER_BENCH_CLASSES")) writePfm(classPath, surfaceClasses(s, *caster, o.camera));
  const ImageError e = imageError(r.image, ref, refSe, keep);
  std::printf("{\"mode\": \"%s\", \"a\": %d, \"b\": %d, \"seed\": %u, \"seconds\": %.4f, \"first_pass_seconds\": %.4f, "
              "\"rays\": %.0f, \"relative_rms_error\": %.6g, \"relative_rms_error_corrected\": %.6g, "
              "\"pixels_measured\": %zu}\n",
              mode.c_str(), a, b, seed, seconds, firstSeconds, r.stats.get("rays"), e.rel, e.relCorrected, e.pixels);
  return 0;
}

// A bare Embree scene over the same triangles, robust like ours.
struct BareEmbree {
  RTCDevice dev = rtcNewDevice(nullptr);
  RTCScene scene = rtcNewScene(dev);
  explicit BareEmbree(const Scene& s) {
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, s.positions.size()));
    auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, s.triangles.size()));
    for (size_t i = 0; i < s.positions.size(); ++i) {
      vb[3 * i] = s.positions[i].x; vb[3 * i + 1] = s.positions[i].y; vb[3 * i + 2] = s.positions[i].z;
    }
    for (size_t i = 0; i < s.triangles.size(); ++i) {
      ib[3 * i] = s.triangles[i].x; ib[3 * i + 1] = s.triangles[i].y; ib[3 * i + 2] = s.triangles[i].z;
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    rtcCommitScene(scene);
  }
  ~BareEmbree() { rtcReleaseScene(scene); rtcReleaseDevice(dev); }
};

RTCRayHit toRayHit(const Ray& r) {
  RTCRayHit h;
  h.ray.org_x = r.o.x; h.ray.org_y = r.o.y; h.ray.org_z = r.o.z; h.ray.tnear = r.tnear;
  h.ray.dir_x = r.d.x; h.ray.dir_y = r.d.y; h.ray.dir_z = r.d.z; h.ray.time = 0.f;
  h.ray.tfar = r.tfar; h.ray.mask = 0xffffffffu; h.ray.id = 0; h.ray.flags = 0;
  h.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  h.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return h;
}

// Forwards to a caster and keeps every single ray it is asked (the
// integrator's secondary rays: continuations and shadow rays).
class RecordingCaster : public RayCaster {
 public:
  explicit RecordingCaster(const RayCaster& inner) : inner_(inner) {}
  Hit intersect(const Ray& r) const override {
    local_.local().hits.push_back(r);
    return inner_.intersect(r);
  }
  bool occluded(const Ray& r) const override {
    local_.local().shadows.push_back(r);
    return inner_.occluded(r);
  }
  void intersectBatch(const Ray* rays, size_t n, Hit* hits) const override { inner_.intersectBatch(rays, n, hits); }
  void collect(std::vector<Ray>& hits, std::vector<Ray>& shadows) const {
    for (const auto& b : local_) {
      hits.insert(hits.end(), b.hits.begin(), b.hits.end());
      shadows.insert(shadows.end(), b.shadows.begin(), b.shadows.end());
    }
  }

 private:
  struct Buffers {
    std::vector<Ray> hits, shadows;
  };
  const RayCaster& inner_;
  mutable tbb::enumerable_thread_specific<Buffers> local_;
};

template <class F>
double timeParallel(size_t n, F f) {
  Timer t;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); });
  return t.seconds();
}

int throughput(int w, int h, int spp, int repeats) {
  const Scene s = benchScene();
  const BareEmbree bare(s);
  const RenderOptions base = baseOptions(s, w, h, RenderMode::PathTraced, spp, 0);
  // Primary rays in the order the renderer casts them: per 16 x 16 tile, per sample.
  std::vector<Ray> primary;
  for (int ty = 0; ty < h; ty += 16)
    for (int tx = 0; tx < w; tx += 16)
      for (int k = 0; k < spp; ++k)
        for (int y = ty; y < std::min(h, ty + 16); ++y)
          for (int x = tx; x < std::min(w, tx + 16); ++x) {
            const float jx = float((k * 7 + 3) % 16) / 16.f, jy = float((k * 11 + 5) % 16) / 16.f;
            primary.push_back(base.camera.ray({x + jx, y + jy}, {0.5f, 0.5f}, s.origin, s.unit));
          }
  const size_t tileRays = 256;  // one batch: a full tile's sample
  const size_t batches = (primary.size() + tileRays - 1) / tileRays;
  std::vector<Hit> hits(primary.size());
  std::vector<RTCRayHit> bareRays(primary.size());
  for (size_t i = 0; i < primary.size(); ++i) bareRays[i] = toRayHit(primary[i]);
  std::vector<double> tBare, tBare8, tSingle, tPacket, tStream;
  auto casters = std::vector<std::unique_ptr<RayCaster>>();
  for (BatchMode m : {BatchMode::Single, BatchMode::Packet8, BatchMode::Stream}) casters.push_back(makeEmbreeCaster(s, m));
  for (int rep = 0; rep < repeats; ++rep) {
    std::vector<RTCRayHit> work = bareRays;
    tBare.push_back(timeParallel(batches, [&](size_t b0, size_t b1) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (size_t i = b0 * tileRays; i < std::min(primary.size(), b1 * tileRays); ++i) rtcIntersect1(bare.scene, &ctx, &work[i]);
    }));
    // Bare 8-wide packets of the same rays (what packets gain without our bookkeeping).
    work = bareRays;
    tBare8.push_back(timeParallel(batches, [&](size_t b0, size_t b1) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      alignas(32) RTCRayHit8 p;
      alignas(32) int valid[8];
      for (size_t i = b0 * tileRays; i < std::min(primary.size(), b1 * tileRays); i += 8) {
        for (size_t k = 0; k < 8; ++k) {
          const bool in = i + k < primary.size();
          const RTCRayHit& r = work[in ? i + k : i];
          valid[k] = in ? -1 : 0;
          p.ray.org_x[k] = r.ray.org_x; p.ray.org_y[k] = r.ray.org_y; p.ray.org_z[k] = r.ray.org_z;
          p.ray.dir_x[k] = r.ray.dir_x; p.ray.dir_y[k] = r.ray.dir_y; p.ray.dir_z[k] = r.ray.dir_z;
          p.ray.tnear[k] = r.ray.tnear; p.ray.tfar[k] = r.ray.tfar; p.ray.time[k] = 0.f; p.ray.mask[k] = 0xffffffffu;
          p.ray.id[k] = 0; p.ray.flags[k] = 0; p.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
          p.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect8(valid, bare.scene, &ctx, &p);
        for (size_t k = 0; k < 8 && i + k < primary.size(); ++k) work[i + k].ray.tfar = p.ray.tfar[k];
      }
    }));
    std::vector<double>* out[3] = {&tSingle, &tPacket, &tStream};
    for (int m = 0; m < 3; ++m)
      out[m]->push_back(timeParallel(batches, [&](size_t b0, size_t b1) {
        for (size_t b = b0; b < b1; ++b) {
          const size_t i0 = b * tileRays, n = std::min(tileRays, primary.size() - i0);
          casters[size_t(m)]->intersectBatch(primary.data() + i0, n, hits.data() + i0);
        }
      }));
  }
  // The secondary rays of a path-traced image, recorded, then replayed bare.
  const auto ours = makeEmbreeCaster(s);
  const RecordingCaster rec(*ours);
  const RenderResult r = render(s, rec, base);
  std::vector<Ray> secHits, secShadows;
  rec.collect(secHits, secShadows);
  std::vector<RTCRayHit> bareHits(secHits.size());
  for (size_t i = 0; i < secHits.size(); ++i) bareHits[i] = toRayHit(secHits[i]);
  std::vector<RTCRay> bareShadows(secShadows.size());
  for (size_t i = 0; i < secShadows.size(); ++i) bareShadows[i] = toRayHit(secShadows[i]).ray;
  std::vector<double> tBareSec, tOursRender, tOursPrimary;
  double oursRays = 0, oursPrimary = 0;
  for (int rep = 0; rep < repeats; ++rep) {
    std::vector<RTCRayHit> wh = bareHits;
    std::vector<RTCRay> ws = bareShadows;
    const double a = timeParallel(wh.size(), [&](size_t i0, size_t i1) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (size_t i = i0; i < i1; ++i) rtcIntersect1(bare.scene, &ctx, &wh[i]);
    });
    const double b = timeParallel(ws.size(), [&](size_t i0, size_t i1) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (size_t i = i0; i < i1; ++i) rtcOccluded1(bare.scene, &ctx, &ws[i]);
    });
    tBareSec.push_back(a + b);
    const RenderResult rr = render(s, *ours, base);
    tOursRender.push_back(rr.stats.get("rays") / rr.stats.get("rays_per_second"));
    oursRays = rr.stats.get("rays");
    oursPrimary = rr.stats.get("primary_rays");
  }
  const double nPrim = double(primary.size()), nSec = double(secHits.size() + secShadows.size());
  // Ours per secondary ray: the render's time less its primary rays' (packets, as it casts them).
  const double oursSecSeconds = median(tOursRender) - median(tPacket) * oursPrimary / nPrim;
  std::printf("{\"width\": %d, \"height\": %d, \"spp\": %d, \"repeats\": %d, \"threads\": %d,\n"
              " \"primary_rays\": %.0f, \"bare_intersect1_primary_rays_per_second\": %.6g,\n"
              " \"bare_intersect8_primary_rays_per_second\": %.6g,\n"
              " \"ours_single_primary_rays_per_second\": %.6g, \"ours_packet8_primary_rays_per_second\": %.6g,\n"
              " \"ours_stream_primary_rays_per_second\": %.6g,\n"
              " \"secondary_rays\": %.0f, \"secondary_intersect_rays\": %zu, \"secondary_shadow_rays\": %zu,\n"
              " \"bare_secondary_rays_per_second\": %.6g, \"ours_path_traced_rays_per_second\": %.6g,\n"
              " \"ours_secondary_rays_per_second\": %.6g, \"ours_rays_in_render\": %.0f}\n",
              w, h, spp, repeats, int(tbb::this_task_arena::max_concurrency()), nPrim, nPrim / median(tBare), nPrim / median(tBare8),
              nPrim / median(tSingle), nPrim / median(tPacket), nPrim / median(tStream), nSec, secHits.size(),
              secShadows.size(), nSec / median(tBareSec), oursRays / median(tOursRender),
              (oursRays - oursPrimary) / oursSecSeconds, oursRays);
  (void)r;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string cmd = argc > 1 ? argv[1] : "";
    if (cmd == "reference" && argc == 7)
      return reference(std::atoi(argv[2]), std::atoi(argv[3]), std::atoi(argv[4]), uint32_t(std::atoi(argv[5])), argv[6]);
    if (cmd == "run" && (argc == 9 || argc == 10))
      return run(std::atoi(argv[2]), std::atoi(argv[3]), argv[4], argv[5], std::atoi(argv[6]), std::atoi(argv[7]),
                 uint32_t(std::atoi(argv[8])), argc == 10 ? std::atoi(argv[9]) : 0);
    if (cmd == "throughput" && argc == 6)
      return throughput(std::atoi(argv[2]), std::atoi(argv[3]), std::atoi(argv[4]), std::atoi(argv[5]));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_bench: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr,
               "usage: render_bench reference W H SPP SEED STEM | run W H STEM MODE A B SEED [CAUSTIC_K] | throughput W H SPP "
               "REPEATS\n");
  return 2;
}
