// Photon emission and transport (the first pass of photon mapping).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "gi/color.h"
#include "gi/emitters.h"
#include "gi/photon.h"
#include "gi/sampling.h"
#include "gi/specular.h"

namespace gi {

namespace {

glm::i8vec3 packNormal(const glm::vec3& n) {
  return glm::i8vec3(int8_t(std::lround(n.x * 127.f)), int8_t(std::lround(n.y * 127.f)), int8_t(std::lround(n.z * 127.f)));
}

// The lights photons leave from: the area emitters and an optional point or
// spot light, chosen in proportion to their (luminance) power.
class PhotonLights {
 public:
  PhotonLights(const Scene& s, const PhotonOptions& o) : area_(s), o_(o) {
    cosSpot_ = std::cos(glm::radians(std::clamp(o.spotAngleDeg, 0.f, 180.f)));
    // Power of an isotropic point light of intensity I: 4 pi I; of a spot of half angle a: 2 pi (1 - cos a) I.
    pointPower_ = double(luminance(o.pointIntensity)) * 2.0 * M_PI * (1.0 - cosSpot_);
    if (!(pointPower_ > 0.0)) pointPower_ = 0.0;
    total_ = area_.totalPower() + pointPower_;
    spotFrame_ = glm::length(o.spotDirection) > 0.f ? glm::normalize(o.spotDirection) : glm::vec3(0.f, -1.f, 0.f);
  }
  bool empty() const { return !(total_ > 0.0); }
  double totalPower() const { return total_; }
  struct Emission {
    glm::vec3 o, d, power, n;  // n: the emitting face's normal (0 for the point light)
  };
  // u: 4 numbers in [0,1); photon power for `count` photons in total.
  Emission sample(glm::vec2 u0, glm::vec2 u1, double count) const {
    Emission e;
    const double pPoint = pointPower_ / total_;
    if (u0.x < pPoint) {
      const glm::vec2 ur{float(std::min(0.99999994, u0.x / pPoint)), u0.y};
      e.o = o_.pointPosition;
      e.d = Frame(spotFrame_).toWorld(uniformCone(ur, float(cosSpot_)));
      // Flux per photon: I * solid angle / (p_choice * count).
      const float omega = float(2.0 * M_PI * (1.0 - cosSpot_));
      e.power = o_.pointIntensity * omega / float(pPoint * count);
      e.n = glm::vec3(0.f);
      return e;
    }
    const float ux = float(std::min(0.99999994, (u0.x - pPoint) / (1.0 - pPoint)));
    const auto L = area_.sample({ux, u0.y});
    e.o = L.p;
    e.n = L.n;
    e.d = Frame(L.n).toWorld(cosineHemisphere(u1));
    // Flux of one photon: E A / (p_face N) = E / (pdfArea N).
    e.power = L.E / (L.pdfArea * float((1.0 - pPoint) * count));
    return e;
  }

