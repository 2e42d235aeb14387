// The first pass's data for the two-pass mode (Chen, Rushmeier, Miller and
// Turner 1991, "A Progressive Multi-Pass Method for Global Illumination";
// Jensen 1996, "Global Illumination using Photon Maps", the rendering pass):
// the per-vertex radiosity B split into what the eye pass recomputes and
// what it reads from the mesh.
//   R        = B - E (>= 0)               reflected radiosity (Map, FinalGather)
//   indirect = B - Bdirect [- rho Hc]     the part due to light that bounced on a
//                                         diffuse surface first (DirectIndirect,
//                                         Caustics; FinalGather at near hits), where Bdirect = E + rho H_direct
//                                         (photon mapping's own, the attribute
//                                         RadiosityDirect, else estimated here at
//                                         the vertices) and Hc the caustic map's
//                                         irradiance at the vertex (removed when
//                                         the first pass has caustics, since the
//                                         eye pass reads them from the map at the
//                                         hit point).
// The indirect part is a difference of noisy estimates and may dip below 0
// at some vertices: it is kept as it is (clamping zero-mean noise would
// bias it upwards); the eye pass keeps the diffuse radiance of a hit >= 0,
// and the log counts such vertices.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "gi/color.h"
#include "gi/direct.h"
#include "gi/memory_limit.h"
#include "gi/sky.h"
#include "gi/specular.h"
#include "render_internal.h"

