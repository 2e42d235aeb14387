// Embree 3 implementation of RayCaster: move-only RAII handles, the error
// callback installed before anything else, primitives limited to usable faces.
#include <embree3/rtcore.h>

#include <algorithm>
#include <memory>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "face_twins.h"
#include "gi/raycaster.h"
#include "gi/scene.h"

namespace gi {
namespace {

// Lanes 0..m-1 of an 8-wide packet from rays[0..m-1]; the others repeat ray 0
// and are masked off in `valid`.
void toPacket8(const Ray* rays, size_t m, RTCRay8& p, int* valid) {
  for (size_t i = 0; i < 8; ++i) {
    const Ray& r = rays[i < m ? i : 0];
    valid[i] = i < m ? -1 : 0;
    p.org_x[i] = r.o.x; p.org_y[i] = r.o.y; p.org_z[i] = r.o.z; p.tnear[i] = r.tnear;
    p.dir_x[i] = r.d.x; p.dir_y[i] = r.d.y; p.dir_z[i] = r.d.z; p.time[i] = 0.f;
    p.tfar[i] = r.tfar; p.mask[i] = 0xffffffffu; p.id[i] = 0; p.flags[i] = 0;
  }
}


struct ErrorSink {
  std::mutex m;
  std::string first;
};

void onEmbreeError(void* user, RTCError code, const char* str) {
  auto* sink = static_cast<ErrorSink*>(user);
  std::lock_guard<std::mutex> lock(sink->m);
  if (sink->first.empty()) sink->first = "Embree error " + std::to_string(int(code)) + ": " + (str ? str : "");
}

class Device {
 public:
  explicit Device(ErrorSink* sink) : d_(rtcNewDevice(nullptr)) {
    if (!d_) throw std::runtime_error("Embree: cannot create a device (" + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(d_, onEmbreeError, sink);
  }
  ~Device() { if (d_) rtcReleaseDevice(d_); }
  Device(Device&& o) noexcept : d_(std::exchange(o.d_, nullptr)) {}
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;
  RTCDevice get() const { return d_; }
 private:
  RTCDevice d_;
};

class SceneHandle {
 public:
  explicit SceneHandle(RTCDevice d) : s_(rtcNewScene(d)) {}
  ~SceneHandle() { if (s_) rtcReleaseScene(s_); }
  SceneHandle(SceneHandle&& o) noexcept : s_(std::exchange(o.s_, nullptr)) {}
  SceneHandle(const SceneHandle&) = delete;
  SceneHandle& operator=(const SceneHandle&) = delete;
  RTCScene get() const { return s_; }
 private:
  RTCScene s_;
};

// Embree asserts (aborting the process) on a ray it cannot represent: a NaN
// or infinite origin or direction, coordinates beyond FLT_LARGE (1.844e18),
// or a NaN tnear or tfar. No ray of a sound computation is like that (scenes
// are in local units, Scene::unit), so meeting one is an error to report,
// never a reason to abort MeshLab.
constexpr float kFltLarge = 1.844e18f;
// The largest local coordinate a scene may have: far above any scene built by
// Scene::fromAbsolute, far below where the squares of lengths overflow a float.
constexpr float kMaxLocalCoordinate = 1099511627776.f;  // 2^40
inline bool representable(const glm::vec3& o, const glm::vec3& d) {
  return std::fabs(o.x) <= kFltLarge && std::fabs(o.y) <= kFltLarge && std::fabs(o.z) <= kFltLarge &&
         std::fabs(d.x) <= kFltLarge && std::fabs(d.y) <= kFltLarge && std::fabs(d.z) <= kFltLarge;
}
inline void checkRay(const glm::vec3& o, const glm::vec3& d, float tnear, float tfar) {
  if (!representable(o, d) || std::isnan(tnear) || std::isnan(tfar))
    throw std::runtime_error("a ray with a non-finite or out-of-range origin or direction (a numerical failure, "
                             "perhaps at this scene's scale): the computation was stopped");
}
inline void checkRay(const Ray& r) { checkRay(r.o, r.d, r.tnear, r.tfar); }

inline void toRTC(const Ray& r, RTCRay& e) {
  e.org_x = r.o.x; e.org_y = r.o.y; e.org_z = r.o.z; e.tnear = r.tnear;
  e.dir_x = r.d.x; e.dir_y = r.d.y; e.dir_z = r.d.z; e.time = 0.f;
  e.tfar = r.tfar; e.mask = 0xffffffffu; e.id = 0; e.flags = 0;
}

class EmbreeCaster final : public RayCaster {
 public:
  size_t sceneFaces() const override { return faceCount_; }
  EmbreeCaster(const Scene& s, BatchMode mode) : device_(&errors_), scene_(device_.get()), mode_(mode) {
    check("creating the scene");
    const auto ok = usableFaceMask(s);
    for (size_t f = 0; f < ok.size(); ++f)
      if (ok[f]) primToFace_.push_back(uint32_t(f));
    // With every face usable, a primitive is its face: no lookup (a cache
    // miss per hit on a large mesh).
    identity_ = primToFace_.size() == s.faceCount();
    faceCount_ = s.faceCount();
    if (!primToFace_.empty()) {
      // The buffers are ours (std::vector: large ones go to huge pages in
      // the tool, gi/huge_pages.h), shared with Embree for the scene's
      // life; the vertices padded so that the last one can be read with a
      // 16-byte load, as Embree requires.
      vertices_.assign(3 * s.positions.size() + 4, 0.f);
      indices_.resize(3 * primToFace_.size());
      float* vb = vertices_.data();
      uint32_t* ib = indices_.data();
      // Only the vertices the built faces use are the scene's (a stray one
      // no face uses, at 2e12, refused every ray-casting filter with this
      // sentence; an outside audit): the others are written as 0, unread.
      std::vector<uint8_t> used(s.positions.size(), 0);
      for (uint32_t f : primToFace_) used[s.triangles[f].x] = used[s.triangles[f].y] = used[s.triangles[f].z] = 1;
      float extent = 0.f;
      for (size_t i = 0; i < s.positions.size(); ++i) {
        const auto& p = s.positions[i];
        const bool fin = used[i] && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
        vb[3 * i] = fin ? p.x : 0.f; vb[3 * i + 1] = fin ? p.y : 0.f; vb[3 * i + 2] = fin ? p.z : 0.f;
        if (fin) extent = std::max({extent, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
      }
      // Scene::fromAbsolute keeps local coordinates within about 2^21; a
      // scene filled directly with world coordinates of 1e30 would overflow
      // the squared lengths of rays and light samples (inf, then NaN or
      // undefined conversions). Refused here, before any algorithm uses it.
      if (extent > kMaxLocalCoordinate) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "the scene's coordinates reach %.3g local units, beyond the %.3g rays can "
                      "represent: a scene is built in local units (Scene::fromAbsolute)", double(extent),
                      double(kMaxLocalCoordinate));
        throw std::runtime_error(buf);
      }
      for (size_t k = 0; k < primToFace_.size(); ++k) {
        const auto& t = s.triangles[primToFace_[k]];
        ib[3 * k] = t.x; ib[3 * k + 1] = t.y; ib[3 * k + 2] = t.z;
      }
      RTCGeometry g = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vb, 0, 3 * sizeof(float),
                                 s.positions.size());
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, ib, 0, 3 * sizeof(uint32_t),
                                 primToFace_.size());
      rtcCommitGeometry(g);
      rtcAttachGeometry(scene_.get(), g);
      rtcReleaseGeometry(g);
    }
    // Robust (watertight) traversal: rays through a shared edge or vertex never
    // slip between two triangles, which would leak light into closed rooms
    // (measured without it: 166 of 1.92M AO rays escape a box of six walls,
    // README). No build quality is set: Embree 3 builds a robust scene with
    // its binned SAH builder whatever the quality asked (spatial splits, the
    // high quality, exist only for its non-robust layout).
    rtcSetSceneFlags(scene_.get(), RTC_SCENE_FLAG_ROBUST);
    rtcCommitScene(scene_.get());
    check("building the BVH");
  }

