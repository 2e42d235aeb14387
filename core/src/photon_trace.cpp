// Photon emission and transport (the first pass of photon mapping).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <new>
#include <stdexcept>

#include "gi/color.h"
#include "gi/emitters.h"
#include "gi/glossy.h"
#include "gi/memory_limit.h"
#include "gi/photon.h"
#include "gi/sampling.h"
#include "gi/specular.h"
#include "hit_origin.h"
#include "photon_internal.h"

namespace gi {

namespace {

// Where a photon's ray, which hit face h.face (unit normal ng) at distance
// h.t, leaves on the side it came from (hitRayOrigin, hit_origin.h: lifted
// along the normal, or near an acute corner on the segment it came along,
// where the lift crossed the neighbouring face and photons left a closed
// room through its corners).
struct PhotonLeave {
  const RayCaster& caster;
  const std::vector<glm::vec3>& altitudes;
  float eps;
  glm::vec3 operator()(const Ray& in, const Hit& h, const glm::vec3& ng) const {
    return hitRayOrigin(caster, in.o, in.d, h.t, ng, eps, hitBorder(altitudes, h.face, h.u, h.v));
  }
};

// A photon meets a mirror or glass face (unit normal ng) at x: its new
// direction and power, with Russian roulette on the tint (a white mirror or
// clear glass always passes); the ray starts again on the side it leaves by
// (a reflection where leave says). False if the photon is absorbed.
bool specularStep(const Scene& s, const Hit& h, const glm::vec3& ng, const glm::vec3& x, float eps,
                  const PhotonLeave& leave, Rng& rng, Ray& ray, glm::vec3& power, size_t& totalInternal) {
  const uint32_t face = h.face;
  const float ior = s.ior.empty() ? 1.5f : s.ior[face];
  const SpecularEvent ev = scatterSpecular(s.faceMaterial(face), ray.d, ng, s.faceRho(face), ior, rng.next());
  totalInternal += ev.totalInternal;
  const float q = std::min(1.f, std::max({ev.weight.r, ev.weight.g, ev.weight.b}));
  if (!(q > 0.f) || (q < 1.f && rng.next() >= q)) return false;
  power *= ev.weight / q;
  ray.o = specularOrigin(ray.d, ev.d, x, ng, eps, [&] { return leave(ray, h, ng); });
  ray.d = ev.d;
  ray.tnear = 0.f;
  ray.tfar = std::numeric_limits<float>::infinity();
  return true;
}

// A photon meets the front of a glossy face (the GGX lobe of gi/glossy.h)
// at x, arriving along ray.d. The BRDF is reciprocal, so the lobe's
// visible-normal sample conditioned on the direction the photon came from
// (-ray.d) draws the outgoing direction with weight f cos(theta_out) / pdf =
// F G2 / G1 <= 1, the factor of the flux. Russian roulette on that weight
// (a one-sample estimate of the lobe's albedo): survival q = its largest
// channel, the power divided by q. A direction drawn below the surface is
// lost (the lobe's G2 < G1 energy loss). False if the photon is absorbed.
bool glossyStep(const Scene& s, const Hit& h, const glm::vec3& ng, const PhotonLeave& leave, Rng& rng, Ray& ray,
                glm::vec3& power) {
  const uint32_t face = h.face;
  const GgxLobe lobe(s.faceRoughness(face), s.faceRho(face));
  const Frame frame(ng);
  const glm::vec2 u{rng.next(), rng.next()};
  const GgxLobe::Sample smp = lobe.sample(frame.toLocal(-ray.d), u);
  if (!smp.valid) return false;
  const float q = std::min(1.f, std::max({smp.weight.r, smp.weight.g, smp.weight.b}));
  if (!(q > 0.f) || (q < 1.f && rng.next() >= q)) return false;
  power *= smp.weight / q;
  ray.o = leave(ray, h, ng);
  ray.d = frame.toWorld(smp.wi);
  ray.tnear = 0.f;
  ray.tfar = std::numeric_limits<float>::infinity();
  return true;
}

// The lights photons leave from: the area emitters, an optional point or
// spot light, the sky and the sun, chosen in proportion to their (luminance)
// power; the sky's and the sun's is what crosses the disk of the bounding
// sphere's radius facing them (photon.h).
class PhotonLights {
 public:
  PhotonLights(const Scene& s, const PhotonOptions& o) : area_(s), o_(o) {
    if (o.outside.any()) {
      const SceneScale sc = sceneScale(s);  // the vertices faces use
      const glm::vec3 lo(sc.lo), hi(sc.hi);
      if (sc.lo.x <= sc.hi.x) {
        centre_ = 0.5f * (lo + hi);
        radius_ = 0.5f * glm::length(hi - lo) * 1.01f + float(sceneScale(s).rayEpsilon);
      }
      // The disk covers the aim sphere (the scene's, or the openings') and
      // starts outside the scene's sphere: every line towards -w through
      // the aim sphere crosses it before the scene.
      aimCentre_ = centre_;
      aimRadius_ = radius_;
      if (o.outsideAimRadius > 0.f && o.outsideAimRadius < radius_) {
        aimCentre_ = o.outsideAimCentre;
        aimRadius_ = o.outsideAimRadius;
      }
      aimDistance_ = glm::length(aimCentre_ - centre_) + radius_;
      const double disk = M_PI * double(aimRadius_) * aimRadius_;
      skyPower_ = o.outside.sky() ? 4.0 * M_PI * double(luminance(o.outside.skyRadiance)) * disk : 0.0;
      sunScale_ = sunDiskScale(o.outside.sunAngularRadiusDeg);
      // Through a disk facing each sampled direction: E_sun <n.w> = E_sun (1 + cos a) / 2 on a facing
      // surface without the factor (gi/sky.h, sunDiskScale).
      sunPower_ = o.outside.sun() ? double(luminance(o.outside.sunIrradiance)) * disk * sunScale_ : 0.0;
    }
    o.point.check();
    // Photons leave the point light itself: a ray from beyond 2^40 local
    // units (about 1e12 times the scene's size) is no float ray, and the
    // run stopped with an internal error (an outside audit: a light at
    // 1e30). Such a light lights nothing measurable: said as a parameter.
    if (luminance(o.point.intensity) > 0.f && !o.outsideLightsOnly &&
        !(glm::all(glm::lessThanEqual(glm::abs(o.point.position), glm::vec3(1099511627776.f)))))
      throw std::invalid_argument("point_position lies too far from the scene (more than 2^40 = 1.1e12 of its local "
                                  "units) for photons to start there in single precision: its light there is nil; "
                                  "move it closer or set point_intensity to 0");
    spot_ = o.point.spot();
    // Power of an isotropic point light of intensity I: 4 pi I; of a spot of half angle a: 2 pi (1 - cos a) I.
    pointPower_ = double(luminance(o.point.intensity)) * spot_.solidAngle();
    if (!(pointPower_ > 0.0) || o.outsideLightsOnly) pointPower_ = 0.0;
    inner_ = o.outsideLightsOnly ? 0.0 : area_.totalPower() + pointPower_;
    total_ = inner_ + skyPower_ + sunPower_;
    if (!std::isfinite(total_))  // the choice between lights would read NaN (and sample no light)
      throw std::invalid_argument("the lights' power is beyond double precision: lower the lights");
    spotFrame_ = glm::length(o.point.spotDirection) > 0.f ? glm::normalize(o.point.spotDirection) : glm::vec3(0.f, -1.f, 0.f);
    // The faces the point light lies on (within the ray epsilon; the default
    // position is the box's corner): per pass, so boxes first, masks if near.
    if (pointPower_ > 0.0) {
      const float eps = float(sceneScale(s).rayEpsilon);
      const glm::vec3& L = o.point.position;
      const size_t nv = s.positions.size();
      std::vector<uint32_t> near;
      for (size_t f = 0; f < s.faceCount(); ++f) {
        const glm::uvec3& t = s.triangles[f];
        if (t.x >= nv || t.y >= nv || t.z >= nv) continue;  // usableFaceMask refuses it below
        const glm::vec3 &a = s.positions[t.x], &b = s.positions[t.y], &c = s.positions[t.z];
        const glm::vec3 lo = glm::min(glm::min(a, b), c) - eps, hi = glm::max(glm::max(a, b), c) + eps;
        if (L.x >= lo.x && L.x <= hi.x && L.y >= lo.y && L.y <= hi.y && L.z >= lo.z && L.z <= hi.z)
          near.push_back(uint32_t(f));
      }
      if (!near.empty()) {
        const std::vector<glm::vec3> faceN = unitFaceNormals(s);
        const std::vector<uint8_t> ok = usableFaceMask(s);
        const glm::dvec3 Ld(L);
        for (uint32_t f : near) {
          const glm::uvec3& t = s.triangles[f];
          const glm::dvec3 q = closestPointOnTriangle(Ld, glm::dvec3(s.positions[t.x]), glm::dvec3(s.positions[t.y]),
                                                      glm::dvec3(s.positions[t.z]));
          if (ok[f] && glm::length(q - Ld) <= double(eps)) pointOn_.push_back(faceN[f]);
        }
      }
    }
  }
  // A point light on a surface (within the ray epsilon): its light towards
  // the back of a face it lies on is absorbed there (true for d), and the
  // rest leaves from past those faces (rays from it start at
  // pointStart()). Traced from the light itself, the rays hit those faces at
  // t ~ 0 in every direction (the origin lies on them): on their back (all
  // absorbed, the light dark) or their front (photons stored at the light,
  // read 1e30 times too bright by a vertex there; an outside sweep, 5
  // December 2026).
  bool pointBlocked(const glm::vec3& d) const {
    for (const glm::vec3& n : pointOn_)
      if (glm::dot(d, n) <= 0.f) return true;
    return false;
  }
  float pointStart(float eps) const { return pointOn_.empty() ? 0.f : 2.f * eps; }
  bool pointOnSurface() const { return !pointOn_.empty(); }
  bool empty() const { return !(total_ > 0.0); }
  double totalPower() const { return total_; }
  // A point on an area emitter or the point light (the caustic projection
  // aims from it): the origin of a photon, before its direction is drawn.
  struct LightPoint {
    glm::vec3 o, n;   // n: the emitting face's normal (0 for the point light)
    glm::vec3 L;      // radiance E / pi of an area emitter, or the intensity I of the point light
    float pdf;        // pdf of the choice: area density x face choice, or the point light's probability
    bool point;
  };
  LightPoint samplePoint(glm::vec2 u0) const {
    const double pPoint = pointPower_ / inner_;
    if (u0.x < pPoint) return {o_.point.position, glm::vec3(0.f), o_.point.intensity, float(pPoint), true};
    const float ux = float(std::min(0.99999994, (u0.x - pPoint) / (1.0 - pPoint)));
    const auto L = area_.sample({ux, u0.y});
    return {L.p, L.n, L.E * float(M_1_PI), L.pdfArea * float(1.0 - pPoint), false};
  }
  // Whether the point or spot light shines towards d.
  bool inSpot(const glm::vec3& d) const { return spot_.contains(d); }

