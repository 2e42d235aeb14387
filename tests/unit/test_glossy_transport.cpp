// Glossy surfaces carried by every estimator: the path-traced reference
// (NEE + MIS with the GGX lobe, through the shared integrator) and photon
// mapping (photons reflected by importance-sampling the lobe, Russian
// roulette on its weight, caustic map). The scene has an exact answer: a
// flat closed box whose five other faces emit E (radiance E / pi, no
// reflection) over a glossy floor. Every direction above the floor meets an
// emitter, so the floor sends (E / pi) A(mu) towards a point seen at
// cos(theta) = mu, A the lobe's directional albedo per channel; a point x on
// the ceiling or a wall receives
//   H(x) = E [1 - ∫_floor (1 - A(mu_y)) cos(theta_x) cos(theta_y) / (pi r^2) dA_y],
// and the floor reflects a total flux E A_floor A_hh, A_hh = 2 ∫ A(mu) mu dmu.
// A is computed here independently of the code under test: microfacet
// normals drawn from D(h) cos(theta_h) (Walter et al. 2007, eq. 35-36), the
// BRDF evaluated, not the visible-normal sampling the estimators use.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gi/color.h"
#include "gi/direct.h"
#include "gi/glossy.h"
#include "gi/pathtrace.h"
#include "gi/photon.h"
#include "gi/sampling.h"
#include "render_test_helpers.h"

using namespace gi;
using gi::test::SceneBuilder;

namespace {

constexpr float kAlpha = 0.3f;
const glm::vec3 kF0(0.9f, 0.6f, 0.3f);
constexpr float kE = 1.f;
constexpr double kHalf = 2.0, kHeight = 1.0;  // the box: [-2, 2] x [0, 1] x [-2, 2]

// The box, 8 x 8 cells per face, faces inward; the floor (y = 0) glossy.
Scene glossyBox() {
  return gi::test::glossyFloorBox({-kHalf, 0, -kHalf}, {kHalf, kHeight, kHalf}, glm::vec3(0.f), glm::vec3(kE), kF0, kAlpha);
}

// A(mu) at mu = (i + 0.5) / kMu, by 2^16 microfacet normals from D cos each
// (standard error about 1e-3).
constexpr int kMu = 128;
std::vector<glm::dvec3> albedoTable() { return gi::test::ggxAlbedoTable(kAlpha, kF0, kMu, 1 << 16, 1000); }

glm::dvec3 albedoAt(const std::vector<glm::dvec3>& A, double mu) {
  const double t = std::clamp(mu * kMu - 0.5, 0.0, double(kMu - 1));
  const int i = std::min(int(t), kMu - 2);
  return A[size_t(i)] + (t - i) * (A[size_t(i) + 1] - A[size_t(i)]);
}

// H(x) / E by the midpoint rule over the floor, 512 x 512 cells (the
// receivers keep 0.5 from the floor: a smooth integrand, error < 1e-4).
glm::dvec3 exactH(const std::vector<glm::dvec3>& A, const glm::dvec3& x, const glm::dvec3& n) {
  const int G = 512;
  const double cell = 2 * kHalf / G;
  glm::dvec3 deficit(0.0);
  for (int i = 0; i < G; ++i)
    for (int j = 0; j < G; ++j) {
      const glm::dvec3 y(-kHalf + (i + 0.5) * cell, 0.0, -kHalf + (j + 0.5) * cell);
      const glm::dvec3 d = y - x;
      const double r2 = glm::dot(d, d), r = std::sqrt(r2);
      const double cx = glm::dot(n, d) / r, cy = -d.y / r;
      if (cx <= 0.0 || cy <= 0.0) continue;
      deficit += (glm::dvec3(1.0) - albedoAt(A, cy)) * (cx * cy / (M_PI * r2) * cell * cell);
    }
  return double(kE) * (glm::dvec3(1.0) - deficit);
}

// The receivers: vertices on the ceiling and the walls at least 0.5 above the floor.
std::vector<size_t> receivers(const Scene& s, const VertexMaterial& m) {
  std::vector<size_t> out;
  for (size_t v = 0; v < s.vertexCount(); ++v)
    if (m.valid[v] && s.toWorld(s.positions[v]).y >= 0.5 - 1e-4) out.push_back(v);
  return out;
}

}  // namespace

