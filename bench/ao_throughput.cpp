// Rays per second of our ambient occlusion against a bare Embree loop over
// the same rays (same origins, same directions, same thread pool).
//   ao_throughput MESH RAYS_PER_VERTEX [REPEATS] [THREADS]  ->  JSON on stdout
// The bare loop gets its rays pre-generated (not timed), so it is the upper
// bound of what tracing alone costs; ours includes sampling and bookkeeping.
// Ours builds its BVH with RTC_SCENE_FLAG_ROBUST (watertight: no leaks through
// shared edges); the bare loop is timed with and without that flag.
#include <embree3/rtcore.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <memory>
#include <mutex>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "gi/ambient.h"
#include "gi/run.h"
#include "gi/sampling.h"
#include "mesh_io.h"

using namespace gi;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct BareEmbree {
  RTCDevice dev = rtcNewDevice(nullptr);
  RTCScene scene = rtcNewScene(dev);
  BareEmbree(const Scene& s, bool robust) {
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, s.positions.size()));
    auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, s.triangles.size()));
    for (size_t i = 0; i < s.positions.size(); ++i) { vb[3 * i] = s.positions[i].x; vb[3 * i + 1] = s.positions[i].y; vb[3 * i + 2] = s.positions[i].z; }
    for (size_t i = 0; i < s.triangles.size(); ++i) { ib[3 * i] = s.triangles[i].x; ib[3 * i + 1] = s.triangles[i].y; ib[3 * i + 2] = s.triangles[i].z; }
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    if (robust) rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    rtcCommitScene(scene);
  }
  ~BareEmbree() { rtcReleaseScene(scene); rtcReleaseDevice(dev); }
};

RTCRay bareRay(const glm::vec3& o, const glm::vec3& d, float tfar) {
  RTCRay r;
  r.org_x = o.x; r.org_y = o.y; r.org_z = o.z; r.tnear = 0.f;
  r.dir_x = d.x; r.dir_y = d.y; r.dir_z = d.z; r.time = 0.f;
  r.tfar = tfar; r.mask = 0xffffffffu; r.id = 0; r.flags = 0;
  return r;
}

// Casts through `c` and keeps every fan's rays, in the order cast (run on
// one thread, so that the bare loop replays one vertex's rays after another
// as ours casts them): the adaptive strata estimator's rays depend on what
// its first rays met.
class RecordingCaster : public RayCaster {
 public:
  explicit RecordingCaster(const RayCaster& c) : c_(c) {}
  Hit intersect(const Ray& r) const override { return c_.intersect(r); }
  bool occluded(const Ray& r) const override { return c_.occluded(r); }
  void occludedFan(const glm::vec3& o, const glm::vec3* dirs, size_t n, float tfar, uint8_t* occ) const override {
    c_.occludedFan(o, dirs, n, tfar, occ);
    std::lock_guard<std::mutex> lock(m_);
    for (size_t i = 0; i < n; ++i) rays.push_back(bareRay(o, dirs[i], tfar));
  }
  mutable std::vector<RTCRay> rays;

