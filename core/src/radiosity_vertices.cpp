// The vertex values of a radiosity solution (radiosity_vertices.h): direct
// light at the vertices, and the final gather of the patch solution with a
// multi-level gather at near hits and rays shared between neighbours.
#include "radiosity_vertices.h"

#include <atomic>
#include <cstring>
#include <limits>

#include "gi/ao_shared.h"
#include "gi/color.h"
#include "gi/direct.h"
#include "gi/sampling.h"
#include "gi/scene_setup.h"
#include "gi/sky.h"
#include "hit_origin.h"

namespace gi {

namespace {

// The indirect irradiance at each vertex by a final gather of the patch
// solution: cosine-weighted rays, so the estimate is the mean of the
// reflected radiosity seen. Near hits (within two patch edges) see the
// patch up close, where its average is wrong twice over: it hides how the
// direct light varies across it (the shadow of an object standing on it, a
// shadow edge), and next to a concave edge (a wall meeting the ceiling) the
// indirect light falls steeply towards the edge, where the other surface
// fills half the sky. The corner patches' mean then overstates what a point
// at the edge receives (by a fifth in the Cornell-like room), and vertices
// on the edge, half of whose rays land there, came out 5-10% too bright.
// So at a near hit the direct light is evaluated at the point itself and its
// indirect light gathered again with one cosine ray, whose own near hit is
// treated the same way, down to kNearLevels levels: a multi-level gather.
// One ray per level is enough, as a vertex averages its many near hits; the
// direct light keeps 4 light samples per point (with 1, a closed furnace
// box gathered with 64 rays per vertex is 1% off at its corners).
// The same for a fixed bounce count K: the vertex gathers R^(K), the
// reflected radiosity after K bounces; a near hit is relit as R^(m)(y) =
// rho (H_direct(y) + H^(m-1)(y)) with m = K, its indirect part gathered
// again from the values of one bounce fewer (R^(m-1): a far hit reads the
// patch's, a near one is relit the same way), and with no levels left the
// patch's own, rho F R^(m-1) = R^(m) - R^(1). With one bounce a near hit
// reflects its direct light alone (exact: no patch value needed). Reading
// the patch instead, an outside check (4 December 2026) found the
// ceiling's edge vertices of a sealed room 25% bright with one bounce and
// 6.6% with two.
constexpr int kNearLevels = kGatherNearLevels;
// The converged solution's near hits go on past those levels: where three
// surfaces meet (a room's corner) each level's ray lands near the corner
// again, where the light is far below the patch's mean (on a room of two
// triangles a wall, 0.48 against 0.83 at the ceiling's corner), and reading
// the mean there made the corner vertices 8-10% bright (an outside check,
// 5 December 2026).
constexpr int kMaxNearChain = 64;

std::vector<glm::vec3> gatherIndirect(const Scene& s, const RayCaster& caster, const VertexMaterial& mat,
                                      const RadiosityOptions& opt, RadiosityResult& res, const Progress& progress) {
  const uint32_t seed = opt.formFactors.seed;
  // K fixed bounces (K < 0: the converged solution): the patch values R^(m)
  // the near hits read, where the solver kept them (res.Rbounces).
  const int K = opt.bounces;
  const bool haveBounces = K > 0 && res.Rbounces.size() == size_t(K);
  const bool refineNear = K < 0 || K == 1 || haveBounces;  // one bounce reads no patch values
  const int nearLevels = K == 1 ? 0 : kNearLevels;
  // R^(m) of face f (m < 0: converged, m = 0: nothing reflected yet).
  const auto patchR = [&](uint32_t f, int m) -> glm::vec3 {
    return m < 0 ? res.Rgather[f] : m == 0 ? glm::vec3(0.f) : res.Rbounces[size_t(m - 1)][f];
  };
  // Face f's own indirect irradiance in R^(m): F R^(m-1) = (R^(m) - R^(1)) / rho.
  const auto patchH = [&](uint32_t f, int m) -> glm::vec3 {
    if (m < 0) return res.Hindirect[f];
    if (m <= 1) return glm::vec3(0.f);
    const glm::vec3 rho = s.faceRho(f), d = res.Rbounces[size_t(m - 1)][f] - res.Rbounces[0][f];
    return {rho.r > 0 ? d.r / rho.r : 0.f, rho.g > 0 ? d.g / rho.g : 0.f, rho.b > 0 ? d.b / rho.b : 0.f};
  };
  const DirectLightAt directAt(s, caster, 4);
  const float eps = float(sceneScale(s).rayEpsilon);
  const std::vector<glm::vec3> faceN = unitFaceNormals(s);
  const std::vector<glm::vec3> faceAlt = faceAltitudes(s);
  // Per face, what a gather ray reads at its hit, in one place (one cache
  // line per hit on a large mesh): the reflected radiosity and the distance
  // within which the hit is near.
  struct FaceRead {
    glm::vec3 R;
    float nearT;
  };
  std::vector<FaceRead> faceRead(s.faceCount());
  for (size_t f = 0; f < s.faceCount(); ++f)
    faceRead[f] = {res.Rgather[f], float(2.0 * std::sqrt(2.0 * faceArea(s, f)))};
  std::atomic<uint64_t> nearHits{0};
  // R^(m) at the hit y = o + d t on face f (m = K at the vertex's own
  // hits); border: a lower bound of y's distance to its triangle's border
  // (hitBorder); u: a 2D sample for its own gather ray. A near hit's rays
  // leave from hitRayOrigin (hit_origin.h): lifted along the normal, or
  // near an acute corner on the free segment it came along (lifted there,
  // a sky outside a closed tetrahedron lit its corner vertices 0.037 of
  // the ground's 0.50).
  const auto reflectedAt = [&](const auto& self, uint32_t f, const glm::vec3& o, const glm::vec3& d, float t,
                               float border, glm::vec2 u, uint32_t key, int levels, int m) -> glm::vec3 {
    if (m == 0) return glm::vec3(0.f);
    if (t > faceRead[f].nearT) return patchR(f, m);
    nearHits.fetch_add(1, std::memory_order_relaxed);
    const glm::vec3 n = faceN[f], y = o + d * t;
    const glm::vec3 from = hitRayOrigin(caster, o, d, t, n, eps, border);
    const glm::vec3 mean = patchH(f, m);
    glm::vec3 Hi = mean;
    // Past the levels, the converged solution goes on by Russian roulette
    // on the difference from the patch's mean: with probability q (the
    // largest reflectance) the mean plus (gathered - mean) / q, else the
    // mean, whose expectation is the gathered value (unbiased), and where
    // the mean is right (a furnace) nearly as quiet as the mean alone. A
    // chain longer than kMaxNearChain (about q^64 rare) stops at the mean.
    float keep = 1.f;
    bool gather = levels > 0 && m != 1, roulette = false;
    if (!gather && m < 0 && levels > -kMaxNearChain) {
      const glm::vec3 rho = s.faceRho(f);
      keep = std::min(0.95f, std::max(rho.r, std::max(rho.g, rho.b)));
      gather = roulette = keep > 0.f && toUnitFloat(hash3(key, 0x5eu, 0x77u)) < keep;
    }
    if (gather) {
      Ray r;
      r.o = from;
      r.d = Frame(n).toWorld(cosineHemisphere(u));
      r.tfar = std::numeric_limits<float>::infinity();
      const Hit h = caster.intersect(r);
      Hi = glm::vec3(0.f);
      if (h.valid() && glm::dot(r.d, faceN[h.face]) < 0.f) {
        const uint32_t next = hash3(key, h.face, 0x53u);
        Hi = self(self, h.face, r.o, r.d, h.t, hitBorder(faceAlt, h.face, h.u, h.v),
                  glm::vec2(toUnitFloat(next), toUnitFloat(hash32(next))), next, levels - 1, m < 0 ? m : m - 1);
      }
      if (roulette) Hi = mean + (Hi - mean) / keep;
    }
    const glm::vec3 Hout = skySunIrradianceAt(opt.outside, caster, from, n, 4, key);
    return s.faceRho(f) * (directAt(y, from, n, key) + Hout + Hi);
  };
  // A near hit's own ray takes the second dimension pair of a padded Sobol
  // sequence of the vertex, so the rays of one vertex's near hits are
  // stratified together.
  auto seen = [&](const GatherHit& g) {
    const FaceRead& fr = faceRead[g.face];
    if (!refineNear || g.t > fr.nearT) return fr.R;
    uint32_t bits[3];
    std::memcpy(bits, &g.point, sizeof bits);
    const glm::vec2 u = PaddedSobol(hash3(g.vertex, seed, 0xfbu))(g.ray, 1);
    return reflectedAt(reflectedAt, g.face, g.origin, g.dir, g.t, hitBorder(faceAlt, g.face, g.u, g.v), u,
                       hash3(bits[0] ^ seed, bits[1], bits[2] ^ g.face), nearLevels, K);
  };
  // The rays' luminance statistics only where the vertices pool them.
  const bool share = opt.gatherShareRings > 0;
  std::vector<VertexRays> lum;
  std::vector<glm::vec3> Hi =
      finalGather(s, caster, mat, opt.gatherRays, seed, seen, opt.vertices, progress, share ? &lum : nullptr);
  if (share) {
    PoolOptions po;
    po.bounded = false;
    po.maxRings = opt.gatherShareRings;
    Hi = poolMeans(s, mat.n, Hi, lum, po, opt.vertices, &res.stats);
  }
  // The roulette's samples may be negative (a dark corner under a bright
  // patch's mean); a vertex's mean of them below 0 (a few rays) is 0.
  for (glm::vec3& h : Hi) h = glm::max(h, glm::vec3(0.f));
  res.stats.add("gather_rays", double(opt.vertices.count(s.vertexCount())) * opt.gatherRays);
  if (refineNear) res.stats.add("gather_near_hits_relit", double(nearHits.load()));
  return Hi;
}

}  // namespace

// Vertex values B = E + rho (H_direct + H_indirect) with the exact direct
// light at each vertex and the indirect light gathered (final gather:
// visibility at the vertex itself, no leaks under objects that cut through
// patches) or interpolated from the incident patches.
void radiosityVertexValues(const Scene& s, const RayCaster& caster, const RadiosityOptions& opt, RadiosityResult& res,
                           const Progress& progress, const SkyOpenings* openings) {
  Timer vt;
  const VertexMaterial mat = vertexMaterial(s);
  const bool gather = opt.vertexOutput == RadiosityVertexOutput::FinalGather;
  // Progress: shadow rays, sky and sun, then the gather's many more rays.
  const double d = gather ? 0.25 : 0.8, o = gather ? 0.35 : 1.0;
  Timer st;
  std::vector<glm::vec3> Hd =
      vertexDirectIrradiance(s, caster, opt.lightSamples, opt.formFactors.seed, progress.sub(0.0, d), opt.vertices);
  res.stats.add("vertex_direct_seconds", st.seconds());
  Timer ot;
  const std::vector<glm::vec3> Hout = vertexSkySunIrradiance(s, caster, opt.outside, opt.lightSamples,
                                                             opt.formFactors.seed, opt.vertices, progress.sub(d, o), openings);
  if (opt.outside.any()) res.stats.add("vertex_sky_sun_seconds", ot.seconds());
  for (size_t v = 0; v < Hd.size(); ++v) Hd[v] += Hout[v];
  Timer gt;
  const std::vector<glm::vec3> Hi =
      gather ? gatherIndirect(s, caster, mat, opt, res, progress.sub(o, 1.0)) : faceToVertex(s, res.Hindirect, res.seenShare);
  if (gather) res.stats.add("final_gather_seconds", gt.seconds());
  res.Bdirect.assign(s.vertexCount(), glm::vec3(0.f));
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    if (!mat.valid[v]) {
      res.Bvertex[v] = glm::vec3(0.f);
      continue;
    }
    res.Bdirect[v] = mat.E[v] + mat.rho[v] * Hd[v];
    // The ambient term A = mean unshot / (1 - rho-bar) stands for every
    // bounce of the unshot radiosity; the indirect light gathered here (from
    // the patches' reflected radiosity, unshot included) already holds its
    // first, so a vertex adds the rest, rho-bar A. (Adding A counted the first
    // bounce twice: a furnace of rho 0.90 read 6.6% bright at a tolerance of
    // 0.5, the patches right; an outside audit.)
    res.Bvertex[v] = mat.E[v] + mat.rho[v] * (Hd[v] + Hi[v] + res.ambientRho * res.ambient);
  }
  // A vertex of a two-sided surface (each face with a reversed copy) has
  // no normal, its faces' cancel (as has one whose normal in the file is
  // zero): no side to evaluate the light on. It takes the patch average of
  // its faces, both sides (what 'Patch average' writes everywhere), and
  // the log says how many did.
  std::vector<glm::vec3> average;
  size_t nTwoSided = 0;
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    if (mat.valid[v] || !mat.diffuse[v] || !opt.vertices.contains(v, s.vertexCount())) continue;
    if (average.empty()) average = faceToVertex(s, res.B, res.seenShare);
    res.Bvertex[v] = average[v];
    ++nTwoSided;
  }
  if (nTwoSided)
    res.stats.note(std::to_string(nTwoSided) + " vertices without a normal (on a two-sided surface their faces' " +
                   "normals cancel): the patch average of their faces, both sides");
  res.stats.add("vertex_output_seconds", vt.seconds());
  res.stats.note(gather ? "vertices: direct light and a final gather of the patch solution at each vertex"
                        : "vertices: direct light at each vertex, indirect interpolated from the patches");
}

}  // namespace gi
