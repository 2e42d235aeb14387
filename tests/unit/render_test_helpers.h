// Small scenes for the eye-pass tests, built face by face.
#pragma once
#include <cmath>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "gi/color.h"
#include "gi/glossy.h"
#include "gi/render.h"
#include "gi/sampling.h"
#include "gi/scene.h"

namespace gi::test {

struct SceneBuilder {
  std::vector<glm::dvec3> pts;
  std::vector<glm::uvec3> tris;
  std::vector<glm::vec3> rho, E;
  std::vector<Material> mat;
  std::vector<float> rough;

  void tri(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, glm::vec3 r, glm::vec3 e, Material m,
           float roughness = 0.2f) {
    const uint32_t i = uint32_t(pts.size());
    pts.push_back(a);
    pts.push_back(b);
    pts.push_back(c);
    tris.push_back({i, i + 1, i + 2});
    rho.push_back(r);
    E.push_back(e);
    mat.push_back(m);
    rough.push_back(roughness);
  }
  // Quad a b c d, counter-clockwise seen from its front, split into n x n
  // cells of two triangles sharing vertices.
  void quad(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d, glm::vec3 r,
            glm::vec3 e = glm::vec3(0.f), Material m = Material::Diffuse, int n = 1, float roughness = 0.2f) {
    const uint32_t base = uint32_t(pts.size());
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const double u = double(i) / n, v = double(j) / n;
        pts.push_back((1 - u) * (1 - v) * a + u * (1 - v) * b + u * v * c + (1 - u) * v * d);
      }
    auto id = [&](int i, int j) { return base + uint32_t(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        for (int k = 0; k < 2; ++k) {
          rho.push_back(r);
          E.push_back(e);
          mat.push_back(m);
          rough.push_back(roughness);
        }
      }
  }
  // Axis-aligned box [lo, hi], faces outward (or inward), each face n x n.
  void box(const glm::dvec3& lo, const glm::dvec3& hi, glm::vec3 r, glm::vec3 e, Material m, bool inward, int n = 1) {
    const glm::dvec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                             {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    const int f[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};
    for (const auto& q : f) {
      if (inward) quad(c[q[0]], c[q[3]], c[q[2]], c[q[1]], r, e, m, n);
      else quad(c[q[0]], c[q[1]], c[q[2]], c[q[3]], r, e, m, n);
    }
  }
  Scene build(float ior = 1.5f) const {
    Scene s = Scene::fromAbsolute(pts, tris);
    s.rho = rho;
    s.emission = E;
    s.material = mat;
    s.ior.assign(tris.size(), ior);
    s.roughness = rough;
    return s;
  }
};

inline double meanLuminance(const Image& img) {
  double s = 0;
  for (const auto& p : img.px) s += luminance(p);
  return s / double(img.px.size());
}

// Two renders of one view over the block of side T at (bx, by): the sums of
// their pixels' luminance and of their pixels' variance (stdError^2), for
// comparing block means within combined standard errors.
struct BlockSums {
  double a = 0, b = 0, varA = 0, varB = 0;
};

inline BlockSums blockSums(const RenderResult& ra, const RenderResult& rb, int bx, int by, int T) {
  const int W = ra.image.width;
  BlockSums s;
  for (int y = by; y < by + T; ++y)
    for (int x = bx; x < bx + T; ++x) {
      const size_t p = size_t(y) * size_t(W) + size_t(x);
      s.a += luminance(ra.image.px[p]);
      s.b += luminance(rb.image.px[p]);
      s.varA += double(ra.stdError[p]) * ra.stdError[p];
      s.varB += double(rb.stdError[p]) * rb.stdError[p];
    }
  return s;
}

// Block means of two images agree within 4 combined standard errors, each
// block's from the per-pixel standard errors sqrt(sum sigma_p^2) / n (for
// the QMC modes this spread of the pixel samples is an upper bound), and so
// do the whole images' sums (a bias spread over the image: in the tests
// below 4 sigma is 1.5% of the Whitted image, 0.6% of the distributed one).
inline void expectBlocksAgree(const RenderResult& a, const RenderResult& b, int block, const char* what) {
  const int W = a.image.width, H = a.image.height;
  int blocks = 0;
  double sa = 0, sb = 0, vsa = 0, vsb = 0;
  for (int by = 0; by + block <= H; by += block)
    for (int bx = 0; bx + block <= W; bx += block) {
      const BlockSums s = blockSums(a, b, bx, by, block);
      const double ma = s.a, mb = s.b, va = s.varA, vb = s.varB;
      const double n = double(block) * block;
      EXPECT_NEAR(ma / n, mb / n, 4 * std::sqrt(va + vb) / n + 1e-6) << what << " block " << bx << "," << by;
      sa += ma;
      sb += mb;
      vsa += va;
      vsb += vb;
      ++blocks;
    }
  EXPECT_GT(blocks, 20);
  EXPECT_NEAR(sa, sb, 4 * std::sqrt(vsa + vsb)) << what << ": whole image";
}

// A closed box [lo, hi], 8 x 8 cells per face, faces inward: walls of
// reflectance wallRho emitting E, the floor (y = lo.y) a black GGX lobe
// (normal reflectance F0, roughness alpha). The scene of the glossy tests.
inline Scene glossyFloorBox(glm::dvec3 lo, glm::dvec3 hi, glm::vec3 wallRho, glm::vec3 E, glm::vec3 F0, float alpha) {
  SceneBuilder b;
  b.box(lo, hi, wallRho, E, Material::Diffuse, true, 8);
  Scene s = b.build();
  const std::vector<glm::vec3> n = unitFaceNormals(s);
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (n[f].y > 0.99f) {
      s.material[f] = Material::Glossy;
      s.rho[f] = F0;
      s.emission[f] = glm::vec3(0.f);
      s.roughness[f] = alpha;
    }
  return s;
}

// The lobe's directional albedo A(mu) at mu = (i + 0.5) / bins, each by
// `samples` microfacet normals drawn from D(h) cos(theta_h) (Walter et al.
// 2007, "Microfacet models for refraction through rough surfaces", eq.
// 35-36) with Sobol dimensions dim0 + i: independent of the visible-normal
// sampling the estimators use.
inline std::vector<glm::dvec3> ggxAlbedoTable(float alpha, glm::vec3 F0, int bins, int samples, uint32_t dim0) {
  const GgxLobe lobe(alpha, F0);
  std::vector<glm::dvec3> A(size_t(bins), glm::dvec3(0.0));
  for (int i = 0; i < bins; ++i) {
    const double mu = (i + 0.5) / bins;
    const glm::vec3 wo(float(std::sqrt(1.0 - mu * mu)), 0.f, float(mu));
    for (int k = 0; k < samples; ++k) {
      const glm::vec2 u = sobolOwen2D(uint32_t(k), dim0 + uint32_t(i));
      const double t2 = double(alpha) * alpha * u.x / (1.0 - u.x), c = 1.0 / std::sqrt(1.0 + t2);
      const double sn = std::sqrt(1.0 - c * c), phi = 2 * M_PI * u.y;
      const glm::vec3 h(float(sn * std::cos(phi)), float(sn * std::sin(phi)), float(c));
      const float woh = glm::dot(wo, h);
      if (woh <= 0.f) continue;
      const glm::vec3 wi = 2.f * woh * h - wo;
      if (wi.z <= 0.f) continue;
      A[size_t(i)] += glm::dvec3(lobe.eval(wo, wi)) * double(wi.z) * (4.0 * woh / (lobe.D(h) * h.z)) / double(samples);
    }
  }
  return A;
}

}  // namespace gi::test
