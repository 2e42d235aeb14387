// Progressive photon mapping and the specular-aware final gather.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "gi/color.h"
#include "gi/glossy.h"
#include "gi/sampling.h"
#include "gi/specular.h"
#include "hit_origin.h"
#include "photon_internal.h"
#include "photon_grid.h"
#include "photon_map.h"
#include "photon_surface.h"

namespace gi {

namespace {

// Per-vertex state of progressive photon mapping: squared radius R^2,
// accumulated photon count N, flux tau, the area A(R) of the counted
// surface within R, and the photons gathered over all passes.
struct PpmVertices {
  std::vector<float> R2;
  std::vector<double> N;
  std::vector<glm::dvec3> tau;
  std::vector<double> A;
  std::vector<size_t> seen;
  std::vector<glm::dvec3> tauPath[3];  // tau by the photons' path kind (light_path_split), scaled alike
  PpmVertices(size_t nv, bool split)
      : R2(nv, 0.f), N(nv, 0.0), tau(nv, glm::dvec3(0.0)), A(nv, 0.0), seen(nv, 0) {
    if (split)
      for (auto& t : tauPath) t.assign(nv, glm::dvec3(0.0));
  }
};

// The photons of one pass; with projection, its caustic photons are the
// aimed ones (those of the global pass dropped). With `keep`, every
// stride-th photon of the global trace (all kinds) is appended to it with
// its power times `scale`, and the hits its path had left to keep->left.
// heldBytes: what the run holds besides (the kept photons), which the
// traces' memory limit leaves out.
struct KeptPhotons {
  std::vector<Photon> photons;
  std::vector<uint8_t> left;
  size_t stride = 1;
  float scale = 1.f;
  size_t bytes() const { return photons.capacity() * sizeof(Photon) + left.capacity(); }
};
std::vector<Photon> tracePass(const PhotonRun& r, int pass, const Progress& pp, PhotonTraceStats& stats,
                              KeptPhotons* keep, double heldBytes) {
  const PhotonOptions& opt = r.opt;
  const size_t count = size_t(opt.photons);
  // The hits left are asked for whenever the direct light is apart, so the
  // lost-power account is the same in every pass (progressivePhotonMap).
  std::vector<uint8_t> left;
  std::vector<Photon> photons = tracePhotons(r.s, r.caster, whileHolding(opt, 0, heldBytes), size_t(pass) * count,
                                             count, pp.sub(0.0, 0.6), stats, opt.directLight ? &left : nullptr);
  if (keep) {
    appendEveryNth(photons, left, keep->stride, keep->scale, keep->photons, keep->left);
    heldBytes = double(keep->bytes());
  }
  if (r.projection) {
    auto caustic = [](const Photon& p) { return p.path == kCausticPhoton; };
    photons.erase(std::remove_if(photons.begin(), photons.end(), caustic), photons.end());
    const auto c = traceCausticPhotons(r.s, r.caster, whileHolding(opt, photons.size(), heldBytes),
                                       size_t(pass) * count, count, pp.sub(0.6, 0.7), stats);
    photons.insert(photons.end(), c.begin(), c.end());
  }
  return photons;
}

// The first radii: the distance to the k-th nearest photon of the first
// pass (a kd-tree over it, returned for the memory account), capped at
// r2cap; r2fallback where fewer than k photons lie within the cap.
std::unique_ptr<PhotonMap> firstRadii(const Scene& s, const PhotonOptions& opt, const VertexMaterial& mat,
                                      const std::vector<Photon>& photons, unsigned pathMask,
                                      const GatherSurface& surface, float r2cap, float r2fallback, PpmVertices& v) {
  auto map = std::make_unique<PhotonMap>(photons, pathMask, surface);
  parallelBlocks(s.vertexCount(), Progress(nullptr), "", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (!mat.valid[i]) continue;
      const float k2 = map->kthRadius2(s.positions[i], mat.n[i], opt.kNearest);
      // Fewer than k photons returns infinity, which would pass an infinite cap.
      v.R2[i] = std::isfinite(k2) && k2 <= r2cap ? std::max(k2, surface.minRadius2()) : r2fallback;
      v.A[i] = surface.area(s.positions[i], mat.n[i], std::sqrt(v.R2[i]));
    }
  });
  return map;
}

