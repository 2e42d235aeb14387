#include "gi/photon.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <nanoflann.hpp>
#include <tbb/parallel_for.h>

#include "gi/color.h"
#include "gi/emitters.h"
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
       ParamType::Int, 64, 1, 10000},
      {"max_radius", "Maximum gather radius",
       "Photons farther than this from a vertex are ignored (0 = no limit). Absolute or % of the bbox diagonal.",
       ParamType::Distance, 0.05, 0.0, 1.0},
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
          out.push_back({x, power, n});
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
struct PhotonCloud {
  const std::vector<Photon>& ph;
  size_t kdtree_get_point_count() const { return ph.size(); }
  float kdtree_get_pt(size_t i, size_t d) const { return ph[i].p[int(d)]; }
  template <class B> bool kdtree_get_bbox(B&) const { return false; }
};
using PhotonTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PhotonCloud>, PhotonCloud, 3, uint32_t>;
}  // namespace

VertexRadiometry computePhotonMap(const Scene& s, const RayCaster& caster, const PhotonOptions& opt, const Progress& progress) {
  if (opt.photons < 1 || opt.kNearest < 1) throw std::invalid_argument("photons and k_nearest must be >= 1");
  Timer timer;
  VertexRadiometry out;
  std::vector<Photon> photons = tracePhotons(s, caster, opt, progress.sub(0.0, 0.6), out.stats);
  const double traceSeconds = timer.seconds();
  Timer buildTimer;
  PhotonCloud cloud{photons};
  PhotonTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  const double buildSeconds = buildTimer.seconds();
  const VertexMaterial mat = vertexMaterial(s);
  const size_t nv = s.vertexCount();
  out.B.assign(nv, glm::vec3(0.f));
  out.H.assign(nv, glm::vec3(0.f));
  out.stdError.assign(nv, 0.f);
  const float r2max = opt.maxRadius > 0 ? float(opt.maxRadius * opt.maxRadius) : HUGE_VALF;
  // Query more than k so that photons on the other side can be dropped.
  const size_t kq = std::min(photons.size(), size_t(opt.kNearest) * 2);
  Timer queryTimer;
  if (kq > 0)
    parallelBlocks(nv, progress.sub(0.6, 1.0), "density estimation", [&](size_t b, size_t e) {
      std::vector<uint32_t> idx(kq);
      std::vector<float> d2(kq);
      for (size_t i = b; i < e; ++i) {
        if (!mat.valid[i]) continue;
        const float q[3] = {s.positions[i].x, s.positions[i].y, s.positions[i].z};
        const size_t found = tree.knnSearch(q, kq, idx.data(), d2.data());
        glm::dvec3 sum(0.0);
        double sumL2 = 0.0;
        float r2 = 0.f;
        int used = 0;
        for (size_t k = 0; k < found && used < opt.kNearest; ++k) {
          if (d2[k] > r2max) break;
          const Photon& p = photons[idx[k]];
          if (glm::dot(p.n, mat.n[i]) < 0.5f) continue;  // other side or another surface
          sum += glm::dvec3(p.power);
          sumL2 += double(luminance(p.power)) * luminance(p.power);
          r2 = d2[k];
          ++used;
        }
        if (used == 0) { out.B[i] = mat.E[i]; continue; }
        if (used < opt.kNearest && opt.maxRadius > 0) r2 = r2max;  // sparse region: the full disk was searched
        const double area = 3.14159265358979 * std::max(r2, 1e-30f);
        out.H[i] = glm::vec3(sum / area);
        out.B[i] = mat.E[i] + mat.rho[i] * out.H[i];
        // Poisson count noise of a density estimate: sqrt(sum Phi^2) / area.
        out.stdError[i] = float(luminance(mat.rho[i]) * std::sqrt(sumL2) / area);
      }
    });
  double lum = 0, err2 = 0;
  size_t valid = 0;
  for (size_t i = 0; i < nv; ++i)
    if (mat.valid[i]) { lum += luminance(out.B[i]); err2 += double(out.stdError[i]) * out.stdError[i]; ++valid; }
  out.stats.add("trace_seconds", traceSeconds);
  out.stats.add("kdtree_build_seconds", buildSeconds);
  out.stats.add("query_seconds", queryTimer.seconds());
  out.stats.add("seconds", timer.seconds());
  out.stats.add("photons_per_second", traceSeconds > 0 ? opt.photons / traceSeconds : 0.0);
  out.stats.add("mean_luminance_B", valid ? lum / double(valid) : 0.0);
  out.stats.add("rms_error_estimate", valid ? std::sqrt(err2 / double(valid)) : 0.0);
  out.stats.note("diffuse surfaces only; no caustic map (no mirror or glass materials yet)");
  return out;
}

}  // namespace gi
