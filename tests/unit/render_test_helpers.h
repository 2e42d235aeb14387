// Small scenes for the eye-pass tests, built face by face.
#pragma once
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "gi/color.h"
#include "gi/render.h"
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

}  // namespace gi::test