  struct Emission {
    glm::vec3 o, d, power, n;
    bool point = false;  // from the point or spot light
  };
  // The global photons: cosine-distributed from area emitters, uniform in the
  // spot's cone; photon power for `count` photons in total.
  Emission sample(glm::vec2 u0, glm::vec2 u1, double count) const {
    const double pOut = (skyPower_ + sunPower_) / total_;
    if (u0.x < pOut) return sampleOutside(float(u0.x / pOut), u0.y, u1, pOut, count);
    u0.x = float(std::min(0.99999994, (u0.x - pOut) / (1.0 - pOut)));
    LightPoint lp = samplePoint(u0);
    lp.pdf *= float(1.0 - pOut);
    Emission e{lp.o, {}, {}, lp.n};
    if (lp.point) {
      e.point = true;
      // Flux per photon: I * solid angle / (p_choice * count).
      // By the versine: a cone of 0.5 degrees sampled by its float cosine
      // put 156 of 200k photons on the axis itself (an outside audit).
      e.d = Frame(spotFrame_).toWorld(uniformConeVersine(u1, float(spot_.versine())));
      e.power = lp.L * float(spot_.solidAngle()) / float(lp.pdf * count);
    } else {
      // L cos / (pdf_A * (cos / pi) * count) = pi L / (pdf_A count).
      e.d = Frame(lp.n).toWorld(cosineHemisphere(u1));
      e.power = lp.L * float(M_PI) / float(lp.pdf * count);
    }
    return e;
  }