// Later passes only gather within each vertex's radius: a grid whose cells
// are the 90th percentile of the radii (most gathers visit 27 cells).
float gridCell(const VertexMaterial& mat, const PpmVertices& v, float r2fallback, float diag) {
  std::vector<float> radii;
  for (size_t i = 0; i < v.R2.size(); ++i)
    if (mat.valid[i]) radii.push_back(v.R2[i]);
  if (radii.empty()) return std::sqrt(r2fallback);
  const size_t q = radii.size() * 9 / 10;
  std::nth_element(radii.begin(), radii.begin() + q, radii.end());
  return std::max(std::sqrt(radii[q]), 1e-6f * diag);
}

// One pass's update at every vertex: M new photons within R give
// N' = N + alpha M, R'^2 = R^2 (N + alpha M) / (N + M), tau' = (tau + Phi_M) A(R') / A(R).
// The vertices `caustic` marks (handed over to the final gather) count
// only their caustic photons.
void updateVertices(const Scene& s, const VertexMaterial& mat, const PhotonGrid& grid, const GatherSurface& surface,
                    double alpha, const std::vector<uint8_t>& caustic, const Progress& progress,
                    const std::string& what, PpmVertices& v) {
  parallelBlocks(s.vertexCount(), progress, what, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (!mat.valid[i]) continue;
      glm::dvec3 flux, fluxPath[3];
      size_t M = 0;
      const bool split = !v.tauPath[0].empty();
      grid.gather(s.positions[i], mat.n[i], v.R2[i], flux, M, split ? fluxPath : nullptr,
                  caustic[i] ? 1u << kCausticPhoton : 7u);
      if (M == 0) continue;
      v.seen[i] += M;
      const double ratio = (v.N[i] + alpha * double(M)) / (v.N[i] + double(M));
      v.N[i] += alpha * double(M);
      v.R2[i] = float(double(v.R2[i]) * ratio);
      // The flux scales with the area the radius keeps: ratio on a plane,
      // not near a crease or border the shrinking disk moves off.
      const double A1 = surface.area(s.positions[i], mat.n[i], std::sqrt(v.R2[i]));
      const double scale = v.A[i] > 0.0 && A1 > 0.0 ? A1 / v.A[i] : ratio;
      v.tau[i] = (v.tau[i] + flux) * scale;
      if (split)
        for (int k = 0; k < 3; ++k) v.tauPath[k][i] = (v.tauPath[k][i] + fluxPath[k]) * scale;
      v.A[i] = A1;
    }
  });
}

// H = tau / (A(R) passes) per vertex, its Poisson noise, and the counts the
// warnings and the log need (a vertex that gathers is without photons only
// if its gather finds none either).
void estimates(const VertexMaterial& mat, const PpmVertices& v, int passes, const std::vector<uint8_t>& gathers,
               ProgressiveResult& r) {
  const size_t nv = v.R2.size();
  r.H.assign(nv, glm::vec3(0.f));
  r.noise.assign(nv, 0.0);
  const bool split = !v.tauPath[0].empty();
  if (split)
    for (auto& h : r.byPath) h.assign(nv, glm::vec3(0.f));
  double sumR = 0, sumN = 0;
  size_t valid = 0;
  // The power a kept photon carries on average (per pass): a vertex that
  // kept none has about one such photon's density as its standard error
  // (it read 0: 190 of floor_wall's vertices, 159 of them beyond 4 of it
  // against the reference; an outside audit). Errors are of the luminance
  // of rho H, B's reflected light (of H's, times rho's luminance, they were
  // 2.5 to 4 times too small where light and surface are both coloured).
  glm::dvec3 tau(0.0);
  double kept = 0;
  for (size_t i = 0; i < nv; ++i)
    if (mat.valid[i] && v.N[i] > 0.0) tau += v.tau[i], kept += v.N[i];
  const glm::dvec3 perPhoton = kept > 0 ? tau / kept : glm::dvec3(0.0);
  for (size_t i = 0; i < nv; ++i) {
    if (!mat.valid[i]) continue;
    ++valid;
    if (v.seen[i] > 0) {
      ++r.check.estimates;
      if (v.seen[i] < size_t(kFewPhotons)) ++r.check.fewEstimates;
    }
    sumR += std::sqrt(double(v.R2[i]));
    sumN += v.N[i];
    const double area = v.A[i] > 0.0 ? v.A[i] : M_PI * double(v.R2[i]);
    if (v.N[i] <= 0.0) {
      r.verticesWithoutPhotons += gathers[i] ? 0 : 1;
      if (area > 0.0) r.noise[i] = luminance(mat.rho[i] * glm::vec3(perPhoton)) / (area * passes);
      continue;
    }
    const glm::dvec3 H = v.tau[i] / (area * passes);
    r.H[i] = glm::vec3(H);
    if (split)
      for (int k = 0; k < 3; ++k) r.byPath[k][i] = glm::vec3(v.tauPath[k][i] / (area * passes));
    // About N photons kept: relative Poisson noise 1 / sqrt(N) (equal photon powers).
    r.noise[i] = luminance(mat.rho[i] * glm::vec3(H)) / std::sqrt(v.N[i]);
  }
  r.meanRadius = valid ? sumR / double(valid) : 0.0;
  r.meanCount = valid ? sumN / double(valid) : 0.0;
}

