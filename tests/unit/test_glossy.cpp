// The GGX glossy lobe (gi/glossy.h): its normalisation (the weak white
// furnace, Heitz 2014), energy conservation (directional albedo <= 1, -> 1
// for a white lobe as alpha -> 0), reciprocity, and a chi-square test of its
// visible-normal sampling against its pdf. The integrals use an independent
// estimator: microfacet normals drawn from D(h) cos(theta_h), the classic
// GGX sampling (Walter et al. 2007, eq. 35-36), not the code under test.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gi/glossy.h"
#include "gi/sampling.h"

using namespace gi;

namespace {

glm::vec3 dirFromAngles(double thetaDeg, double phiDeg) {
  const double t = glm::radians(thetaDeg), p = glm::radians(phiDeg);
  return glm::vec3(float(std::sin(t) * std::cos(p)), float(std::sin(t) * std::sin(p)), float(std::cos(t)));
}

// h ~ D(h) cos(theta_h): tan^2 theta_h = alpha^2 u / (1 - u).
glm::vec3 sampleNdf(float alpha, glm::vec2 u) {
  const double t2 = double(alpha) * alpha * u.x / (1.0 - u.x);
  const double c = 1.0 / std::sqrt(1.0 + t2), sn = std::sqrt(std::max(0.0, 1.0 - c * c));
  const double phi = 2.0 * M_PI * u.y;
  return glm::vec3(float(sn * std::cos(phi)), float(sn * std::sin(phi)), float(c));
}

struct Estimate {
  double mean = 0, stdErr = 0;
};
template <class F>
Estimate monteCarlo(int n, uint32_t key, F f) {
  double s = 0, s2 = 0;
  for (int i = 0; i < n; ++i) {
    const double x = f(sobolOwen2D(uint32_t(i), key));
    s += x;
    s2 += x * x;
  }
  Estimate e;
  e.mean = s / n;
  e.stdErr = std::sqrt(std::max(0.0, s2 / n - e.mean * e.mean) / (n - 1));
  return e;
}

const float kAlphas[] = {0.05f, 0.2f, 0.5f, 1.f};
const double kThetas[] = {0.0, 30.0, 60.0, 80.0, 89.0};

}  // namespace

// The microfacet normals' projected areas fill the surface:
//   ∫ D(h) cos(theta_h) dh = 2 pi ∫_0^{pi/2} D(theta) cos sin dtheta = 1,
// by the midpoint rule in t = tan(theta) / alpha (which spreads the peak):
// dtheta = alpha dt / (1 + alpha^2 t^2), t in [0, 2000), 2e5 steps; the
// tail beyond holds ~1 / 2000^2 of the mass.
TEST(Glossy, NormalDistributionIsNormalised) {
  for (float a : kAlphas) {
    const GgxLobe lobe(a, glm::vec3(1.f));
    const int n = 200000;
    const double tMax = 2000, dt = tMax / n;
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      const double t = (i + 0.5) * dt, th = std::atan(a * t);
      const glm::vec3 h(float(std::sin(th)), 0.f, float(std::cos(th)));
      sum += 2 * M_PI * lobe.D(h) * std::cos(th) * std::sin(th) * a * dt / (1 + a * a * t * t);
    }
    EXPECT_NEAR(sum, 1.0, 2e-4) << "alpha " << a;
  }
}

// Weak white furnace: the visible normals are a distribution,
//   ∫ D(h) G1(wo) max(0, wo.h) / (n.wo) dh = 1  for every wo and alpha.
// Estimated with h ~ D cos(theta_h) (estimator G1 max(0, wo.h) / (n.wo cos theta_h)),
// 2^16 scrambled Sobol points: within 5 estimated standard errors plus 1e-3
// (the float arithmetic). A wrong D normalisation or Lambda fails it.
TEST(Glossy, WeakWhiteFurnaceIsOne) {
  for (float a : kAlphas)
    for (double th : kThetas) {
      const GgxLobe lobe(a, glm::vec3(1.f));
      const glm::vec3 wo = dirFromAngles(th, 20.0);
      const Estimate e = monteCarlo(1 << 16, 11u, [&](glm::vec2 u) {
        const glm::vec3 h = sampleNdf(a, u);
        return lobe.G1(wo) * std::max(0.f, glm::dot(wo, h)) / double(wo.z * h.z);
      });
      EXPECT_NEAR(e.mean, 1.0, 5 * e.stdErr + 1e-3) << "alpha " << a << " theta " << th;
    }
}

