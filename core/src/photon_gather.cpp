// The final gather of the photon map (Jensen 1996) with its near hits relit,
// and the vertices where the k-nearest estimate hands over to it.
//
// The gather's estimate at a vertex x with normal n is the mean over N
// cosine-weighted rays of the reflected radiosity rho(y) H(y) where they land,
//   H_indirect(x) ~ (1/N) sum_j rho(y_j) H(y_j),
// H(y) the density estimate of the photon map at y (all photons but those of
// each path's last allowed hit: the gather adds that reflection). That
// estimate spreads what lands on y's surface over the sphere of radius r(y)
// around y: where the ray is shorter than r(y) the vertex itself lies in the
// region the estimate blurs, and it reads its own surroundings' average,
// not the point's. At the foot of a block, a floor point's sphere reaches
// under the block, where no photon lands: it reads too dark, and a vertex
// there (half of whose rays land within a few centimetres) read 35-42% low
// in the Cornell box. So at such a near hit (t < r(y)) the hit is relit, as
// the radiosity filter's final gather relights its near hits
// (radiosity_vertices.cpp):
//   H(y) = H_direct(y) + H_caustic(y) + rho(z) H(z),
// the direct light by light sampling at y itself (the area lights, the point
// or spot light, the sky and the sun), the caustic photons read at y, and
// the rest from one cosine ray from y to z, read from the photons with two
// or more hits left (one reflection at z, one at y, one at x: max_depth
// stays exact). One ray a near hit is enough: a vertex averages many. A far
// hit reads H(y) with its direct part by light sampling at y as well: the
// direct photons' estimate blurs a shadow edge the vertex sees. The
// estimates the rays read are kept at a subset of the photons (below).
#include <algorithm>
#include <atomic>
#include <memory>
#include <optional>

#include "gi/color.h"
#include "gi/emitters.h"
#include "gi/sampling.h"
#include "gi/scene_setup.h"
#include "gi/vertex_graph.h"
#include "hit_origin.h"
#include "photon_internal.h"
#include "photon_map.h"
#include "photon_surface.h"
#include "point_cloud.h"

