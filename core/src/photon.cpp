#include "gi/photon.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include <nanoflann.hpp>
#include <tbb/parallel_for.h>

#include "gi/color.h"
#include "gi/emitters.h"
#include "gi/direct.h"
#include "gi/sampling.h"

namespace gi {

std::vector<ParamSpec> PhotonOptions::specs() {
  return {
      {"photons", "Photons emitted",
       "Number of photon paths shot from the emitters (in proportion to their power). More photons: less noise and "
       "blur; memory grows linearly (about 40 bytes per stored photon).",
       ParamType::Int, 200000, 1, 100000000},
      {"k_nearest", "Photons per estimate",
       "The radiance at a vertex is estimated from its k nearest photons on the same side of the surface: more "
       "photons mean less noise but more blur.",
       ParamType::Int, 64, 1, 512},
      {"max_radius", "Maximum gather radius",
       "Photons farther than this from a vertex are ignored (0 = no limit). Absolute or % of the bbox diagonal.",
       ParamType::Distance, 0.05, 0.0, 1.0},
      {"direct_light", "Direct light by light sampling",
       "Compute the direct light at each vertex exactly (point-to-triangle factors to the emitters with shadow rays: "
       "soft shadows, no photon noise) and use the photons only for the indirect light. Off: all light from the "
       "photon map (the classic noisy look).",
       ParamType::Bool, 1},
      {"light_samples", "Shadow rays per vertex", "Shadow rays for the direct light at each vertex.", ParamType::Int,
       256, 1, 1 << 20},
      {"final_gather", "Final gather",
       "Instead of reading the photon map at the vertex, cast cosine-weighted rays and read it where they land "
       "(Jensen's final gather): much smoother indirect light, at the cost of the rays.",
       ParamType::Bool, 0},
      {"gather_rays", "Final-gather rays per vertex", "Rays per vertex for the final gather.", ParamType::Int, 64, 1,
       1 << 20},
      {"max_depth", "Maximum bounces", "Paths end after this many diffuse bounces (Russian roulette ends most earlier).",
       ParamType::Int, 16, 1, 1000},
      seedSpec("photon paths"),
  };
}

PhotonOptions PhotonOptions::fromParams(const ParamValues& v) {
  PhotonOptions o;
  o.photons = v.getInt("photons");
  o.kNearest = v.getInt("k_nearest");
  o.maxRadius = v.getFloat("max_radius");
  o.maxDepth = v.getInt("max_depth");
  o.directLight = v.getBool("direct_light");
  o.lightSamples = v.getInt("light_samples");
  o.finalGather = v.getBool("final_gather");
  o.gatherRays = v.getInt("gather_rays");
  o.seed = uint32_t(v.getInt("seed"));
  return o;
}

std::vector<Photon> tracePhotons(const Scene& s, const RayCaster& caster, const PhotonOptions& opt,
                                 const Progress& progress, RunStats& stats) {
  const EmitterSampler lights(s);
  if (lights.empty())
    throw std::invalid_argument("the scene has no emitters: select the light's faces (or mark them by face quality) "
                                "and choose the matching 'Emitters' option");
  const float eps = float(analyzeScene(s).rayEpsilon);
  std::vector<glm::vec3> faceN(s.faceCount());
  for (size_t f = 0; f < s.faceCount(); ++f) {
    glm::vec3 n = faceNormalUnnormalized(s, f);
    const float l = glm::length(n);
    faceN[f] = l > 0.f ? n / l : glm::vec3(0.f, 0.f, 1.f);
  }
  // Fixed-size blocks, concatenated in order: the result is independent of threads.
  constexpr size_t kBlock = 4096;
  const size_t N = size_t(opt.photons);
  const size_t nBlocks = (N + kBlock - 1) / kBlock;
  std::vector<std::vector<Photon>> blocks(nBlocks);
  const double totalPower = lights.totalPower();
  std::vector<size_t> bounces(nBlocks, 0);
  parallelBlocks(nBlocks, progress, "tracing photons", [&](size_t b0, size_t b1) {
    for (size_t b = b0; b < b1; ++b) {
      auto& out = blocks[b];
      for (size_t i = b * kBlock; i < std::min(N, (b + 1) * kBlock); ++i) {
        // Emission: power-proportional point, cosine-distributed direction.
        const auto L = lights.sample(sobolOwen2D(uint32_t(i), hash32(opt.seed ^ 0x9e37u)));
        const glm::vec3 dir0 = Frame(L.n).toWorld(cosineHemisphere(sobolOwen2D(uint32_t(i), hash32(opt.seed ^ 0x51edu))));
        // Flux of one photon: E A / (p_face N) = E / (pdfArea N), per channel.
        glm::vec3 power = L.E / (L.pdfArea * float(N));
        Rng rng(hash3(uint32_t(i), opt.seed, 0x7u));
        Ray ray;
        ray.o = L.p + L.n * eps;
        ray.d = dir0;
        for (int depth = 0; depth < opt.maxDepth; ++depth) {
          const Hit h = caster.intersect(ray);
          if (!h.valid()) break;
          const glm::vec3 x = ray.o + ray.d * h.t;
          glm::vec3 n = faceN[h.face];
          if (glm::dot(n, ray.d) > 0.f) n = -n;  // the side the photon arrived on
          out.push_back({x, power, n, uint16_t(std::min(depth, 65535))});
          const glm::vec3 rho = s.faceRho(h.face);
          const float q = std::min(0.95f, std::max({rho.r, rho.g, rho.b}));
          if (!(q > 0.f) || rng.next() >= q) break;  // Russian roulette: absorbed
          power *= rho / q;
          ray.o = x + n * eps;
          ray.d = Frame(n).toWorld(cosineHemisphere({rng.next(), rng.next()}));
          ray.tnear = 0.f;
          ray.tfar = std::numeric_limits<float>::infinity();
          ++bounces[b];
        }
      }
    }
  });
  std::vector<Photon> all;
  size_t total = 0, nb = 0;
  for (size_t b = 0; b < nBlocks; ++b) { total += blocks[b].size(); nb += bounces[b]; }
  all.reserve(total);
  for (auto& b : blocks) all.insert(all.end(), b.begin(), b.end());
  stats.add("photons_emitted", double(N));
  stats.add("photons_stored", double(all.size()));
  stats.add("emitted_power_W", totalPower);
  stats.add("bounces", double(nb));
  return all;
}

namespace {

// A kd-tree (nanoflann) over a subset of the photons, with the density
// estimate: H(x) ~ sum_k Phi_k / (pi r_k^2) over the k nearest photons that
// arrived on the same side of the surface (a uniform disk kernel).
class PhotonMap {
 public:
  PhotonMap(const std::vector<Photon>& all, bool indirectOnly) : cloud_{all, {}} {
    for (uint32_t i = 0; i < all.size(); ++i)
      if (!indirectOnly || all[i].depth > 0) cloud_.idx.push_back(i);
    tree_ = std::make_unique<Tree>(3, cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    tree_->buildIndex();
  }
  size_t size() const { return cloud_.idx.size(); }
  // Irradiance at x (unit normal n); sumL2 gets the sum of squared photon luminances.
  glm::vec3 irradiance(const glm::vec3& x, const glm::vec3& n, int k, float r2max, double* poissonErr) const {
    const size_t kq = std::min(size(), size_t(k) * 2);  // more than k: photons on the other side are dropped
    if (kq == 0) return glm::vec3(0.f);
    uint32_t idx[1024];
    float d2[1024];
    const size_t want = std::min<size_t>(kq, 1024);
    const float q[3] = {x.x, x.y, x.z};
    const size_t found = tree_->knnSearch(q, want, idx, d2);
    glm::dvec3 sum(0.0);
    double sumL2 = 0.0;
    float r2 = 0.f;
    int used = 0;
    for (size_t m = 0; m < found && used < k; ++m) {
      if (d2[m] > r2max) break;
      const Photon& p = cloud_.all[cloud_.idx[idx[m]]];
      if (glm::dot(p.n, n) < 0.5f) continue;  // other side or another surface
      sum += glm::dvec3(p.power);
      sumL2 += double(luminance(p.power)) * luminance(p.power);
      r2 = d2[m];
      ++used;
    }
    if (used == 0) return glm::vec3(0.f);
    if (used < k && r2max < HUGE_VALF) r2 = r2max;  // sparse region: the whole disk was searched
    const double area = 3.14159265358979 * std::max(r2, 1e-30f);
    if (poissonErr) *poissonErr = std::sqrt(sumL2) / area;  // Poisson count noise of the estimate
    return glm::vec3(sum / area);
  }

 private:
  struct Cloud {
    const std::vector<Photon>& all;
    std::vector<uint32_t> idx;
    size_t kdtree_get_point_count() const { return idx.size(); }
    float kdtree_get_pt(size_t i, size_t d) const { return all[idx[i]].p[int(d)]; }
    template <class B> bool kdtree_get_bbox(B&) const { return false; }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3, uint32_t>;
  Cloud cloud_;
  std::unique_ptr<Tree> tree_;
};

}  // namespace

VertexRadiometry computePhotonMap(const Scene& s, const RayCaster& caster, const PhotonOptions& opt, const Progress& progress) {
  if (opt.photons < 1 || opt.kNearest < 1 || opt.kNearest > 512)
    throw std::invalid_argument("photons must be >= 1 and k_nearest in [1, 512]");
  Timer timer;
  VertexRadiometry out;
  std::vector<Photon> photons = tracePhotons(s, caster, opt, progress.sub(0.0, 0.5), out.stats);
  const double traceSeconds = timer.seconds();
  Timer buildTimer;
  // Vertices read the map of photons after at least one diffuse bounce when
  // the direct light is computed apart; the final gather reads all photons
  // at the points it hits (their direct light included).
  const PhotonMap vertexMap(photons, opt.directLight);
  std::unique_ptr<PhotonMap> gatherMap;
  if (opt.directLight && opt.finalGather) gatherMap = std::make_unique<PhotonMap>(photons, false);
  const double buildSeconds = buildTimer.seconds();
  const VertexMaterial mat = vertexMaterial(s);
  const size_t nv = s.vertexCount();
  out.B.assign(nv, glm::vec3(0.f));
  out.H.assign(nv, glm::vec3(0.f));
  out.stdError.assign(nv, 0.f);
  const float r2max = opt.maxRadius > 0 ? float(opt.maxRadius * opt.maxRadius) : HUGE_VALF;
  Timer directTimer;
  std::vector<glm::vec3> Hd;
  if (opt.directLight) Hd = vertexDirectIrradiance(s, caster, opt.lightSamples, opt.seed, progress.sub(0.5, 0.7));
  const double directSeconds = directTimer.seconds();
  std::vector<glm::vec3> faceN(s.faceCount());
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const glm::vec3 n = faceNormalUnnormalized(s, f);
    faceN[f] = glm::length(n) > 0.f ? glm::normalize(n) : glm::vec3(0.f);
  }
  Timer queryTimer;
  // Final gather: cosine rays from each vertex; each hit's reflected radiosity rho H_photons.
  std::vector<glm::vec3> gathered;
  if (gatherMap)
    gathered = finalGather(s, caster, mat, opt.gatherRays, opt.seed ^ 0x6au, [&](uint32_t f, const glm::vec3& y) {
      return s.faceRho(f) * gatherMap->irradiance(y, faceN[f], opt.kNearest, r2max, nullptr);
    });
  parallelBlocks(nv, progress.sub(0.7, 1.0), "density estimation", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (!mat.valid[i]) continue;
      double err = 0;
      glm::vec3 H(0.f);
      if (gatherMap) {
        H = gathered[i];      } else {
        H = vertexMap.irradiance(s.positions[i], mat.n[i], opt.kNearest, r2max, &err);
      }
      if (opt.directLight) H += Hd[i];
      out.H[i] = H;
      out.B[i] = mat.E[i] + mat.rho[i] * H;
      out.stdError[i] = float(luminance(mat.rho[i]) * err);
    }
  });
  double lum = 0, err2 = 0;
  size_t valid = 0;
  for (size_t i = 0; i < nv; ++i)
    if (mat.valid[i]) { lum += luminance(out.B[i]); err2 += double(out.stdError[i]) * out.stdError[i]; ++valid; }
  out.stats.add("trace_seconds", traceSeconds);
  out.stats.add("kdtree_build_seconds", buildSeconds);
  out.stats.add("direct_light_seconds", directSeconds);
  out.stats.add("query_seconds", queryTimer.seconds());
  out.stats.add("seconds", timer.seconds());
  out.stats.add("photons_per_second", traceSeconds > 0 ? opt.photons / traceSeconds : 0.0);
  out.stats.add("photons_in_vertex_map", double(vertexMap.size()));
  out.stats.add("mean_luminance_B", valid ? lum / double(valid) : 0.0);
  out.stats.add("photon_noise_estimate", valid ? std::sqrt(err2 / double(valid)) : 0.0);
  out.stats.note(opt.directLight ? "direct light by explicit light sampling at the vertices; photons give the indirect light"
                                 : "all light from the photon map");
  if (gatherMap) out.stats.note("final gather of the photon map (" + std::to_string(opt.gatherRays) + " rays per vertex)");
  out.stats.note("diffuse surfaces only; no caustic map (no mirror or glass materials yet)");
  return out;
}

}  // namespace gi