  Hit intersect(const Ray& r) const override {
    checkRay(r);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    toRTC(r, rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_.get(), &ctx, &rh);
    Hit h;
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
      h.t = rh.ray.tfar; h.face = faceOf(rh.hit.primID); h.u = rh.hit.u; h.v = rh.hit.v;
      h.ng = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
      front(rh.hit.primID, r.d, h);
    }
    return h;
  }

  bool occluded(const Ray& r) const override {
    checkRay(r);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay e;
    toRTC(r, e);
    rtcOccluded1(scene_.get(), &ctx, &e);
    return e.tfar < 0.f;
  }

  void occludedFan(const glm::vec3& o, const glm::vec3* dirs, size_t n, float tfar, uint8_t* occ) const override {
    if (mode_ != BatchMode::Single) return RayCaster::occludedFan(o, dirs, n, tfar, occ);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay e;
    e.org_x = o.x; e.org_y = o.y; e.org_z = o.z; e.tnear = 0.f; e.time = 0.f; e.mask = 0xffffffffu; e.id = 0; e.flags = 0;
    for (size_t i = 0; i < n; ++i) {
      checkRay(o, dirs[i], 0.f, tfar);
      e.dir_x = dirs[i].x; e.dir_y = dirs[i].y; e.dir_z = dirs[i].z; e.tfar = tfar;
      rtcOccluded1(scene_.get(), &ctx, &e);
      occ[i] = e.tfar < 0.f ? 1 : 0;
    }
  }