// The reference's irradiance at each receiver against H(x): per channel,
// every vertex within 4.5 of its standard errors (the reported stdErrorH is
// for luminance; a channel's is taken as luminance's scaled by the channel's
// share, the noise coming from the same paths), and the mean over the
// receivers within 4 standard errors of the mean plus 0.1% (quadrature and
// the albedo table). The glossy floor's deficit is 15-40% of H at the
// ceiling, so a lobe 3% too bright or too dark would fail.
TEST(GlossyTransport, ReferenceMatchesTheGlossyFloorBox) {
  const Scene s = glossyBox();
  const auto A = albedoTable();
  auto caster = makeEmbreeCaster(s);
  PathTraceOptions o;
  o.samplesPerVertex = 1024;
  const PathTraceResult r = pathTrace(s, *caster, o);
  const VertexMaterial m = vertexMaterial(s);
  const auto rec = receivers(s, m);
  ASSERT_GT(rec.size(), 200u);
  glm::dvec3 sum(0.0), sumExact(0.0);
  double var = 0;
  int outliers = 0;
  for (size_t v : rec) {
    const glm::dvec3 H = exactH(A, glm::dvec3(s.toWorld(s.positions[v])), glm::dvec3(m.n[v]));
    const glm::dvec3 got(r.H[v]);
    const double se = r.stdErrorH[v];
    ASSERT_GT(se, 0.0);
    for (int c = 0; c < 3; ++c) {
      const double seC = se * H[c] / luminance(glm::vec3(H));
      if (std::abs(got[c] - H[c]) > 4.5 * seC) ++outliers;
    }
    sum += got;
    sumExact += H;
    var += se * se;
  }
  const double n = double(rec.size());
  EXPECT_LE(outliers, 2) << "of " << 3 * rec.size() << " channels beyond 4.5 standard errors";
  const double seMean = std::sqrt(var) / n;
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(sum[c] / n, sumExact[c] / n, 4 * seMean + 1e-3 * sumExact[c] / n) << "channel " << c;
  EXPECT_GT(r.stats.get("rays"), 0.0);
  // The floor's vertices lie on glossy faces only: no diffuse radiosity, 0, and the log says so.
  bool noted = false;
  for (const auto& note : r.stats.notes) noted = noted || note.find("glossy") != std::string::npos;
  EXPECT_TRUE(noted) << r.stats.line("reference");
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    if (!m.valid[v]) {
      EXPECT_EQ(r.B[v], glm::vec3(0.f));
    }
  }
}

// Photon transport off the glossy floor: the caustic photons (L S D, S the
// glossy floor) carry the flux it reflects, E A_floor A_hh per channel. Each
// emitted photon contributes 0 or its caustic power X; the standard error of
// the sum is sqrt(sum X^2 - (sum X)^2 / N) over the N emitted. No photon is
// stored on the floor (the only face whose normal points up).
TEST(GlossyTransport, PhotonsCarryTheLobeAlbedo) {
  const Scene s = glossyBox();
  const auto A = albedoTable();
  glm::dvec3 Ahh(0.0);
  for (int i = 0; i < kMu; ++i) Ahh += 2.0 * A[size_t(i)] * ((i + 0.5) / kMu) / double(kMu);
  auto caster = makeEmbreeCaster(s);
  PhotonOptions o;
  const size_t N = 400000;
  PhotonTraceStats st;
  const std::vector<Photon> ph = tracePhotons(s, *caster, o, 0, N, Progress(nullptr), st);
  glm::dvec3 sum(0.0), sum2(0.0);
  size_t onFloor = 0;
  for (const Photon& p : ph) {
    if (p.normal().y > 0.9f) ++onFloor;  // facing up: only the floor does
    if (p.path != kCausticPhoton) continue;
    sum += glm::dvec3(p.power);
    sum2 += glm::dvec3(p.power) * glm::dvec3(p.power);
  }
  EXPECT_EQ(onFloor, 0u);
  EXPECT_GT(st.glossyBounces, N / 4);
  const double area = 4 * kHalf * kHalf;
  for (int c = 0; c < 3; ++c) {
    const double expected = kE * area * Ahh[c];
    const double se = std::sqrt(std::max(0.0, sum2[c] - sum[c] * sum[c] / double(N)));
    EXPECT_NEAR(sum[c], expected, 4 * se + 1e-3 * expected) << "channel " << c;
  }
}

