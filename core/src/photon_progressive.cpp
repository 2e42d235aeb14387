// Progressive photon mapping and the specular-aware final gather.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "gi/color.h"
#include "gi/glossy.h"
#include "gi/sampling.h"
#include "gi/specular.h"
#include "photon_internal.h"
#include "photon_grid.h"
#include "photon_map.h"
#include "photon_surface.h"

namespace gi {

ProgressiveResult progressivePhotonMap(const Scene& s, const RayCaster& caster, const PhotonOptions& opt,
                                       const VertexMaterial& mat, unsigned pathMask, bool projection,
                                       const Progress& progress, PhotonTraceStats& stats) {
  const size_t nv = s.vertexCount();
  ProgressiveResult r;
  std::vector<float> R2(nv, 0.f);
  std::vector<double> N(nv, 0.0);
  std::vector<glm::dvec3> tau(nv, glm::dvec3(0.0));
  std::vector<double> A(nv, 0.0);  // area of the counted surface within each radius
  std::vector<size_t> seen(nv, 0);  // photons gathered over all passes
  const GatherSurface surface(s);
  const float r2cap = opt.maxRadius > 0 ? float(opt.maxRadius * opt.maxRadius) : HUGE_VALF;
  // Vertices where the first pass finds fewer than k photons within the cap
  // start at the cap, or at 1% of the diagonal without one.
  const float diag = float(sceneScale(s).diagonal);
  const float r2fallback = std::min(r2cap, 1e-4f * diag * diag);
  const double alpha = opt.alpha;
  const size_t count = size_t(opt.photons);
  for (int pass = 0; pass < opt.passes; ++pass) {
    const Progress pp = progress.sub(double(pass) / opt.passes, double(pass + 1) / opt.passes);
    Timer tt;
    std::vector<Photon> photons = tracePhotons(s, caster, opt, size_t(pass) * count, count, pp.sub(0.0, 0.6), stats);
    if (projection) {
      photons.erase(std::remove_if(photons.begin(), photons.end(), [](const Photon& p) { return p.path == kCausticPhoton; }),
                    photons.end());
      const auto c = traceCausticPhotons(s, caster, opt, size_t(pass) * count, count, pp.sub(0.6, 0.7), stats);
      photons.insert(photons.end(), c.begin(), c.end());
    }
    r.traceSeconds += tt.seconds();
    Timer bt;
    // Pass 1 needs the k nearest photons (the first radii): a kd-tree. Later
    // passes only gather within each vertex's radius: a grid whose cells are
    // the 90th percentile of the radii (most gathers visit 27 cells).
    std::unique_ptr<PhotonMap> map;
    if (pass == 0) {
      map = std::make_unique<PhotonMap>(photons, pathMask, surface);
      parallelBlocks(nv, Progress(nullptr), "", [&](size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) {
          if (!mat.valid[i]) continue;
          const float k2 = map->kthRadius2(s.positions[i], mat.n[i], opt.kNearest);
          // Fewer than k photons returns infinity, which would pass an infinite cap.
          R2[i] = std::isfinite(k2) && k2 <= r2cap ? std::max(k2, 1e-30f) : r2fallback;
          A[i] = surface.area(s.positions[i], mat.n[i], std::sqrt(R2[i]));
        }
      });
    }
    std::vector<float> radii;
    for (size_t i = 0; i < nv; ++i)
      if (mat.valid[i]) radii.push_back(R2[i]);
    float cell = std::sqrt(r2fallback);
    if (!radii.empty()) {
      const size_t q = radii.size() * 9 / 10;
      std::nth_element(radii.begin(), radii.begin() + q, radii.end());
      cell = std::max(std::sqrt(radii[q]), 1e-6f * diag);
    }
    const PhotonGrid grid(photons, pathMask, cell);
    r.check.mapPhotons += grid.size();
    r.buildSeconds += bt.seconds();
    r.peakBytes = std::max(r.peakBytes, double(photons.capacity() * sizeof(Photon) + grid.memoryBytes() +
                                               (map ? map->memoryBytes() : 0)));
    map.reset();
    std::vector<Photon>().swap(photons);
    Timer qt;
    parallelBlocks(nv, pp.sub(0.7, 1.0), "progressive pass " + std::to_string(pass + 1), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        if (!mat.valid[i]) continue;
        glm::dvec3 flux;
        size_t M = 0;
        grid.gather(s.positions[i], mat.n[i], R2[i], flux, M);
        if (M == 0) continue;
        seen[i] += M;
        const double ratio = (N[i] + alpha * double(M)) / (N[i] + double(M));
        N[i] += alpha * double(M);
        R2[i] = float(double(R2[i]) * ratio);
        // The flux scales with the area the radius keeps: ratio on a plane,
        // not near a crease or border the shrinking disk moves off.
        const double A1 = surface.area(s.positions[i], mat.n[i], std::sqrt(R2[i]));
        tau[i] = (tau[i] + flux) * (A[i] > 0.0 && A1 > 0.0 ? A1 / A[i] : ratio);
        A[i] = A1;
      }
    });
    r.querySeconds += qt.seconds();
  }
  r.H.assign(nv, glm::vec3(0.f));
  r.noise.assign(nv, 0.0);
  double sumR = 0, sumN = 0;
  size_t valid = 0;
  for (size_t i = 0; i < nv; ++i) {
    if (!mat.valid[i]) continue;
    ++valid;
    if (seen[i] > 0) {
      ++r.check.estimates;
      if (seen[i] < size_t(kFewPhotons)) ++r.check.fewEstimates;
    }
    sumR += std::sqrt(double(R2[i]));
    sumN += N[i];
    if (N[i] <= 0.0) { ++r.verticesWithoutPhotons; continue; }
    const double area = A[i] > 0.0 ? A[i] : M_PI * double(R2[i]);
    const glm::dvec3 H = tau[i] / (area * opt.passes);
    r.H[i] = glm::vec3(H);
    // About N photons kept: relative Poisson noise 1 / sqrt(N) (equal photon powers).
    r.noise[i] = luminance(glm::vec3(H)) / std::sqrt(N[i]);
  }
  r.check.surfaceArea = surface.totalArea();
  r.meanRadius = valid ? sumR / double(valid) : 0.0;
  r.meanCount = valid ? sumN / double(valid) : 0.0;
  return r;
}