// The vertices that take a final gather (photon_gather.cpp's test with the
// first radius), counted by reason.
void decideHandOver(const PhotonRun& r, const GatherSurface& surface, const PpmVertices& v, HandOver& ho) {
  const std::vector<uint8_t> crease = creaseVertices(r.s, r.mat);
  ho.at.assign(r.s.vertexCount(), 0);
  std::atomic<size_t> creases{0}, others{0};
  parallelBlocks(r.s.vertexCount(), Progress(nullptr), "", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      bool atCrease = false;
      if (!r.mat.valid[i] || !handsOver(r, surface, crease, i, std::sqrt(v.R2[i]), atCrease)) continue;
      ho.at[i] = 1;
      (atCrease ? creases : others).fetch_add(1, std::memory_order_relaxed);
    }
  });
  ho.crease = creases.load();
  ho.otherSurface = others.load();
}

// The final gather at the vertices handed over, from the kept photons'
// map, added to their (caustic) estimates.
void gatherHandedOver(const PhotonRun& r, const GatherSurface& surface, const KeptPhotons& kept,
                      const Progress& progress, ProgressiveResult& out) {
  Timer bt;
  const std::unique_ptr<PhotonMap> all = gatherMap(kept.photons, surface, kept.left);
  out.buildSeconds += bt.seconds();
  out.peakBytes = std::max(out.peakBytes, double(kept.bytes() + all->memoryBytes()));
  std::atomic<size_t> some{0}, few{0};
  const auto count = [&](int used) {
    if (used > 0) some.fetch_add(1, std::memory_order_relaxed);
    if (used > 0 && used < kFewPhotons) few.fetch_add(1, std::memory_order_relaxed);
  };
  Timer gt;
  std::vector<double> variance;
  const std::vector<glm::vec3> H = gatherPhotonMap(r, *all, &out.ho.at, count, &out.ho.nearHits, progress, &variance);
  out.ho.gatherSeconds = gt.seconds();
  out.check.estimates += some.load();
  out.check.fewEstimates += few.load();
  for (size_t i = 0; i < H.size(); ++i) {
    if (!out.ho.at[i] || !r.mat.valid[i]) continue;
    out.H[i] += H[i];
    out.noise[i] = std::sqrt(out.noise[i] * out.noise[i] + variance[i]);  // the caustic part's and the gather's
    if (!out.byPath[kPathIndirect].empty()) out.byPath[kPathIndirect][i] = H[i];
    if (luminance(out.H[i]) <= 0.f) ++out.verticesWithoutPhotons;
  }
}

}  // namespace