// Photon mapping's per-vertex irradiance on the ceiling: the direct light by
// light sampling (the walls) plus the caustic map (the floor's reflection),
// against H(x). The caustic part is 20-45% of H; its k = 128 estimates have
// a relative noise of about 1/sqrt(128) = 9% each, and vertices 0.5 apart
// share no photons (gather radius about 0.06), so the mean over the 81
// ceiling vertices has a standard error taken from their own spread; allowed
// besides 4 of those: 2% of the caustic part for the density estimate's
// blur (the floor's reflection varies slowly over a gather disk). Measured:
// +2.7% of the caustic part (2.1 standard errors); a test of the whole
// pipeline that fails at errors of about 7% in the glossy reflection (the
// energy test above resolves 0.5%).
TEST(GlossyTransport, PhotonMapMatchesTheGlossyFloorBox) {
  const Scene s = glossyBox();
  const auto A = albedoTable();
  auto caster = makeEmbreeCaster(s);
  PhotonOptions o;
  o.photons = 1000000;
  o.causticK = 128;
  const VertexRadiometry r = computePhotonMap(s, *caster, o);
  const VertexMaterial m = vertexMaterial(s);
  glm::dvec3 sum(0.0), sum2(0.0), caustic(0.0);
  double n = 0;
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    if (!m.valid[v] || m.n[v].y > -0.99f) continue;  // the ceiling
    const glm::dvec3 x(s.toWorld(s.positions[v]));
    const glm::dvec3 H = exactH(A, x, glm::dvec3(m.n[v]));
    // The part through the floor: E ∫ A dF (H with A = 0 is the walls' direct light).
    glm::dvec3 viaFloor(0.0);
    {
      const int G = 256;
      const double cell = 2 * kHalf / G;
      for (int i = 0; i < G; ++i)
        for (int j = 0; j < G; ++j) {
          const glm::dvec3 y(-kHalf + (i + 0.5) * cell, 0.0, -kHalf + (j + 0.5) * cell);
          const glm::dvec3 d = y - x;
          const double r2 = glm::dot(d, d), rr = std::sqrt(r2), c = -d.y / rr;
          viaFloor += albedoAt(A, c) * (c * c / (M_PI * r2) * cell * cell);
        }
    }
    const glm::dvec3 diff = glm::dvec3(r.H[v]) - H;
    sum += diff;
    sum2 += diff * diff;
    caustic += double(kE) * viaFloor;
    ++n;
  }
  ASSERT_EQ(n, 81.0);
  for (int c = 0; c < 3; ++c) {
    const double mean = sum[c] / n, sd = std::sqrt(std::max(0.0, (sum2[c] - n * mean * mean) / (n - 1)));
    EXPECT_NEAR(mean, 0.0, 4 * sd / std::sqrt(n) + 0.02 * caustic[c] / n)
        << "channel " << c << " caustic part " << caustic[c] / n;
  }
  EXPECT_GT(r.stats.get("glossy_bounces"), 0.0);
}