 private:
  // From the sky (a < pSky of the outside power) or the sun: w towards the
  // light (uniform over the sphere, pdf 1 / (4 pi); uniform in the sun's
  // cone, pdf 1 / Omega), a point uniform on the disk of the aim sphere's
  // radius R facing w, D along w from its centre (outside the scene); the
  // photon carries L / (pdf_w pdf_disk p count).
  Emission sampleOutside(float a, float b, glm::vec2 u1, double pOut, double count) const {
    const double pSky = skyPower_ / (skyPower_ + sunPower_);
    const bool sky = a < pSky;
    const double disk = M_PI * double(aimRadius_) * aimRadius_;
    glm::vec3 w;
    glm::vec3 power;
    if (sky) {
      w = uniformSphere(u1);
      power = o_.outside.skyRadiance * float(4.0 * M_PI * disk / (pOut * pSky * count));
    } else {
      w = Frame(o_.outside.sunDirection).toWorld(uniformCone(u1, o_.outside.sunCos()));
      // L_sun Omega = E_sun.
      power = o_.outside.sunIrradiance * float(disk * sunScale_ / (pOut * (1.0 - pSky) * count));
    }
    const float ad = sky ? a / float(pSky) : (a - float(pSky)) / float(1.0 - pSky);
    const float r = aimRadius_ * std::sqrt(std::clamp(ad, 0.f, 1.f)), phi = 2.f * float(M_PI) * b;
    const glm::vec3 o = aimCentre_ + aimDistance_ * w + Frame(w).toWorld({r * std::cos(phi), r * std::sin(phi), 0.f});
    return {o, -w, power, glm::vec3(0.f)};
  }