 private:
  const RayCaster& c_;
  mutable std::mutex m_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) { std::fprintf(stderr, "usage: ao_throughput MESH RAYS_PER_VERTEX [REPEATS] [THREADS]\n"); return 2; }
  const int rpv = std::atoi(argv[2]);
  const int repeats = argc > 3 ? std::atoi(argv[3]) : 5;
  const int threads = argc > 4 ? std::atoi(argv[4]) : 0;
  std::unique_ptr<tbb::global_control> gc;
  if (threads > 0) gc = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
  io::LoadedMesh mesh = io::loadMesh(argv[1]);
  const Scene& s = mesh.scene;
  const SceneReport rep = analyzeScene(s);
  const auto normals = computeVertexNormals(s);
  const auto origins = vertexRayOrigins(s, normals, float(rep.rayEpsilon));
  // The same rays as computeAmbient casts (seed 0, fixed count).
  const size_t nv = s.vertexCount();
  std::vector<RTCRay> rays(nv * size_t(rpv));
  for (size_t i = 0; i < nv; ++i) {
    const Frame f(normals[i]);
    SobolOwenStream seq(hash3(uint32_t(i), 0u, 0x41u));
    const size_t nr = static_cast<size_t>(rpv);
    std::vector<float> u0(nr), u1(nr), lx(nr), ly(nr), lz(nr);
    for (int b = 0; b < rpv; b += 32) {
      const int m = std::min(32, rpv - b);
      seq.nextBlock(m, &u0[size_t(b)], &u1[size_t(b)]);
      cosineHemisphereBlock(m, &u0[size_t(b)], &u1[size_t(b)], &lx[size_t(b)], &ly[size_t(b)], &lz[size_t(b)]);
    }
    for (int j = 0; j < rpv; ++j)
      rays[i * size_t(rpv) + size_t(j)] =
          bareRay(origins[i], f.t * lx[size_t(j)] + f.b * ly[size_t(j)] + f.n * lz[size_t(j)], HUGE_VALF);
  }
  BareEmbree bare(s, false), bareRobust(s, true);
  std::vector<double> tBare, tBareRobust, tOurs, tOursSingle, tOursStream, tShared, tSharedPooling, tStrata,
      tStrataBare;
  double sharedRays = 0;
  size_t occludedBare = 0;
  // The adaptive strata estimator with rpv strata: its rays, recorded once.
  AmbientOptions strata;
  strata.raysPerVertex = rpv;
  strata.batch = BatchMode::Single;
  strata.mergeDuplicates = false;
  strata.skipOpenVertices = false;  // every vertex casts, as in the loops above
  strata.estimator = AOEstimator::Strata;
  std::vector<RTCRay> strataRays;
  {
    auto caster = makeEmbreeCaster(s, BatchMode::Single);
    RecordingCaster rec(*caster);
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    computeAmbient(s, rec, strata);
    strataRays.swap(rec.rays);
  }
  auto bareLoop = [&](RTCScene scene, const std::vector<RTCRay>& from = {}) {
    std::vector<RTCRay> work = from.empty() ? rays : from;
    Timer t;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, work.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (size_t k = r.begin(); k < r.end(); ++k) rtcOccluded1(scene, &ctx, &work[k]);
    });
    const double sec = t.seconds();
    occludedBare = size_t(std::count_if(work.begin(), work.end(), [](const RTCRay& r) { return r.tfar < 0.f; }));
    return sec;
  };
  for (int rep_i = 0; rep_i < repeats; ++rep_i) {
    tBare.push_back(bareLoop(bare.scene));
    tBareRobust.push_back(bareLoop(bareRobust.scene));
    for (auto [mode, out] : {std::pair{BatchMode::Packet8, &tOurs}, std::pair{BatchMode::Single, &tOursSingle},
                             std::pair{BatchMode::Stream, &tOursStream}}) {
      auto caster = makeEmbreeCaster(s, mode);
      AmbientOptions o;
      o.raysPerVertex = rpv;
      o.batch = mode;
      o.mergeDuplicates = false;
      AmbientResult res = computeAmbient(s, *caster, o);
      out->push_back(res.stats.get("rays") / res.stats.get("rays_per_second"));
    }
    // The shared estimator casts the same rays (its per-vertex prefix); its
    // rays per second count the casting only (pooling is reported apart).
    auto caster = makeEmbreeCaster(s, BatchMode::Single);
    AmbientOptions o;
    o.raysPerVertex = rpv;
    o.batch = BatchMode::Single;
    o.mergeDuplicates = false;
    o.estimator = AOEstimator::Shared;
    AmbientResult res = computeAmbient(s, *caster, o);
    sharedRays = res.stats.get("rays");
    tShared.push_back(sharedRays / res.stats.get("rays_per_second"));
    tSharedPooling.push_back(tShared.back() + res.stats.get("pooling_seconds"));
    // Adaptive strata: its casting time (direction generation and split
    // decisions included) against the bare loop over its own rays.
    const AmbientResult st = computeAmbient(s, *caster, strata);
    tStrata.push_back(st.stats.get("rays") / st.stats.get("rays_per_second"));
    tStrataBare.push_back(bareLoop(bareRobust.scene, strataRays));
  }
  const double n = double(rays.size());
  std::printf("{\"mesh\": \"%s\", \"vertices\": %zu, \"faces\": %zu, \"rays\": %.0f, \"occluded_fraction\": %.6f,\n"
              " \"bare_embree_occluded1_rays_per_second\": %.6g, \"bare_embree_robust_occluded1_rays_per_second\": %.6g,\n"
              " \"ours_packet8_rays_per_second\": %.6g, \"ours_single_rays_per_second\": %.6g, \"ours_stream_rays_per_second\": %.6g,\n"
              " \"ratio_ours_packet8_to_bare\": %.4f, \"ratio_ours_single_to_bare\": %.4f, \"ratio_ours_stream_to_bare\": %.4f,\n"
              " \"ratio_ours_single_to_bare_robust\": %.4f, \"ours_shared_rays_per_second\": %.6g,\n"
              " \"ratio_ours_shared_to_bare\": %.4f, \"ratio_ours_shared_to_bare_robust\": %.4f,\n"
              " \"ours_shared_with_pooling_rays_per_second\": %.6g, \"ratio_ours_shared_with_pooling_to_bare_robust\": %.4f,\n"
              " \"strata_rays\": %.0f, \"ours_strata_rays_per_second\": %.6g, \"bare_embree_robust_strata_rays_per_second\": %.6g,\n"
              " \"ratio_ours_strata_to_bare_robust\": %.4f, \"repeats\": %d}\n",
              argv[1], nv, s.faceCount(), n, double(occludedBare) / n, n / median(tBare), n / median(tBareRobust), n / median(tOurs),
              n / median(tOursSingle), n / median(tOursStream), median(tBare) / median(tOurs),
              median(tBare) / median(tOursSingle), median(tBare) / median(tOursStream),
              median(tBareRobust) / median(tOursSingle), sharedRays / median(tShared),
              median(tBare) / median(tShared) * sharedRays / n, median(tBareRobust) / median(tShared) * sharedRays / n,
              sharedRays / median(tSharedPooling), median(tBareRobust) / median(tSharedPooling) * sharedRays / n,
              double(strataRays.size()), double(strataRays.size()) / median(tStrata),
              double(strataRays.size()) / median(tStrataBare), median(tStrataBare) / median(tStrata), repeats);
  return 0;
}