// Directional albedo A(wo) = ∫ f(wo, wi) cos(theta_i) dwi of a white lobe
// (F0 = 1): at most 1 for every angle and roughness (single scattering
// loses the light that leaves the microsurface after several bounces), and
// within 1% of 1 for a nearly smooth lobe (alpha = 0.05) away from grazing.
// Independent estimator: wi = reflect(wo, h), h ~ D cos, pdf = D cos / (4 wo.h).
// The visible-normal sampler's mean weight must give the same albedo
// (within the two estimates' combined 5 standard errors).
TEST(Glossy, DirectionalAlbedoAtMostOne) {
  for (float a : kAlphas) {
    for (double th : kThetas) {
      const GgxLobe lobe(a, glm::vec3(1.f));
      const glm::vec3 wo = dirFromAngles(th, 0.0);
      const Estimate e = monteCarlo(1 << 16, 12u, [&](glm::vec2 u) {
        const glm::vec3 h = sampleNdf(a, u);
        const float woh = glm::dot(wo, h);
        if (woh <= 0.f) return 0.0;
        const glm::vec3 wi = 2.f * woh * h - wo;
        if (wi.z <= 0.f) return 0.0;
        const double pdf = lobe.D(h) * h.z / (4.0 * woh);
        return double(lobe.eval(wo, wi).g) * wi.z / pdf;
      });
      EXPECT_LE(e.mean, 1.0 + 5 * e.stdErr + 1e-4) << "alpha " << a << " theta " << th;
      if (a <= 0.05f && th <= 60.0) {
        EXPECT_GT(e.mean, 0.99) << "theta " << th;
      }
      const Estimate w = monteCarlo(1 << 16, 13u, [&](glm::vec2 u) {
        const GgxLobe::Sample s = lobe.sample(wo, u);
        return s.valid ? double(s.weight.g) : 0.0;
      });
      EXPECT_NEAR(w.mean, e.mean, 5 * std::hypot(w.stdErr, e.stdErr) + 1e-4) << "alpha " << a << " theta " << th;
    }
  }
}

// A coloured F0 absorbs: the albedo of each channel lies below the white
// lobe's, and at normal incidence on a smooth lobe close to F0 itself.
TEST(Glossy, FresnelColourAbsorbs) {
  const GgxLobe lobe(0.05f, glm::vec3(0.9f, 0.5f, 0.1f));
  const Estimate e = monteCarlo(1 << 14, 14u, [&](glm::vec2 u) {
    const GgxLobe::Sample s = lobe.sample(glm::vec3(0, 0, 1), u);
    return s.valid ? double(s.weight.b) : 0.0;
  });
  EXPECT_NEAR(e.mean, 0.1, 0.01);  // Schlick at cos = 1 gives F0; the lobe spreads to cos ~ 0.995
}

// Reciprocity f(wo, wi) = f(wi, wo) (Helmholtz), over random direction pairs.
TEST(Glossy, Reciprocity) {
  Rng rng(5);
  for (float a : kAlphas) {
    const GgxLobe lobe(a, glm::vec3(0.8f, 0.4f, 0.2f));
    for (int i = 0; i < 2000; ++i) {
      const glm::vec3 wo = uniformHemisphere({rng.next(), rng.next()});
      const glm::vec3 wi = uniformHemisphere({rng.next(), rng.next()});
      const glm::vec3 f1 = lobe.eval(wo, wi), f2 = lobe.eval(wi, wo);
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(f1[k], f2[k], 1e-5f * std::max(1.f, f1[k])) << "alpha " << a;
    }
  }
}