  EmitterSampler area_;
  const PhotonOptions& o_;
  glm::vec3 centre_{0.f}, aimCentre_{0.f};
  float radius_ = 0.f, aimRadius_ = 0.f, aimDistance_ = 0.f;
  double skyPower_ = 0.0, sunPower_ = 0.0, inner_ = 0.0;
  double pointPower_ = 0.0, total_ = 0.0;
  Cone spot_;  // the point light's cone
  double sunScale_ = 1.0;
  glm::vec3 spotFrame_;
  std::vector<glm::vec3> pointOn_;  // unit normals of the faces the point light lies on
};

// What one stored photon costs at the peak of a run: the photon (28 bytes),
// the blocks' concatenation and the maps' kd-tree indices. Measured with
// `gi photonmap` on the Cornell box: 1,000,000 photons store 1,856,547 and
// peak 102 MB above a run of 10,000, 55 bytes each; rounded up.
constexpr double kStoredPhotonBytes = 56.0;

std::string defaultMemoryRemedy() {
  return "lower the photons (per pass when progressive: more passes take no more memory)";
}

// The photons stored so far against the memory limit: once over it the
// remaining blocks are skipped, and check() refuses the run with the need
// extrapolated from the paths traced. The run is refused, not cut short: a
// map of part of the photons would carry part of the power.
class StoreBudget {
 public:
  StoreBudget(const PhotonOptions& o, size_t paths)
      : limit_(memoryLimitOrAvailable(o.memoryLimitBytes)), paths_(paths), remedy_(o.memoryRemedy) {}
  bool full() const {
    return failed_.load() || (limit_ != 0 && double(stored_.load()) * kStoredPhotonBytes > double(limit_));
  }
  void add(size_t stored, size_t paths) {
    stored_ += stored;
    traced_ += paths;
  }
  // f, with an allocation that fails all the same (the limit's figure is
  // an estimate; another process may take memory meanwhile) ending the
  // trace as the limit does: check() refuses the run in one sentence, not
  // a bare "out of memory" after minutes (an outside audit).
  template <class F>
  auto guard(F f) {
    return [this, f](auto&&... a) {
      try {
        f(a...);
      } catch (const std::bad_alloc&) {
        failed_ = true;
      }
    };
  }
  void check(const std::string& what) const {
    if (failed_.load())
      throw std::invalid_argument(what + " ran out of memory (" + memoryAmount(double(limit_)) +
                                  " were available when it began); " + remedy());
    if (!full()) return;
    const double need = double(stored_.load()) * kStoredPhotonBytes * double(paths_) / double(std::max<size_t>(traced_, 1));
    requireMemory(need, limit_, what, remedy());
  }