namespace gi {

std::unique_ptr<PhotonMap> gatherMap(const std::vector<Photon>& photons, const GatherSurface& surface,
                                     const std::vector<uint8_t>& hitsLeft) {
  return std::make_unique<PhotonMap>(photons, 7u, surface, &hitsLeft);
}

void appendEveryNth(const std::vector<Photon>& photons, const std::vector<uint8_t>& left, size_t stride, float scale,
                    std::vector<Photon>& out, std::vector<uint8_t>& outLeft) {
  out.reserve(out.size() + photons.size() / stride + 1);
  outLeft.reserve(outLeft.size() + photons.size() / stride + 1);
  for (size_t i = 0; i < photons.size(); i += stride) {
    const Photon& p = photons[i];
    out.push_back({p.p, p.power * scale, p.n, p.path});
    outLeft.push_back(left[i]);
  }
}

namespace {

// Irradiance kept at every `stride`-th photon of the map (precomputed in
// Christensen 1999, "Faster Photon Map Global Illumination"; here computed
// at a site's first reading and kept): a gather ray then reads
// the nearest such site on its side instead of searching k photons, which
// made a final gather cost about 2.6 ms a vertex at 64 rays (a 100k-triangle
// scan room) where the sites cost one estimate each, once. With k photons an
// estimate's disk holds about k / stride sites, so the nearest lies well
// inside the radius over which the estimate is already an average.
// The estimates count only the photons that are not sites, their power
// times stride / (stride - 1) (stride >= 2). Choosing the site nearest to
// a ray's hit says that no site lies in the ball between them, and a site
// there is a photon missing near the site: counting the sites made the
// estimates (k - 1) / k times the density, -25% at k = 4, with the site's
// own photon counted on top (k - 1) / (k - 2) times it less that, and
// infinite at k = 1 (a photon at distance 0; found 5 December 2026). The
// photons that are not sites are independent of where the sites lie (the
// sites are every stride-th photon of the map, in the order of their
// paths, not of their places), so their estimate has no such bias: a
// furnace's gathered light within 0.5% at k = 4 and 8
// (PhotonMap.SmallKHasNoBias).
class SiteIrradiance {
 public:
  struct Site {
    glm::vec3 H{0.f}, caustic{0.f}, direct{0.f}, two{0.f};  // all photons, the caustic ones, the direct ones,
                                                             // those with 2 or more hits left
    float radius = 0.f;
    int used = 0;  // photons the estimate read
  };
  // Sites every `stride`-th photon (at least every second).
  SiteIrradiance(const PhotonMap& all, int k, float r2max, size_t stride)
      : all_(all), k_(k), r2max_(r2max), stride_(std::max<size_t>(stride, 2)),
        scale_(float(stride_) / float(stride_ - 1)) {
    const size_t n = (all.size() + stride_ - 1) / stride_;
    cloud_.pts.resize(n);
    normal_.resize(n);
    sites_.resize(n);
    state_ = std::make_unique<std::atomic<uint8_t>[]>(n);
    for (size_t i = 0; i < n; ++i) {
      const Photon& ph = all.photon(i * stride_);
      cloud_.pts[i] = ph.p;
      normal_[i] = ph.n;
      state_[i].store(0, std::memory_order_relaxed);
    }
    tree_ = std::make_unique<PointTree>(3, cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tree_->buildIndex();
  }
  // The estimate at site i, computed at its first reading (a site no ray
  // reads costs nothing); the same value whichever thread computes it.
  Site site(size_t i) const {
    if (state_[i].load(std::memory_order_acquire) == 2) return sites_[i];
    const Photon& ph = all_.photon(i * stride_);
    const Site st = estimate(ph.p, ph.normal(), true);
    uint8_t empty = 0;
    if (state_[i].compare_exchange_strong(empty, 1, std::memory_order_acq_rel)) {
      sites_[i] = st;
      state_[i].store(2, std::memory_order_release);
    }
    return st;
  }
  size_t size() const { return sites_.size(); }
  // The estimate at y (normal n) from the photons that are not sites;
  // `widen`: search past the 2k nearest while fewer than k are on n's side.
  Site estimate(const glm::vec3& y, const glm::vec3& n, bool widen) const {
    Site st;
    glm::vec3 parts[kPathKinds] = {glm::vec3(0.f), glm::vec3(0.f), glm::vec3(0.f)};
    PhotonOnly rest;
    rest.widen = widen;
    rest.skipEvery = uint32_t(stride_);
    st.H = scale_ * all_.irradiance(y, n, k_, r2max_, PhotonKernel::Uniform, nullptr, &st.used, parts, rest,
                                    &st.radius, &st.two);
    st.caustic = scale_ * parts[kCausticPhoton];
    st.direct = scale_ * parts[kDirectPhoton];
    st.two *= scale_;
    return st;
  }
  // The nearest site to y whose photon arrived within 60 degrees of n, among
  // the 16 nearest, if y lies within half its estimate's radius; none if
  // none. Where photons are sparse (a room lit through a window by the sun
  // alone) the nearest site may lie metres away in the lit patch, and its
  // estimate is not y's: read regardless of distance, the gathered light of
  // such a room came out 23% high at 200,000 photons and the vertices
  // handed over to the gather 28% high at 1M (an outside audit, 5 December
  // 2026). In a dense map the nearest site lies at about sqrt(stride / k)
  // of the radius, a third of it.
  std::optional<Site> nearest(const glm::vec3& y, const glm::vec3& n) const {
    if (sites_.empty()) return std::nullopt;
    const float p[3] = {y.x, y.y, y.z};
    uint32_t idx[16];
    float d2[16];
    // The 4 nearest first (where most rays find their site), then 16.
    for (size_t want : {size_t(4), size_t(16)}) {
      const size_t found = tree_->knnSearch(p, std::min(want, sites_.size()), idx, d2);
      for (size_t m = 0; m < found; ++m)
        if (glm::dot(unpackNormal(normal_[idx[m]]), n) >= kSameSide) {
          const Site s = site(idx[m]);
          if (d2[m] <= kSiteReach * kSiteReach * s.radius * s.radius) return s;
          return std::nullopt;
        }
      if (found < want) break;
    }
    return std::nullopt;
  }
  static constexpr float kSiteReach = 0.5f;

 private:
  const PhotonMap& all_;
  int k_;
  float r2max_;
  size_t stride_;
  float scale_;
  PointCloud cloud_;
  std::vector<glm::i8vec3> normal_;
  mutable std::vector<Site> sites_;
  std::unique_ptr<std::atomic<uint8_t>[]> state_;  // 0 not computed, 1 being stored, 2 stored
  std::unique_ptr<PointTree> tree_;
};

}  // namespace

std::vector<glm::vec3> gatherPhotonMap(const PhotonRun& r, const PhotonMap& all, const std::vector<uint8_t>* only,
                                       const std::function<void(int)>& count, size_t* nearHits,
                                       const Progress& progress, std::vector<double>* variance) {
  const Scene& s = r.s;
  const PhotonOptions& opt = r.opt;
  const DirectLightAt directAt(s, r.caster, 4);
  const std::vector<glm::vec3> faceN = unitFaceNormals(s);
  const SiteIrradiance sites(all, opt.kNearest, r.r2max, size_t(std::max(1, opt.kNearest / 8)));
  std::atomic<size_t> relit{0};
  // A point's estimate: the nearest site's, or (none on this side near it) its own.
  const auto at = [&](const glm::vec3& y, const glm::vec3& n) {
    if (const std::optional<SiteIrradiance::Site> site = sites.nearest(y, n)) return *site;
    return sites.estimate(y, n, false);
  };
  const auto value = [&](const PhotonGatherHit& g) -> glm::vec3 {
    const SiteIrradiance::Site e = at(g.point, g.normal);
    count(e.used);
    // max_depth 0: no reflection may be added at y.
    if (opt.maxDepth < 1) return s.faceRho(g.face) * e.H;
    // Eps off the face, on the ray's last leg near a corner (hit_origin.h).
    const glm::vec3 o = hitRayOrigin(r.caster, g.legOrigin, g.legDir, g.t, g.normal, r.eps, g.border);
    const glm::vec3 direct = directAt(g.point, o, g.normal, g.key) + pointLightIrradiance(opt.point, r.caster, g.point, o, g.normal) +
                             skySunIrradianceAt(opt.outside, r.caster, o, g.normal, 4, g.key);
    // A far hit: the photons' estimate, but for the direct light, taken at
    // y itself (the direct photons' estimate blurs a shadow edge over the
    // radius: a wall lit by a floor on which it casts the sun's shadow read
    // +10.6% on average, +19% near the floor; an outside audit).
    if (!(g.t < e.radius)) return s.faceRho(g.face) * (e.H - e.direct + direct);
    relit.fetch_add(1, std::memory_order_relaxed);
    glm::vec3 Hy = direct + e.caustic;
    Rng rng(hash3(g.key, 0x6eu, 0x2bu));
    Ray ray;
    ray.o = o;
    ray.d = Frame(g.normal).toWorld(cosineHemisphere({rng.next(), rng.next()}));
    const Hit h = r.caster.intersect(ray);
    if (h.valid() && s.faceMaterial(h.face) == Material::Diffuse && glm::dot(ray.d, faceN[h.face]) < 0.f)
      Hy += s.faceRho(h.face) * at(ray.o + ray.d * h.t, faceN[h.face]).two;
    return s.faceRho(g.face) * Hy;
  };
  std::vector<glm::vec3> H =
      specularFinalGather(s, r.caster, r.mat, r.origins, opt.gatherRays, opt.seed ^ 0x6au, r.eps, value, only, progress,
                          variance);
  if (variance) {
    // The variance from at least the mean of the gathered neighbours' (two
    // rings): where most of a vertex's rays miss a small bright patch, their
    // spread says little. A spot on the Cornell box's tall block lit the
    // ceiling through it: at 64 rays 31 to 42 of 829 vertices off the edges
    // lay beyond 3 standard errors of the reference (z down to -13.6; an
    // outside audit).
    std::vector<uint8_t> gathered(s.vertexCount(), 0);
    // (A black vertex's B = E has no reflected light and no error to take.)
    for (size_t v = 0; v < gathered.size(); ++v)
      gathered[v] = (!only || (*only)[v]) && r.mat.valid[v] && luminance(r.mat.rho[v]) > 0.f;
    atLeastRingMean(VertexGraph::build(s), gathered, *variance);
  }
  if (nearHits) *nearHits = relit.load();
  return H;
}

// The caustic photons vertex i sees (PhotonOnly::visibleFrom).
PhotonOnly seenFrom(const PhotonRun& r, size_t i) {
  PhotonOnly o;
  o.visibleFrom = &r.caster;
  o.from = r.origins[i];
  o.eps = r.eps;
  o.widen = false;  // the 2k nearest at most, each one ray (a widening search cast them again each round)
  return o;
}

bool handsOver(const PhotonRun& r, const GatherSurface& surface, const std::vector<uint8_t>& crease, size_t i,
               float radius, bool& atCrease) {
  const float cosCrease = float(std::cos(kCreaseDegrees * M_PI / 180.0));
  atCrease = !crease.empty() && crease[i];
  return atCrease ||
         surface.otherSurfaceWithin(r.s.positions[i], r.mat.n[i], radius, surface.vertexSheet(i), cosCrease);
}

// Density estimates at the vertices: the global map there with k_nearest
// photons (or the final gather reading `all` everywhere), plus the caustic
// map with caustic_k; counts the estimates that held some or only a few
// photons. With the direct light apart, the k-nearest mode hands a vertex
// over to the final gather where the density estimate tells another
// quantity than the vertex's value: at a crease (creaseVertices), and
// where another surface rises inside the estimate's radius
// (GatherSurface::otherSurfaceWithin). `all` is built for them if needed.
PhotonEstimate estimateAtVertices(const PhotonRun& r, PhotonMaps& m, const std::vector<Photon>& photons,
                                  const GatherSurface& surface, const std::vector<uint8_t>& hitsLeft,
                                  const std::vector<uint8_t>& crease, HandOver& ho, const Progress& progress) {
  const Scene& s = r.s;
  const PhotonOptions& opt = r.opt;
  const size_t nv = s.vertexCount();
  PhotonEstimate e;
  e.H.assign(nv, glm::vec3(0.f));
  e.noise.assign(nv, 0.0);
  const bool split = opt.lightPathSplit;
  if (split)
    for (auto& h : e.byPath) h.assign(nv, glm::vec3(0.f));
  std::atomic<size_t> some{0}, few{0};
  auto count = [&](int used) {
    if (used > 0) some.fetch_add(1, std::memory_order_relaxed);
    if (used > 0 && used < kFewPhotons) few.fetch_add(1, std::memory_order_relaxed);
  };
  const bool gatherAll = !m.global;
  const bool handOver = !gatherAll && opt.directLight;
  ho.at.assign(nv, gatherAll ? 1 : 0);
  std::atomic<size_t> creases{0}, others{0};
  parallelBlocks(nv, progress.sub(0.0, gatherAll ? 0.1 : 0.6), "density estimation", [&](size_t b, size_t end) {
    for (size_t i = b; i < end; ++i) {
      if (!r.mat.valid[i]) continue;
      double e1 = 0, e2 = 0;  // the noise of the luminance of rho H, B's (w: rho times the luminance weights)
      const glm::vec3 w = r.mat.rho[i] * glm::vec3(kLuminanceWeights);
      // The terms by path kind: a final gather's photons lie one diffuse
      // bounce beyond the vertex (all indirect); a map's by their tag.
      glm::vec3 parts[kPathKinds] = {glm::vec3(0.f), glm::vec3(0.f), glm::vec3(0.f)};
      glm::vec3* byPath = split ? parts : nullptr;
      glm::vec3 H(0.f);
      PhotonOnly causticOnly;  // beside another surface: the caustic photons the vertex sees
      if (!gatherAll) {
        int used = 0;
        float radius = 0.f;
        H = m.global->irradiance(s.positions[i], r.mat.n[i], opt.kNearest, r.r2max, PhotonKernel::Uniform, &e1,
                                 &used, byPath, PhotonOnly(), &radius, nullptr, w);
        bool atCrease = false;
        if (handOver) {
          if (handsOver(r, surface, crease, i, radius, atCrease)) {
            ho.at[i] = 1;
            causticOnly = seenFrom(r, i);
            (atCrease ? creases : others).fetch_add(1, std::memory_order_relaxed);
            // The gather's light takes the global map's place (all indirect with the direct light apart).
            H = glm::vec3(0.f);
            parts[kPathIndirect] = glm::vec3(0.f);
            e1 = 0;
          } else {
            count(used);
          }
        } else {
          count(used);
        }
      }
      if (m.caustics)
        H += m.caustics->irradiance(s.positions[i], r.mat.n[i], opt.causticK, r.r2max, PhotonKernel::Cone, &e2,
                                    nullptr, byPath, causticOnly, nullptr, nullptr, w);
      if (split)
        for (int k = 0; k < kPathKinds; ++k) e.byPath[k][i] = parts[k];
      e.H[i] = H;
      e.noise[i] = std::sqrt(e1 * e1 + e2 * e2);
    }
  });
  ho.crease = creases.load();
  ho.otherSurface = others.load();
  if (gatherAll || ho.crease + ho.otherSurface > 0) {
    Timer bt;
    if (!m.all) {
      // The hand-over's gather reads a map of kPpmGatherPaths paths' photons
      // at most (every stride-th photon at stride times its power: the same
      // density), as progressive photon mapping's does: its error is the
      // gather rays' noise, not the map's (the same errors with 1 to 10
      // times the photons), and a map of every photon of a large run cost
      // as much again as the run's own map (3M paths on the Cornell box:
      // 4.8 s of kd-trees against 1.7 s).
      const size_t stride = gatherMapStride(size_t(opt.photons));
      if (stride > 1) {
        m.thinnedStride = stride;
        appendEveryNth(photons, hitsLeft, stride, float(stride), m.thinned, m.thinnedLeft);
        m.all = gatherMap(m.thinned, surface, m.thinnedLeft);
        m.bytes += m.thinned.capacity() * sizeof(Photon) + m.thinnedLeft.capacity();
      } else {
        m.all = gatherMap(photons, surface, hitsLeft);
      }
      m.bytes += m.all->memoryBytes();
    }
    ho.buildSeconds = bt.seconds();
    Timer gt;
    std::vector<double> variance;
    const std::vector<glm::vec3> gathered =
        gatherPhotonMap(r, *m.all, &ho.at, count, &ho.nearHits, progress.sub(gatherAll ? 0.1 : 0.6, 1.0), &variance);
    ho.gatherSeconds = gt.seconds();
    for (size_t i = 0; i < nv; ++i) {
      if (!ho.at[i] || !r.mat.valid[i]) continue;
      e.H[i] += gathered[i];
      // The gather's own noise joins the caustic map's (until 5 December
      // 2026 these vertices reported 0: an error map read their z-scores as
      // exact; an outside audit).
      e.noise[i] = std::sqrt(e.noise[i] * e.noise[i] + variance[i]);
      if (split) e.byPath[kPathIndirect][i] = gathered[i];
    }
  }
  for (size_t i = 0; i < nv; ++i)
    if (r.mat.valid[i] && luminance(e.H[i]) <= 0.f) ++e.verticesWithoutPhotons;
  e.check.estimates = some.load();
  e.check.fewEstimates = few.load();
  return e;
}

}  // namespace gi