// Each sample's weight is f cos / pdf and its pdf is pdf(wo, wi), up to
// float rounding: h recomputed from wo + wi differs from the sampled h by
// ~1e-7, and D's relative sensitivity to it grows as 1 / alpha^2 (2e-3 at
// alpha = 0.05).
TEST(Glossy, SampleWeightIsBsdfOverPdf) {
  Rng rng(6);
  for (float a : kAlphas) {
    const GgxLobe lobe(a, glm::vec3(0.8f, 0.4f, 0.2f));
    for (int i = 0; i < 2000; ++i) {
      const glm::vec3 wo = uniformHemisphere({rng.next(), rng.next()});
      if (wo.z < 0.02f) continue;
      const GgxLobe::Sample s = lobe.sample(wo, {rng.next(), rng.next()});
      if (!s.valid) continue;
      EXPECT_NEAR(s.pdf, lobe.pdf(wo, s.wi), 2e-3f * s.pdf);
      const glm::vec3 expect = lobe.eval(wo, s.wi) * s.wi.z / s.pdf;
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(s.weight[k], expect[k], 2e-3f * std::max(1.f, expect[k]));
    }
  }
}

// Chi-square goodness of fit of the sampled directions against pdf(): 2^17
// samples in 24 x 32 cells of (cos theta_i, phi_i) plus one cell for lost
// samples (below the surface, probability 1 - ∫ pdf); expected counts by
// 8 x 8 midpoint sub-cells; cells expecting fewer than 5 pooled. The
// statistic must stay below the chi-square quantile at p = 1e-4 (Wilson and
// Hilferty 1931 approximation) for its degrees of freedom.
TEST(Glossy, ChiSquareSamplingMatchesPdf) {
  const int nTheta = 24, nPhi = 32, sub = 8, N = 1 << 17;
  for (float a : {0.15f, 0.5f})
    for (double th : {20.0, 70.0}) {
      const GgxLobe lobe(a, glm::vec3(1.f));
      const glm::vec3 wo = dirFromAngles(th, 30.0);
      std::vector<double> observed(nTheta * nPhi + 1, 0.0), expected(nTheta * nPhi + 1, 0.0);
      for (int i = 0; i < N; ++i) {
        const GgxLobe::Sample s = lobe.sample(wo, sobolOwen2D(uint32_t(i), 77u));
        if (!s.valid) { observed.back() += 1; continue; }
        const int ti = std::min(nTheta - 1, int(s.wi.z * nTheta));
        double phi = std::atan2(s.wi.y, s.wi.x);
        if (phi < 0) phi += 2 * M_PI;
        const int pi = std::min(nPhi - 1, int(phi / (2 * M_PI) * nPhi));
        observed[size_t(ti * nPhi + pi)] += 1;
      }
      double total = 0;
      for (int ti = 0; ti < nTheta; ++ti)
        for (int pi = 0; pi < nPhi; ++pi) {
          double sum = 0;
          const double dc = 1.0 / (nTheta * sub), dp = 2 * M_PI / (nPhi * sub);
          for (int a1 = 0; a1 < sub; ++a1)
            for (int b1 = 0; b1 < sub; ++b1) {
              const double c = (ti * sub + a1 + 0.5) * dc, p = (pi * sub + b1 + 0.5) * dp;
              const double sn = std::sqrt(1 - c * c);
              const glm::vec3 wi(float(sn * std::cos(p)), float(sn * std::sin(p)), float(c));
              sum += lobe.pdf(wo, wi) * dc * dp;
            }
          expected[size_t(ti * nPhi + pi)] = sum * N;
          total += sum;
        }
      expected.back() = std::max(0.0, 1.0 - total) * N;
      double chi2 = 0, poolO = 0, poolE = 0;
      int cells = 0;
      for (size_t k = 0; k < expected.size(); ++k) {
        if (expected[k] < 5) { poolO += observed[k]; poolE += expected[k]; continue; }
        chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
        ++cells;
      }
      if (poolE >= 5) { chi2 += (poolO - poolE) * (poolO - poolE) / poolE; ++cells; }
      const double dof = cells - 1, z = 3.719;  // upper 1e-4 point of the normal
      const double q = dof * std::pow(1 - 2 / (9 * dof) + z * std::sqrt(2 / (9 * dof)), 3);
      EXPECT_LT(chi2, q) << "alpha " << a << " theta " << th << " (" << cells << " cells)";
      EXPECT_NEAR(total, 1.0 - observed.back() / N, 0.01) << "lost-sample probability";
    }
}