 private:
  std::string remedy() const { return remedy_.empty() ? defaultMemoryRemedy() : remedy_; }
  size_t limit_, paths_;
  std::string remedy_;
  std::atomic<size_t> stored_{0}, traced_{0};
  std::atomic<bool> failed_{false};
};

// Photon g of the seed's sequence: its index in a scrambled Sobol sequence
// of 2^32 points, and the keys of that sequence's scrambles and of its
// path's random numbers. Each further 2^32 photons (a progressive run of
// many passes: 10^8 photons a pass reach 2^32 in the 43rd) get fresh keys,
// an independent randomisation, so no path repeats; the first 2^32 keep the
// keys they always had. Until 3 December 2026 the index wrapped, and pass 43
// on retraced the paths of the first passes.
struct PhotonKeys {
  uint32_t index, pos, dir, rng;
};
PhotonKeys photonKeys(uint32_t seed, uint64_t g, uint32_t posSalt, uint32_t dirSalt) {
  const uint32_t epoch = uint32_t(g >> 32), s = epoch == 0 ? seed : hash3(seed, epoch, 0xe90cu);
  return {uint32_t(g), hash32(s ^ posSalt), hash32(s ^ dirSalt), s};
}

}  // namespace

PhotonOptions whileHolding(const PhotonOptions& o, size_t heldPhotons, double otherBytes) {
  PhotonOptions out = o;
  if (o.memoryLimitBytes == 0) return out;
  const double held = double(heldPhotons) * kStoredPhotonBytes + otherBytes;
  const double left = double(o.memoryLimitBytes) - held;
  out.memoryLimitBytes = left >= 1.0 ? size_t(left) : 1;
  // A refusal names what is left: it says what the rest of the run holds.
  if (held > 0.0)
    out.memoryRemedy = (o.memoryRemedy.empty() ? defaultMemoryRemedy() : o.memoryRemedy) + " (the run's other photons "
                       "hold " + memoryAmount(held) + " of the " + memoryAmount(double(o.memoryLimitBytes)) + ")";
  return out;
}

std::vector<Photon> tracePhotons(const Scene& s, const RayCaster& caster, const PhotonOptions& opt, size_t first,
                                 size_t count, const Progress& progress, PhotonTraceStats& stats,
                                 std::vector<uint8_t>* lastHit) {
  const PhotonLights lights(s, opt);
  if (lights.empty())
    throw std::invalid_argument("the scene has no light: no emitter faces that emit (select them or mark them by face "
                                "quality, with emitter_intensity above 0 and an emitter_color that is not black), no "
                                "point or spot light, no sky and no sun");
  const float eps = float(sceneScale(s).rayEpsilon);
  const std::vector<glm::vec3> altitudes = faceAltitudes(s);
  const PhotonLeave leave{caster, altitudes, eps};
  const std::vector<glm::vec3> faceN = unitFaceNormals(s);
  // Fixed-size blocks, concatenated in order: the result is independent of threads.
  constexpr size_t kBlock = 4096;
  const size_t nBlocks = (count + kBlock - 1) / kBlock;
  std::vector<std::vector<Photon>> blocks(nBlocks);
  std::vector<std::vector<uint8_t>> lastBlocks(lastHit ? nBlocks : 0);
  std::vector<PhotonTraceStats> bstats(nBlocks);

  StoreBudget budget(opt, count);
  // max_depth counts reflections as the reference and the eye pass do (0:
  // direct light only): a path may reach hits 0 .. max_depth.
  const int hits = opt.maxDepth + 1;
  parallelBlocks(nBlocks, progress, "tracing photons", budget.guard([&](size_t b0, size_t b1) {
    for (size_t b = b0; b < b1; ++b) {
      if (budget.full()) continue;
      auto& out = blocks[b];
      PhotonTraceStats& st = bstats[b];
      const size_t end = std::min(count, (b + 1) * kBlock);
      for (size_t i = b * kBlock; i < end; ++i) {
        const PhotonKeys k = photonKeys(opt.seed, uint64_t(first) + i, 0x9e37u, 0x51edu);
        const auto em = lights.sample(sobolOwen2D(k.index, k.pos), sobolOwen2D(k.index, k.dir), double(count));
        glm::vec3 power = em.power;
        st.emittedRGB += glm::dvec3(power);
        if (em.point && lights.pointBlocked(em.d)) continue;  // into the surface the light lies on
        Rng rng(hash3(k.index, k.rng, 0x7u));
        Ray ray;
        ray.o = em.o + em.n * eps;
        ray.d = em.d;
        if (em.point) ray.tnear = lights.pointStart(eps);
        int diffuse = 0;
        bool viaSpecular = false;
        int depth = 0;
        bool flaggedLast = false;  // stored at the last hit, outside the gather's map: counted as lost there
        for (; depth < hits; ++depth) {
          const Hit h = caster.intersect(ray);
          if (!h.valid()) { ++st.escaped; break; }
          const glm::vec3 x = ray.o + ray.d * h.t;
          const Material m = s.faceMaterial(h.face);
          const glm::vec3 ng = faceN[h.face];
          if (isSpecular(m)) {
            if (!specularStep(s, h, ng, x, eps, leave, rng, ray, power, st.totalInternal)) break;
            ++st.specularBounces;
            viaSpecular = true;
            continue;
          }
          // Diffuse and glossy faces are one-sided, as in the radiosity
          // filter and the reference: the back of a face is black.
          if (glm::dot(ng, ray.d) > 0.f) break;
          if (m == Material::Glossy) {
            // Not stored (no diffuse light to estimate there); a caustic path's S (gi/specular.h).
            if (!glossyStep(s, h, ng, leave, rng, ray, power)) break;
            ++st.glossyBounces;
            viaSpecular = true;
            continue;
          }
          const uint8_t path = diffuse > 0 ? kIndirectPhoton : viaSpecular ? kCausticPhoton : kDirectPhoton;
          out.push_back({x, power, packNormal(ng), path});
          if (lastHit) {
            // The hits left after this one; at the last allowed hit (but a
            // caustic's, which the caustic map keeps) the power the path
            // carries on is counted apart (lastHitCutPower).
            lastBlocks[b].push_back(uint8_t(std::min(opt.maxDepth - depth, 255)));
            flaggedLast = depth == opt.maxDepth && path != kCausticPhoton;
          }
          st.storedPower += luminance(power);
          (path == kDirectPhoton ? st.direct : path == kCausticPhoton ? st.caustic : st.indirect)++;
          const glm::vec3 rho = s.faceRho(h.face);
          const float q = std::min(1.f, std::max({rho.r, rho.g, rho.b}));
          if (!(q > 0.f) || rng.next() >= q) break;  // Russian roulette: absorbed
          power *= rho / q;
          ++diffuse;
          ++st.diffuseBounces;
          ray.o = leave(ray, h, ng);
          ray.d = Frame(ng).toWorld(cosineHemisphere({rng.next(), rng.next()}));
          ray.tnear = 0.f;
          ray.tfar = std::numeric_limits<float>::infinity();
        }
        if (depth == hits) {
          ++st.lostAtMaxDepth;
          if (!flaggedLast) st.lostPower += luminance(power), st.lostRGB += glm::dvec3(power);
          else st.lastHitCutPower += luminance(power), st.lastHitCutRGB += glm::dvec3(power);
        }
      }
      // Trimmed to what it holds: growth by doubling leaves up to twice.
      out.shrink_to_fit();
      if (lastHit) lastBlocks[b].shrink_to_fit();
      budget.add(out.size(), end - b * kBlock);
    }
  }));
  const std::string what = "the photon map of " + std::to_string(count) + " photons";
  budget.check(what);
  // Concatenate block by block, freeing each, so the peak stays near one copy.
  size_t total = 0;
  for (const auto& b : blocks) total += b.size();
  std::vector<Photon> all;
  budget.guard([&] {
    all.reserve(total);
    if (lastHit) {
      lastHit->clear();
      lastHit->reserve(total);
    }
  })();
  budget.check(what);
  for (size_t b = 0; b < nBlocks; ++b) {
    all.insert(all.end(), blocks[b].begin(), blocks[b].end());
    std::vector<Photon>().swap(blocks[b]);
    if (lastHit) lastHit->insert(lastHit->end(), lastBlocks[b].begin(), lastBlocks[b].end());
    const auto& t = bstats[b];
    stats.caustic += t.caustic;
    stats.direct += t.direct;
    stats.indirect += t.indirect;
    stats.diffuseBounces += t.diffuseBounces;
    stats.specularBounces += t.specularBounces;
    stats.glossyBounces += t.glossyBounces;
    stats.totalInternal += t.totalInternal;
    stats.lostAtMaxDepth += t.lostAtMaxDepth;
    stats.escaped += t.escaped;
    stats.storedPower += t.storedPower;
    stats.lostPower += t.lostPower;
    stats.lostRGB += t.lostRGB;
    stats.lastHitCutPower += t.lastHitCutPower;
    stats.lastHitCutRGB += t.lastHitCutRGB;
    stats.emittedRGB += t.emittedRGB;
  }
  stats.stored = stats.direct + stats.caustic + stats.indirect;
  stats.emitted += count;
  stats.pointOnSurface = lights.pointOnSurface();
  stats.emittedPower = lights.totalPower();
  ++stats.passes;
  return all;
}

namespace {

// Bounding spheres of the connected groups of mirror, glass and glossy faces.
struct SpecularTarget {
  glm::vec3 c;
  float r;
};
std::vector<SpecularTarget> specularTargets(const Scene& s) {
  std::vector<uint32_t> parent(s.vertexCount());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  const auto ok = usableFaceMask(s);
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f] && isCausticSurface(s.faceMaterial(f)))
      for (int k = 1; k < 3; ++k) parent[find(s.triangles[f][k])] = find(s.triangles[f][0]);
  std::vector<int> group(s.vertexCount(), -1);
  std::vector<glm::vec3> lo, hi;
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!ok[f] || !isCausticSurface(s.faceMaterial(f))) continue;
    const uint32_t root = find(s.triangles[f][0]);
    if (group[root] < 0) {
      group[root] = int(lo.size());
      lo.push_back(glm::vec3(HUGE_VALF));
      hi.push_back(glm::vec3(-HUGE_VALF));
    }
    for (int k = 0; k < 3; ++k) {
      lo[size_t(group[root])] = glm::min(lo[size_t(group[root])], s.positions[s.triangles[f][k]]);
      hi[size_t(group[root])] = glm::max(hi[size_t(group[root])], s.positions[s.triangles[f][k]]);
    }
  }
  std::vector<SpecularTarget> out;
  for (size_t g = 0; g < lo.size(); ++g) {
    const glm::vec3 c = 0.5f * (lo[g] + hi[g]);
    out.push_back({c, glm::length(hi[g] - lo[g]) * 0.5f * 1.001f + 1e-6f});
  }
  return out;
}