ProgressiveResult progressivePhotonMap(const PhotonRun& r, const Progress& progress, PhotonTraceStats& stats) {
  const Scene& s = r.s;
  const PhotonOptions& opt = r.opt;
  const VertexMaterial& mat = r.mat;
  ProgressiveResult out;
  PpmVertices v(s.vertexCount(), opt.lightPathSplit);
  const GatherSurface surface(s);
  const float r2cap = opt.maxRadius > 0 ? float(opt.maxRadius * opt.maxRadius) : HUGE_VALF;
  // Vertices where the first pass finds fewer than k photons within the cap
  // start at the cap, or at 1% of the diagonal without one.
  const float diag = float(sceneScale(s).diagonal);
  const float r2fallback = std::min(r2cap, 1e-4f * diag * diag);
  // With the direct light apart, the photons of the first passes (those of
  // kPpmGatherPaths paths) are kept for the final gather of the vertices
  // handed over to it (dropped after the first pass if there are none). A
  // pass of more paths keeps every stride-th photon, its power times the
  // stride (each photon kept with probability 1 / stride: the same density).
  int keepPasses = 0;
  KeptPhotons kept;
  if (opt.directLight) {
    const size_t paths = size_t(opt.photons);
    keepPasses = int(std::min<size_t>((kPpmGatherPaths + paths - 1) / paths, size_t(opt.passes)));
    kept.stride = gatherMapStride(paths);
    kept.scale = float(kept.stride) / float(keepPasses);
  }
  out.ho.at.assign(s.vertexCount(), 0);
  const double gatherShare = opt.directLight ? 0.1 : 0.0;
  for (int pass = 0; pass < opt.passes; ++pass) {
    const double passShare = (1.0 - gatherShare) / opt.passes;
    const Progress pp = progress.sub(passShare * pass, passShare * (pass + 1));
    Timer tt;
    // The photons kept for the gather are held through every pass.
    std::vector<Photon> photons =
        tracePass(r, pass, pp, stats, pass < keepPasses ? &kept : nullptr, double(kept.bytes()));
    out.traceSeconds += tt.seconds();
    Timer bt;
    std::unique_ptr<PhotonMap> map;
    if (pass == 0) {
      map = firstRadii(s, opt, mat, photons, r.vertexPaths, surface, r2cap, r2fallback, v);
      if (opt.directLight) decideHandOver(r, surface, v, out.ho);
      if (out.ho.crease + out.ho.otherSurface == 0) {
        keepPasses = 0;
        kept = KeptPhotons();
      }
    }
    const PhotonGrid grid(photons, r.vertexPaths, gridCell(mat, v, r2fallback, diag));
    out.check.mapPhotons += grid.size();
    out.buildSeconds += bt.seconds();
    out.peakBytes = std::max(out.peakBytes, double(photons.capacity() * sizeof(Photon) + grid.memoryBytes() +
                                                   (map ? map->memoryBytes() : 0) + kept.bytes()));
    map.reset();
    std::vector<Photon>().swap(photons);
    Timer qt;
    updateVertices(s, mat, grid, surface, opt.alpha, out.ho.at, pp.sub(0.7, 1.0),
                   "progressive pass " + std::to_string(pass + 1), v);
    out.querySeconds += qt.seconds();
  }
  // The density estimates lose the power of the paths cut at max_depth, the
  // photon at their last hit apart (tracePhotons' account with the hits left).
  stats.lostPower += stats.lastHitCutPower;
  stats.lostRGB += stats.lastHitCutRGB;
  estimates(mat, v, opt.passes, out.ho.at, out);
  out.gatherPasses = keepPasses;
  out.gatherStride = kept.stride;
  if (keepPasses > 0) gatherHandedOver(r, surface, kept, progress.sub(1.0 - gatherShare, 1.0), out);
  out.check.surfaceArea = surface.totalArea();
  return out;
}