  // Coherent rays (a tile of primary rays): Embree's 8-wide packets or its
  // stream interface (rtcIntersect1M), both told the rays are coherent.
  // bench/render_bench.py measures the three modes.
  void intersectBatch(const Ray* rays, size_t n, Hit* hits) const override {
    if (mode_ == BatchMode::Single) return RayCaster::intersectBatch(rays, n, hits);
    for (size_t i = 0; i < n; ++i) checkRay(rays[i]);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    auto hitOf = [&](const Ray& ray, unsigned geomID, unsigned primID, float t, float u, float v, float nx, float ny,
                     float nz) {
      Hit h;
      if (geomID != RTC_INVALID_GEOMETRY_ID) {
        h.t = t; h.face = faceOf(primID); h.u = u; h.v = v;
        h.ng = {nx, ny, nz};
        front(primID, ray.d, h);
      }
      return h;
    };
    if (mode_ == BatchMode::Stream) {
      constexpr size_t kChunk = 64;
      RTCRayHit buf[kChunk];
      for (size_t b = 0; b < n; b += kChunk) {
        const size_t m = std::min(kChunk, n - b);
        for (size_t i = 0; i < m; ++i) {
          toRTC(rays[b + i], buf[i].ray);
          buf[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
          buf[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect1M(scene_.get(), &ctx, buf, unsigned(m), sizeof(RTCRayHit));
        for (size_t i = 0; i < m; ++i) {
          const RTCRayHit& r = buf[i];
          hits[b + i] = hitOf(rays[b + i], r.hit.geomID, r.hit.primID, r.ray.tfar, r.hit.u, r.hit.v, r.hit.Ng_x, r.hit.Ng_y, r.hit.Ng_z);
        }
      }
      return;
    }
    alignas(32) RTCRayHit8 p;
    alignas(32) int valid[8];
    for (size_t b = 0; b < n; b += 8) {
      const size_t m = std::min<size_t>(8, n - b);
      toPacket8(rays + b, m, p.ray, valid);
      for (size_t i = 0; i < 8; ++i) {
        p.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        p.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect8(valid, scene_.get(), &ctx, &p);
      for (size_t i = 0; i < m; ++i)
        hits[b + i] = hitOf(rays[b + i], p.hit.geomID[i], p.hit.primID[i], p.ray.tfar[i], p.hit.u[i], p.hit.v[i], p.hit.Ng_x[i],
                            p.hit.Ng_y[i], p.hit.Ng_z[i]);
    }
  }

  void occludedBatch(const Ray* rays, size_t n, uint8_t* occ) const override {
    if (mode_ == BatchMode::Single) return RayCaster::occludedBatch(rays, n, occ);
    for (size_t i = 0; i < n; ++i) checkRay(rays[i]);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    if (mode_ == BatchMode::Stream) {
      constexpr size_t kChunk = 64;
      RTCRay buf[kChunk];
      for (size_t b = 0; b < n; b += kChunk) {
        const size_t m = std::min(kChunk, n - b);
        for (size_t i = 0; i < m; ++i) toRTC(rays[b + i], buf[i]);
        rtcOccluded1M(scene_.get(), &ctx, buf, unsigned(m), sizeof(RTCRay));
        for (size_t i = 0; i < m; ++i) occ[b + i] = buf[i].tfar < 0.f ? 1 : 0;
      }
      return;
    }
    alignas(32) RTCRay8 p;
    alignas(32) int valid[8];
    for (size_t b = 0; b < n; b += 8) {
      const size_t m = std::min<size_t>(8, n - b);
      toPacket8(rays + b, m, p, valid);
      rtcOccluded8(valid, scene_.get(), &ctx, &p);
      for (size_t i = 0; i < m; ++i) occ[b + i] = p.tfar[i] < 0.f ? 1 : 0;
    }
  }

 private:
  void check(const char* what) {
    std::lock_guard<std::mutex> lock(errors_.m);
    if (!errors_.first.empty()) throw std::runtime_error(errors_.first + " (while " + what + ")");
  }
  ErrorSink errors_;  // outlives the device (declared first)
  Device device_;
  std::vector<float> vertices_;    // shared with the scene: outlive it (declared before it)
  std::vector<uint32_t> indices_;
  SceneHandle scene_;
  BatchMode mode_;
  std::vector<uint32_t> primToFace_;
  bool identity_ = false;
  uint32_t faceOf(unsigned primID) const { return identity_ ? uint32_t(primID) : primToFace_[primID]; }
  // A hit on a face's back that has a reversed copy: the copy's front
  // (face_twins.h). The copies are found at the first hit from behind, so
  // that the filters whose rays never meet a back (ambient occlusion's
  // shadow rays) do not pay for the search.
  void front(unsigned primID, const glm::vec3& d, Hit& h) const {
    if (!(glm::dot(d, h.ng) > 0.f)) return;
    toFront(twins(), uint32_t(primID), d, h, [this](uint32_t p) { return faceOf(p); });
  }
  const FaceTwins& twins() const {
    std::call_once(twinsOnce_, [this] {
      // Isolated: while it waits for its parallel sort, this thread must not
      // take up another of the caller's rays (it would wait on itself here).
      tbb::this_task_arena::isolate([this] {
        auto t = std::make_unique<FaceTwins>(vertices_.data(), indices_.data(), primToFace_.size());
        // A search cut short by the caller's cancellation (an exception in
        // another ray's task) would miss copies for the caster's life: not
        // kept (call_once tries again at the next call).
        if (tbb::is_current_task_group_canceling()) throw std::runtime_error("the computation was cancelled");
        if (!identity_ && t->any()) {
          primOfFace_.assign(faceCount_, kNoHit);
          for (size_t k = 0; k < primToFace_.size(); ++k) primOfFace_[primToFace_[k]] = uint32_t(k);
        }
        twins_ = std::move(t);
      });
    });
    return *twins_;
  }
  mutable std::once_flag twinsOnce_;
  mutable std::unique_ptr<FaceTwins> twins_;
  mutable std::vector<uint32_t> primOfFace_;  // faces to primitives, where they differ and copies exist
  size_t faceCount_ = 0;

 public:
  uint32_t reversedCopy(uint32_t face) const override {
    const FaceTwins& t = twins();
    if (!t.any() || face >= faceCount_) return kNoHit;
    const uint32_t prim = identity_ ? face : primOfFace_[face];
    const uint32_t copy = prim == kNoHit ? kNoHit : t.twin(prim);
    return copy == kNoHit ? kNoHit : faceOf(copy);
  }
};

}  // namespace

std::unique_ptr<RayCaster> makeEmbreeCaster(const Scene& s, BatchMode mode) {
  return std::make_unique<EmbreeCaster>(s, mode);
}

}  // namespace gi
