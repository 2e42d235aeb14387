#include "gi/direct.h"

#include <cmath>
#include <stdexcept>

#include "gi/color.h"
#include "gi/emitters.h"
#include "gi/sampling.h"

namespace gi {

std::vector<ParamSpec> DirectOptions::specs() {
  return {
      {"light_samples", "Shadow rays per vertex",
       "Points sampled on the emitters (in proportion to their power) for each vertex, each with a shadow ray. "
       "More samples give smoother soft shadows; the error falls as about N^-1/2 to N^-3/4.",
       ParamType::Int, 64, 1, 1 << 20},
      seedSpec("sampling sequences"),
  };
}

DirectOptions DirectOptions::fromParams(const ParamValues& v) {
  DirectOptions o;
  o.lightSamples = v.getInt("light_samples");
  o.seed = uint32_t(v.getInt("seed"));
  return o;
}

VertexMaterial vertexMaterial(const Scene& s) {
  const size_t nv = s.vertexCount();
  VertexMaterial m;
  std::vector<glm::dvec3> rho(nv, glm::dvec3(0.0)), E(nv, glm::dvec3(0.0));
  std::vector<double> w(nv, 0.0);
  const auto ok = usableFaceMask(s);
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!ok[f]) continue;
    const double a = faceArea(s, f);
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = s.triangles[f][k];
      rho[v] += a * glm::dvec3(s.faceRho(f));
      E[v] += a * glm::dvec3(s.faceEmission(f));
      w[v] += a;
    }
  }
  m.n = s.vertexNormals.size() == nv ? s.vertexNormals : computeVertexNormals(s);
  m.rho.resize(nv);
  m.E.resize(nv);
  m.valid.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    m.valid[i] = w[i] > 0.0 && glm::dot(m.n[i], m.n[i]) > 0.5f;
    m.rho[i] = w[i] > 0.0 ? glm::vec3(rho[i] / w[i]) : glm::vec3(0.f);
    m.E[i] = w[i] > 0.0 ? glm::vec3(E[i] / w[i]) : glm::vec3(0.f);
  }
  return m;
}

VertexRadiometry computeDirect(const Scene& s, const RayCaster& caster, const DirectOptions& opt, const Progress& progress) {
  if (opt.lightSamples < 1) throw std::invalid_argument("light_samples must be >= 1");
  Timer timer;
  const EmitterSampler lights(s);
  if (lights.empty())
    throw std::invalid_argument("the scene has no emitters: select the light's faces (or mark them by face quality) "
                                "and choose the matching 'Emitters' option");
  const SceneReport rep = analyzeScene(s);
  const float eps = float(rep.rayEpsilon);
  const VertexMaterial mat = vertexMaterial(s);
  const size_t nv = s.vertexCount();
  const std::vector<glm::vec3> origins = vertexRayOrigins(s, mat.n, eps);
  VertexRadiometry out;
  out.B.assign(nv, glm::vec3(0.f));
  out.H.assign(nv, glm::vec3(0.f));
  out.stdError.assign(nv, 0.f);
  const int N = opt.lightSamples;
  parallelBlocks(nv, progress, "direct light", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (!mat.valid[i]) continue;
      SobolOwenStream seq(hash3(uint32_t(i), opt.seed, 0xd1u));
      glm::dvec3 sum(0.0);
      double sl = 0, sl2 = 0;
      for (int j = 0; j < N; ++j) {
        const glm::vec3 c = sampleDirectIrradiance(lights, caster, origins[i], mat.n[i], seq.next(), eps);
        sum += glm::dvec3(c);
        const double l = luminance(c * mat.rho[i]);
        sl += l;
        sl2 += l * l;
      }
      const glm::vec3 H = glm::vec3(sum / double(N));
      out.H[i] = H;
      out.B[i] = mat.E[i] + mat.rho[i] * H;
      const double mean = sl / N, var = N > 1 ? std::max(0.0, (sl2 - N * mean * mean) / (N - 1)) : 0.0;
      out.stdError[i] = float(std::sqrt(var / N));
    }
  });
  double err2 = 0, lum = 0;
  size_t valid = 0;
  for (size_t i = 0; i < nv; ++i)
    if (mat.valid[i]) { err2 += double(out.stdError[i]) * out.stdError[i]; lum += luminance(out.B[i]); ++valid; }
  auto& st = out.stats;
  st.add("vertices", double(nv));
  st.add("emitter_faces", double(lights.faceCount()));
  st.add("emitted_power_W", lights.totalPower());
  st.add("shadow_rays", double(valid) * N);
  st.add("seconds", timer.seconds());
  st.add("mean_luminance_B", valid ? lum / double(valid) : 0.0);
  st.add("rms_error_estimate", valid ? std::sqrt(err2 / double(valid)) : 0.0);
  st.note("direct light only (per-vertex light sampling)");
  if (valid < nv) st.note(std::to_string(nv - valid) + " vertices without a usable face got 0");
  return out;
}

}  // namespace gi