std::vector<glm::vec3> specularFinalGather(
    const Scene& s, const RayCaster& caster, const VertexMaterial& mat, const std::vector<glm::vec3>& origins, int rays,
    uint32_t key, float eps, const std::function<glm::vec3(const PhotonGatherHit&)>& value,
    const std::vector<uint8_t>* only, const Progress& progress, std::vector<double>* variance) {
  const std::vector<glm::vec3> faceN = unitFaceNormals(s);
  const std::vector<glm::vec3> faceAlt = faceAltitudes(s);
  std::vector<glm::vec3> H(s.vertexCount(), glm::vec3(0.f));
  if (variance) variance->assign(s.vertexCount(), 0.0);
  parallelBlocks(s.vertexCount(), progress, "final gather", [&](size_t b, size_t e) {
    for (size_t v = b; v < e; ++v) {
      if (!mat.valid[v] || (only && !(*only)[v])) continue;
      SobolOwenStream seq(hash3(uint32_t(v), key, 0xf9u));
      Rng rng(hash3(uint32_t(v), key, 0xfau));
      const Frame frame(mat.n[v]);
      glm::dvec3 sum(0.0);
      double sumL2 = 0;
      for (int k = 0; k < rays; ++k) {
        const glm::dvec3 before = sum;
        Ray ray;
        ray.o = origins[v];
        ray.d = frame.toWorld(cosineHemisphere(seq.next()));
        glm::vec3 weight(1.f);
        for (int bounce = 0; bounce < 16; ++bounce) {
          const Hit h = caster.intersect(ray);
          if (!h.valid()) break;
          const glm::vec3 ng = faceN[h.face];
          const glm::vec3 y = ray.o + ray.d * h.t;
          const Material m = s.faceMaterial(h.face);
          if (m == Material::Diffuse) {
            if (glm::dot(ray.d, ng) < 0.f)
              sum += glm::dvec3(weight * value({h.face, y, ng, h.t, hash3(uint32_t(v), key ^ 0x9e3779b9u, uint32_t(k)),
                                                ray.o, ray.d, hitBorder(faceAlt, h.face, h.u, h.v)}));
            break;
          }
          if (m == Material::Glossy) {
            // The lobe sampled towards where the light comes from (weight f cos / pdf); the back is black.
            if (!(glm::dot(ray.d, ng) < 0.f)) break;
            const Frame fr(ng);
            const glm::vec2 u{rng.next(), rng.next()};
            const GgxLobe::Sample g = GgxLobe(s.faceRoughness(h.face), s.faceRho(h.face)).sample(fr.toLocal(-ray.d), u);
            if (!g.valid) break;
            weight *= g.weight;
            ray.o = hitRayOrigin(caster, ray.o, ray.d, h.t, ng, eps, hitBorder(faceAlt, h.face, h.u, h.v));
            ray.d = fr.toWorld(g.wi);
            ray.tnear = 0.f;
            ray.tfar = std::numeric_limits<float>::infinity();
            continue;
          }
          const float ior = s.ior.empty() ? 1.5f : s.ior[h.face];
          const SpecularEvent ev = scatterSpecular(m, ray.d, ng, s.faceRho(h.face), ior, rng.next());
          weight *= ev.weight * ev.radianceScale;
          // A reflection leaves on the side the ray came from (hitRayOrigin), a refraction through the other.
          ray.o = specularOrigin(ray.d, ev.d, y, ng, eps, [&] {
            return hitRayOrigin(caster, ray.o, ray.d, h.t, ng, eps, hitBorder(faceAlt, h.face, h.u, h.v));
          });
          ray.d = ev.d;
          ray.tnear = 0.f;
          ray.tfar = std::numeric_limits<float>::infinity();
        }
        const double l = luminance(mat.rho[v] * glm::vec3(sum - before));  // B's reflected light: rho H
        sumL2 += l * l;
      }
      H[v] = glm::vec3(sum / double(rays));
      if (variance && rays > 1) {
        const double m = luminance(mat.rho[v] * H[v]);
        (*variance)[v] = std::max(0.0, (sumL2 / rays - m * m) / (rays - 1));
      }
    }
  });
  return H;
}

std::vector<uint8_t> creaseVertices(const Scene& s, const VertexMaterial& mat) {
  const std::vector<glm::vec3> faceN = unitFaceNormals(s);
  const std::vector<uint8_t> ok = usableFaceMask(s);
  const float cosMax = float(std::cos(kCreaseDegrees * M_PI / 180.0));
  std::vector<uint8_t> crease(s.vertexCount(), 0);
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!ok[f] || s.faceMaterial(f) != Material::Diffuse) continue;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = s.triangles[f][k];
      if (mat.valid[v] && glm::dot(faceN[f], mat.n[v]) < cosMax) crease[v] = 1;
    }
  }
  return crease;
}

}  // namespace gi