// A direction from o towards one of the targets' spheres: the sphere chosen
// in proportion to the solid angle of its cone, the direction uniform in the
// cone; pdf = (number of cones containing it) / (sum of the cones' solid
// angles). False (and nothing drawn) if o lies inside a sphere.
bool aimAtTargets(const std::vector<SpecularTarget>& targets, const glm::vec3& o, glm::vec2 u, glm::vec3& d, float& pdf) {
  thread_local std::vector<float> omega, cosMax;
  omega.resize(targets.size());
  cosMax.resize(targets.size());
  float total = 0.f;
  for (size_t t = 0; t < targets.size(); ++t) {
    const float l = glm::length(targets[t].c - o);
    if (l <= targets[t].r) return false;
    cosMax[t] = std::sqrt(std::max(0.f, 1.f - (targets[t].r / l) * (targets[t].r / l)));
    omega[t] = 2.f * float(M_PI) * (1.f - cosMax[t]);
    total += omega[t];
  }
  float acc = 0.f;
  size_t t = 0;
  for (; t + 1 < targets.size() && u.x * total >= acc + omega[t]; ++t) acc += omega[t];
  u.x = std::clamp((u.x * total - acc) / omega[t], 0.f, 0.99999994f);
  d = Frame(glm::normalize(targets[t].c - o)).toWorld(uniformCone(u, cosMax[t]));
  pdf = 0.f;
  for (size_t k = 0; k < targets.size(); ++k) {
    const glm::vec3 a = targets[k].c - o;
    if (glm::dot(d, a) / glm::length(a) >= cosMax[k]) pdf += 1.f / total;
  }
  return true;
}

}  // namespace