namespace gi::eye {

TwoPassData::TwoPassData() = default;
TwoPassData::~TwoPassData() = default;

namespace {

constexpr int kVertexDirectSamples = 256;  // shadow rays per vertex when Bdirect is not given

void checkPerVertex(const std::vector<glm::vec3>& v, size_t nv, const char* what) {
  if (v.size() != nv)
    throw std::invalid_argument(std::string(what) + " has " + std::to_string(v.size()) + " values for " +
                                std::to_string(nv) + " vertices");
  size_t bad = 0;
  for (const auto& c : v)
    for (int k = 0; k < 3; ++k)
      if (!(c[k] >= 0.f) || !std::isfinite(c[k])) ++bad;
  if (bad)
    throw std::invalid_argument(std::string(what) + " has " + std::to_string(bad) +
                                " negative or non-finite channels (a radiosity is a finite value >= 0)");
}

}  // namespace

void prepareTwoPass(TwoPassData& tp, const Scene& s, const RayCaster& caster, const RenderOptions& o,
                    const PhotonMemory& memory, const Progress& progress, RunStats& stats) {
  const size_t nv = s.vertexCount();
  if (o.firstPassB.empty())
    throw std::invalid_argument("the two-pass mode needs a first pass on these layers: run 'GI: Radiosity' or "
                                "'GI: Photon Mapping' (which store the per-vertex radiosity) first, in the same "
                                "MeshLab session or script (MeshLab 2020.09 does not read per-vertex attributes "
                                "such as Radiosity from a PLY file; the gi tool does)");
  checkPerVertex(o.firstPassB, nv, "the first pass's radiosity");
  const VertexMaterial mat = vertexMaterial(s);
  tp.R.resize(nv);
  size_t negative = 0;
  for (size_t i = 0; i < nv; ++i) tp.R[i] = glm::max(o.firstPassB[i] - mat.E[i], glm::vec3(0.f));
  // This view's own lights (a point light, the sky, the sun) reach the
  // diffuse surfaces only through what the first pass stored of them: with
  // 'First pass alone' not at all, with the others by their direct light,
  // their indirect light only if the first pass had them (radiosity has no
  // point light). A point light given here only changed nothing, silently
  // (an outside audit).
  if (o.point.on() || o.outside().any()) {
    const SkySun out = o.outside();
    std::vector<std::string> names;
    if (o.point.on()) names.push_back("point light");
    if (out.sky()) names.push_back("sky");
    if (out.sun()) names.push_back("sun");
    std::string lights = names[0];
    for (size_t k = 1; k < names.size(); ++k) lights += (k + 1 == names.size() ? " and " : ", ") + names[k];
    const bool one = names.size() == 1;
    stats.note(o.twoPass == TwoPassDiffuse::Map
                   ? "'First pass alone': the diffuse surfaces take no light from this view's " + lights +
                         " but what the first pass stored (give it the same lights; radiosity has no point light)"
                   : "this view's " + lights + (one ? " adds its" : " add their") + " direct light; " +
                         (one ? "its" : "their") + " indirect light is the first pass's (give it the same lights; "
                         "radiosity has no point light)");
  }
  const bool wantCaustics = o.twoPass == TwoPassDiffuse::Caustics || o.twoPass == TwoPassDiffuse::FinalGather;
  if (wantCaustics && anyFaceMaterial(s, isCausticSurface)) {
    Timer t;
    PhotonOptions po;
    po.photons = o.causticPhotons;
    po.causticK = o.causticK;
    po.point = o.point;
    po.seed = o.seed;
    // The eye pass's limit: a caustic through k mirrors or glass is k reflections.
    po.maxDepth = std::min(o.maxDepth, 1000);
    po.memoryLimitBytes = memory.limitBytes;
    po.memoryRemedy = "lower caustic_photons";
    if (memory.imageBytes > 0)
      po.memoryRemedy += ", or width and height (the image takes another " + memoryAmount(memory.imageBytes) + ")";
    PhotonTraceStats ts;
    std::vector<Photon> photons =
        traceCausticPhotons(s, caster, po, 0, size_t(o.causticPhotons), progress.sub(0.0, 0.25), ts);
    const SkySun outside = o.outside();
    if (outside.any()) {
      // Projection aims from points on the lights, and the sky and the sun
      // have none in the scene: as photon mapping does with them, their
      // caustic photons come from a trace of their own (caustic_photons
      // paths, aimed at the openings where those are the only way in), kept
      // where they came through mirrors, glass or glossy faces. Without
      // them the sun through a glass window or off a mirror was black where
      // the final gather reads the map (an outside review).
      PhotonOptions out = whileHolding(po, photons.size());
      out.outside = outside;
      out.outsideLightsOnly = true;
      aimAtOpenings(findSkyOpenings(s, caster, outside, o.seed), s, out);
      PhotonTraceStats tsOut;
      const std::vector<Photon> all =
          tracePhotons(s, caster, out, 0, size_t(o.causticPhotons), progress.sub(0.25, 0.5), tsOut);
      size_t kept = 0;
      for (const Photon& p : all)
        if (p.path == kCausticPhoton) photons.push_back(p), ++kept;
      stats.add("caustic_photons_sky_sun_paths", double(tsOut.emitted));
      stats.add("caustic_photons_sky_sun_stored", double(kept));
    }
    const size_t stored = photons.size();
    tp.r2max = o.causticMaxRadius > 0 ? float(o.causticMaxRadius * o.causticMaxRadius) : HUGE_VALF;
    // Its kd-tree over millions of photons takes seconds (20 million aimed
    // on the caustic Cornell box: 6.4 million stored, 12 s with the
    // tracing) with nothing said: the bar looked stuck (an outside audit).
    if (stored) {
      progress.report(0.5, "building the caustic map (" + std::to_string(stored) + " photons)");
      tp.caustics = std::make_unique<CausticMap>(std::move(photons), s);
    }
    stats.add("caustic_photons_aimed", double(ts.causticEmitted));
    stats.add("caustic_photons_stored", double(stored));
    stats.add("caustic_map_seconds", t.seconds());
    if (!stored) stats.note("no caustic photon reached a diffuse surface through mirrors, glass or glossy faces");
    // As photon mapping warns (photon_checks.cpp); the view said nothing
    // until 5 December 2026 (caustic_photons 1: the brightest pixel 4 times
    // too bright).
    if (const auto w = smallKWarning("caustic_k", o.causticK))
      stats.warn(*w);
    else if (stored && stored < size_t(o.causticK))
      stats.warn("caustic_k " + std::to_string(o.causticK) + " exceeds the " + std::to_string(stored) +
                 " photons of the caustic map: every estimate spans them all (one blurred average); raise "
                 "caustic_photons");
  } else if (wantCaustics) {
    stats.note("no caustic map: the scene has no mirror, glass or glossy faces");
  }
  if (o.twoPass == TwoPassDiffuse::FinalGather) {
    // Near gather hits are relit at the point (render_integrators.cpp):
    // within two patch edges of a hit face, as radiosity's own gather.
    tp.nearT.resize(s.faceCount());
    for (size_t f = 0; f < s.faceCount(); ++f) tp.nearT[f] = float(2.0 * std::sqrt(2.0 * faceArea(s, f)));
  }
  if (o.twoPass == TwoPassDiffuse::DirectIndirect || o.twoPass == TwoPassDiffuse::Caustics ||
      o.twoPass == TwoPassDiffuse::FinalGather) {
    std::vector<glm::vec3> Bd = o.firstPassBdirect;
    if (!Bd.empty()) {
      checkPerVertex(Bd, nv, "the first pass's direct radiosity");
      // Its direct part is part of it: B >= Bdirect (up to rounding) wherever
      // the two come from one run; one left by an earlier run (a later
      // radiosity pass replaced B) is not used.
      size_t above = 0;
      for (size_t i = 0; i < nv; ++i)
        for (int k = 0; k < 3; ++k)
          if (Bd[i][k] - o.firstPassB[i][k] > 1e-5f * std::max(Bd[i][k], 1e-30f)) { ++above; break; }
      if (above) {
        stats.note("the stored direct part exceeds the first pass's radiosity at " + std::to_string(above) +
                   " vertices (left by another run): not used");
        Bd.clear();
      } else {
        stats.note(o.twoPass == TwoPassDiffuse::FinalGather
                       ? "the first pass's own direct part replaced by ray-traced direct light at near gather hits"
                       : "the first pass's own direct part replaced by ray-traced direct light");
      }
    }
    if (Bd.empty()) {
      // Estimated here, from this view's lights, taken to be the first
      // pass's: the emitting faces, the sky and the sun, the point light.
      Timer t;
      std::vector<glm::vec3> Hd =
          vertexDirectIrradiance(s, caster, kVertexDirectSamples, o.seed ^ 0x2b0du, progress.sub(0.5, 0.75));
      const SkySun outside = o.outside();
      if (outside.any()) {
        const std::vector<glm::vec3> Hout = vertexSkySunIrradiance(s, caster, outside, kVertexDirectSamples,
                                                                   o.seed ^ 0x5c1du, VertexPart(), progress.sub(0.75, 1.0));
        for (size_t i = 0; i < nv; ++i) Hd[i] += Hout[i];
      }
      if (o.point.on()) {
        const float eps = float(sceneScale(s).rayEpsilon);
        const std::vector<glm::vec3> origins = vertexRayOrigins(s, mat.n, eps);
        for (size_t i = 0; i < nv; ++i)
          if (mat.valid[i]) Hd[i] += pointLightIrradiance(o.point, caster, vertexLightPoint(origins[i], mat.n[i], eps), origins[i],
                                            mat.n[i]);
      }
      Bd.resize(nv);
      for (size_t i = 0; i < nv; ++i) Bd[i] = mat.E[i] + mat.rho[i] * Hd[i];
      stats.add("vertex_direct_seconds", t.seconds());
      stats.note("the first pass's direct part estimated at the vertices (" + std::to_string(kVertexDirectSamples) +
                 " shadow rays each) and replaced by ray-traced direct light" +
                 (o.twoPass == TwoPassDiffuse::FinalGather ? " at near gather hits" : ""));
    }
    tp.indirect.resize(nv);
    const bool removeCaustics = tp.caustics && o.firstPassHasCaustics;
    for (size_t i = 0; i < nv; ++i) {
      glm::vec3 ind = o.firstPassB[i] - Bd[i];
      if (removeCaustics && mat.valid[i])
        ind -= mat.rho[i] * tp.caustic(s.positions[i], mat.n[i], o.causticK);
      tp.indirect[i] = ind;
      negative += mat.valid[i] && (ind.r < 0.f || ind.g < 0.f || ind.b < 0.f);
    }
    if (removeCaustics) stats.note("the first pass's caustics replaced by the caustic map read at the hit points");
  }
  if (!tp.indirect.empty()) {
    stats.add("first_pass_negative_indirect_vertices", double(negative));
    if (negative > nv / 10)
      stats.warn(std::to_string(negative) + " of " + std::to_string(nv) +
                 " vertices have a negative indirect part (B below its direct part: a first pass noisier than "
                 "the direct estimate, or computed with other lights or materials)");
  }
}

}  // namespace gi::eye