 private:
  EmitterSampler area_;
  const PhotonOptions& o_;
  double pointPower_ = 0.0, total_ = 0.0, cosSpot_ = -1.0;
  glm::vec3 spotFrame_;
};

}  // namespace

std::vector<Photon> tracePhotons(const Scene& s, const RayCaster& caster, const PhotonOptions& opt, size_t first,
                                 size_t count, const Progress& progress, PhotonTraceStats& stats) {
  const PhotonLights lights(s, opt);
  if (lights.empty())
    throw std::invalid_argument("the scene has no light: no emitter faces (select them or mark them by face quality) "
                                "and no point or spot light");
  const float eps = float(analyzeScene(s).rayEpsilon);
  std::vector<glm::vec3> faceN(s.faceCount());
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const glm::vec3 n = faceNormalUnnormalized(s, f);
    const float l = glm::length(n);
    faceN[f] = l > 0.f ? n / l : glm::vec3(0.f, 0.f, 1.f);
  }
  // Fixed-size blocks, concatenated in order: the result is independent of threads.
  constexpr size_t kBlock = 4096;
  const size_t nBlocks = (count + kBlock - 1) / kBlock;
  std::vector<std::vector<Photon>> blocks(nBlocks);
  std::vector<PhotonTraceStats> bstats(nBlocks);
  const uint32_t kPos = hash32(opt.seed ^ 0x9e37u), kDir = hash32(opt.seed ^ 0x51edu);
  parallelBlocks(nBlocks, progress, "tracing photons", [&](size_t b0, size_t b1) {
    for (size_t b = b0; b < b1; ++b) {
      auto& out = blocks[b];
      PhotonTraceStats& st = bstats[b];
      for (size_t i = b * kBlock; i < std::min(count, (b + 1) * kBlock); ++i) {
        const uint32_t index = uint32_t(first + i);
        const auto em = lights.sample(sobolOwen2D(index, kPos), sobolOwen2D(index, kDir), double(count));
        glm::vec3 power = em.power;
        Rng rng(hash3(index, opt.seed, 0x7u));
        Ray ray;
        ray.o = em.o + em.n * eps;
        ray.d = em.d;
        int diffuse = 0;
        bool viaSpecular = false;
        int depth = 0;
        for (; depth < opt.maxDepth; ++depth) {
          const Hit h = caster.intersect(ray);
          if (!h.valid()) { ++st.escaped; break; }
          const glm::vec3 x = ray.o + ray.d * h.t;
          const Material m = s.faceMaterial(h.face);
          const glm::vec3 ng = faceN[h.face];
          glm::vec3 newDir;
          glm::vec3 side = glm::dot(ng, ray.d) > 0.f ? -ng : ng;  // the side the photon arrived on
          if (isSpecular(m)) {
            const glm::vec3 tint = s.faceRho(h.face);
            const float ior = s.ior.empty() ? 1.5f : s.ior[h.face];
            const SpecularEvent ev = scatterSpecular(m, ray.d, ng, tint, ior, rng.next());
            st.totalInternal += ev.totalInternal;
            // Russian roulette on the tint (a white mirror or clear glass always survives).
            const float q = std::min(1.f, std::max({ev.weight.r, ev.weight.g, ev.weight.b}));
            if (!(q > 0.f) || (q < 1.f && rng.next() >= q)) break;
            power *= ev.weight / q;
            newDir = ev.d;
            ++st.specularBounces;
            viaSpecular = true;
            side = glm::dot(newDir, ng) > 0.f ? ng : -ng;  // leave on the side of the new direction
          } else {
            // Diffuse faces are one-sided, as in the radiosity filter and the
            // reference: the back of a face is black.
            if (glm::dot(ng, ray.d) > 0.f) break;
            const uint8_t path = diffuse > 0 ? kIndirectPhoton : viaSpecular ? kCausticPhoton : kDirectPhoton;
            out.push_back({x, power, packNormal(side), path});
            st.storedPower += luminance(power);
            (path == kDirectPhoton ? st.direct : path == kCausticPhoton ? st.caustic : st.indirect)++;
            const glm::vec3 rho = s.faceRho(h.face);
            const float q = std::min(1.f, std::max({rho.r, rho.g, rho.b}));
            if (!(q > 0.f) || rng.next() >= q) break;  // Russian roulette: absorbed
            power *= rho / q;
            newDir = Frame(side).toWorld(cosineHemisphere({rng.next(), rng.next()}));
            ++diffuse;
            ++st.diffuseBounces;
          }
          ray.o = x + side * eps;
          ray.d = newDir;
          ray.tnear = 0.f;
          ray.tfar = std::numeric_limits<float>::infinity();
        }
        if (depth == opt.maxDepth) { ++st.lostAtMaxDepth; st.lostPower += luminance(power); }
      }
    }
  });
  // Concatenate block by block, freeing each, so the peak stays near one copy.
  size_t total = 0;
  for (const auto& b : blocks) total += b.size();
  std::vector<Photon> all;
  all.reserve(total);
  for (size_t b = 0; b < nBlocks; ++b) {
    all.insert(all.end(), blocks[b].begin(), blocks[b].end());
    std::vector<Photon>().swap(blocks[b]);
    const auto& t = bstats[b];
    stats.caustic += t.caustic;
    stats.direct += t.direct;
    stats.indirect += t.indirect;
    stats.diffuseBounces += t.diffuseBounces;
    stats.specularBounces += t.specularBounces;
    stats.totalInternal += t.totalInternal;
    stats.lostAtMaxDepth += t.lostAtMaxDepth;
    stats.escaped += t.escaped;
    stats.storedPower += t.storedPower;
    stats.lostPower += t.lostPower;
  }
  stats.stored = stats.direct + stats.caustic + stats.indirect;
  stats.emitted += count;
  stats.emittedPower = lights.totalPower();
  ++stats.passes;
  return all;
}

}  // namespace gi