std::vector<Photon> traceCausticPhotons(const Scene& s, const RayCaster& caster, const PhotonOptions& opt, size_t first,
                                        size_t count, const Progress& progress, PhotonTraceStats& stats) {
  const PhotonLights lights(s, opt);
  const std::vector<SpecularTarget> targets = specularTargets(s);
  if (lights.empty() || targets.empty()) return {};
  const float eps = float(sceneScale(s).rayEpsilon);
  const std::vector<glm::vec3> altitudes = faceAltitudes(s);
  const PhotonLeave leave{caster, altitudes, eps};
  const std::vector<glm::vec3> faceN = unitFaceNormals(s);
  constexpr size_t kBlock = 4096;
  const size_t nBlocks = (count + kBlock - 1) / kBlock;
  std::vector<std::vector<Photon>> blocks(nBlocks);
  std::vector<size_t> specular(nBlocks, 0), glossy(nBlocks, 0), missed(nBlocks, 0);

  StoreBudget budget(opt, count);
  parallelBlocks(nBlocks, progress, "tracing caustic photons", budget.guard([&](size_t b0, size_t b1) {
    for (size_t b = b0; b < b1; ++b) {
      if (budget.full()) continue;
      const size_t end = std::min(count, (b + 1) * kBlock);
      for (size_t i = b * kBlock; i < end; ++i) {
        const PhotonKeys k = photonKeys(opt.seed, uint64_t(first) + i, 0xca57u, 0xca58u);
        const auto lp = lights.samplePoint(sobolOwen2D(k.index, k.pos));
        glm::vec2 u = sobolOwen2D(k.index, k.dir);
        Ray ray;
        ray.o = lp.o + lp.n * eps;
        glm::vec3 power;
        glm::vec3 d;
        float pdfW = 0.f;
        if (!aimAtTargets(targets, lp.o, u, d, pdfW)) {
          // The light point lies within a target's sphere: every direction
          // may reach it; draw them as the global photons do.
          const auto e = lights.sample(sobolOwen2D(k.index, k.pos), u, double(count));
          d = e.d;
          power = e.power;
        } else if (lp.point) {
          if (!lights.inSpot(d)) continue;
          power = lp.L / (lp.pdf * pdfW * float(count));
        } else {
          const float c = glm::dot(d, lp.n);
          if (c <= 0.f) continue;
          power = lp.L * c / (lp.pdf * pdfW * float(count));
        }
        if (lp.point && lights.pointBlocked(d)) continue;  // into the surface the light lies on
        ray.d = d;
        if (lp.point) ray.tnear = lights.pointStart(eps);
        Rng rng(hash3(k.index, k.rng, 0xc5u));
        bool viaSpecular = false;
        // Stored at the diffuse hit after at most max_depth specular bounces.
        for (int depth = 0; depth <= opt.maxDepth; ++depth) {
          const Hit h = caster.intersect(ray);
          if (!h.valid()) break;
          const Material m = s.faceMaterial(h.face);
          const glm::vec3 x = ray.o + ray.d * h.t, ng = faceN[h.face];
          if (m == Material::Diffuse) {
            // L S+ D: stored at the first diffuse front face. A first hit on a
            // diffuse face is not a caustic path: the global photons carry it.
            if (viaSpecular && glm::dot(ng, ray.d) < 0.f) blocks[b].push_back({x, power, packNormal(ng), kCausticPhoton});
            if (!viaSpecular) ++missed[b];
            break;
          }
          if (m == Material::Glossy) {
            if (glm::dot(ng, ray.d) > 0.f || !glossyStep(s, h, ng, leave, rng, ray, power)) break;
            ++glossy[b];
          } else {
            size_t tir = 0;
            if (!specularStep(s, h, ng, x, eps, leave, rng, ray, power, tir)) break;
            ++specular[b];
          }
          viaSpecular = true;
        }
      }
      blocks[b].shrink_to_fit();  // growth by doubling left caustic blocks 1.56 times their photons
      budget.add(blocks[b].size(), end - b * kBlock);
    }
  }));
  const std::string what = "the caustic map of " + std::to_string(count) + " photons";
  budget.check(what);
  std::vector<Photon> all;
  size_t total = 0;
  for (const auto& b : blocks) total += b.size();
  budget.guard([&] { all.reserve(total); })();
  budget.check(what);
  for (size_t b = 0; b < nBlocks; ++b) {
    all.insert(all.end(), blocks[b].begin(), blocks[b].end());
    std::vector<Photon>().swap(blocks[b]);
    stats.specularBounces += specular[b];
    stats.glossyBounces += glossy[b];
    stats.causticMissed += missed[b];
  }
  stats.causticEmitted += count;
  stats.causticStored += all.size();
  return all;
}

}  // namespace gi