std::vector<glm::vec3> specularFinalGather(
    const Scene& s, const RayCaster& caster, const VertexMaterial& mat, const std::vector<glm::vec3>& origins, int rays,
    uint32_t key, float eps, const std::function<glm::vec3(uint32_t, const glm::vec3&, const glm::vec3&)>& value) {
  const std::vector<glm::vec3> faceN = unitFaceNormals(s);
  std::vector<glm::vec3> H(s.vertexCount(), glm::vec3(0.f));
  parallelBlocks(s.vertexCount(), Progress(nullptr), "", [&](size_t b, size_t e) {
    for (size_t v = b; v < e; ++v) {
      if (!mat.valid[v]) continue;
      SobolOwenStream seq(hash3(uint32_t(v), key, 0xf9u));
      Rng rng(hash3(uint32_t(v), key, 0xfau));
      const Frame frame(mat.n[v]);
      glm::dvec3 sum(0.0);
      for (int k = 0; k < rays; ++k) {
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
            if (glm::dot(ray.d, ng) < 0.f) sum += glm::dvec3(weight * value(h.face, y, ng));
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
            ray.o = y + ng * eps;
            ray.d = fr.toWorld(g.wi);
            ray.tnear = 0.f;
            ray.tfar = std::numeric_limits<float>::infinity();
            continue;
          }
          const float ior = s.ior.empty() ? 1.5f : s.ior[h.face];
          const SpecularEvent ev = scatterSpecular(m, ray.d, ng, s.faceRho(h.face), ior, rng.next());
          weight *= ev.weight * ev.radianceScale;
          ray.o = y + (glm::dot(ev.d, ng) > 0.f ? ng : -ng) * eps;
          ray.d = ev.d;
          ray.tnear = 0.f;
          ray.tfar = std::numeric_limits<float>::infinity();
        }
      }
      H[v] = glm::vec3(sum / double(rays));
    }
  });
  return H;
}

}  // namespace gi
