#include "gi/scenes.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

#include "gi/color.h"
#include "gi/scan.h"

namespace gi::scenes {

namespace {

using glm::dvec3;
constexpr double kPi = 3.14159265358979323846;

glm::u8vec3 srgbBytes(const glm::vec3& linear) {
  auto q = [](float v) { return uint8_t(std::lround(linearToSrgb(v) * 255.f)); };
  return {q(linear.r), q(linear.g), q(linear.b)};
}

// The attributes mirror rho and emission, so a PLY carries the same scene.
void refreshAttributes(SceneFile& sf) {
  const Scene& s = sf.scene;
  const size_t nf = s.faceCount();
  sf.attrs = MeshAttributes{};
  sf.attrs.faceColor.resize(nf);
  sf.attrs.faceQuality.resize(nf);
  for (size_t f = 0; f < nf; ++f) {
    sf.attrs.faceColor[f] = srgbBytes(s.faceRho(f));
    const glm::vec3 e = s.faceEmission(f);
    sf.attrs.faceQuality[f] = (e.r > 0.f || e.g > 0.f || e.b > 0.f) ? 1.f : 0.f;
  }
}

// Collects absolute double positions and oriented triangles with materials.
struct Builder {
  std::vector<dvec3> pts;
  std::vector<glm::uvec3> tris;
  std::vector<glm::vec3> rho, E;

  uint32_t vertex(const dvec3& p) {
    pts.push_back(p);
    return uint32_t(pts.size() - 1);
  }

  // Orientation is fixed here, from the wanted front direction, so that the
  // generators need not care about winding.
  void tri(uint32_t a, uint32_t b, uint32_t c, const dvec3& front, const glm::vec3& r, const glm::vec3& e) {
    if (a == b || b == c || a == c) return;
    const dvec3 n = glm::cross(pts[b] - pts[a], pts[c] - pts[a]);
    if (glm::dot(n, front) < 0.0) std::swap(b, c);
    tris.push_back({a, b, c});
    rho.push_back(r);
    E.push_back(e);
  }

  // Bilinear nu x nv grid over the quad p00 p10 p11 p01, two triangles per cell.
  void quad(const dvec3& p00, const dvec3& p10, const dvec3& p11, const dvec3& p01, int nu, int nv,
            const dvec3& front, const glm::vec3& r, const glm::vec3& e = glm::vec3(0.f)) {
    nu = std::max(nu, 1);
    nv = std::max(nv, 1);
    const uint32_t base = uint32_t(pts.size());
    for (int j = 0; j <= nv; ++j)
      for (int i = 0; i <= nu; ++i) {
        const double u = double(i) / nu, v = double(j) / nv;
        vertex((1 - u) * (1 - v) * p00 + u * (1 - v) * p10 + u * v * p11 + (1 - u) * v * p01);
      }
    auto id = [&](int i, int j) { return base + uint32_t(j * (nu + 1) + i); };
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        tri(id(i, j), id(i + 1, j), id(i + 1, j + 1), front, r, e);
        tri(id(i, j), id(i + 1, j + 1), id(i, j + 1), front, r, e);
      }
  }

  // Same, with the cell counts chosen for a patch edge of about h.
  void quadH(const dvec3& p00, const dvec3& p10, const dvec3& p11, const dvec3& p01, double h, const dvec3& front,
             const glm::vec3& r, const glm::vec3& e = glm::vec3(0.f)) {
    auto cells = [h](double len) { return std::max(1, int(std::lround(len / h))); };
    const int nu = cells(std::max(glm::length(p10 - p00), glm::length(p11 - p01)));
    const int nv = cells(std::max(glm::length(p01 - p00), glm::length(p11 - p10)));
    quad(p00, p10, p11, p01, nu, nv, front, r, e);
  }

  // Ring of `count` vertices at radius r in the plane z (count 1: the centre).
  std::vector<uint32_t> ring(double r, double z, int count) {
    std::vector<uint32_t> ids;
    if (count <= 1) return {vertex(dvec3(0.0, 0.0, z))};
    for (int j = 0; j < count; ++j) {
      const double phi = 2.0 * kPi * j / count;
      ids.push_back(vertex(dvec3(r * std::cos(phi), r * std::sin(phi), z)));
    }
    return ids;
  }

  // Triangulates the band between two rings (vertex counts may differ) by
  // advancing along whichever ring has the next vertex at the smaller angle.
  template <class FrontFn>
  void zip(const std::vector<uint32_t>& A, const std::vector<uint32_t>& B, FrontFn front, const glm::vec3& r,
           const glm::vec3& e = glm::vec3(0.f)) {
    const size_t a = A.size(), b = B.size();
    size_t i = 0, j = 0;
    while (i < a || j < b) {
      const bool advanceA = j >= b || (i < a && double(i + 1) / a <= double(j + 1) / b);
      uint32_t v0 = A[i % a], v1, v2;
      if (advanceA) { v1 = A[(i + 1) % a]; v2 = B[j % b]; ++i; }
      else { v1 = B[(j + 1) % b]; v2 = B[j % b]; ++j; }
      const dvec3 c = (pts[v0] + pts[v1] + pts[v2]) / 3.0;
      tri(v0, v1, v2, front(c), r, e);
    }
  }

  SceneFile finish() {
    SceneFile sf;
    sf.scene = Scene::fromAbsolute(pts, std::move(tris));
    sf.scene.rho = std::move(rho);
    sf.scene.emission = std::move(E);
    refreshAttributes(sf);
    return sf;
  }
};

const glm::vec3 kGrey(0.5f);

}  // namespace

void setUniform(SceneFile& sf, const glm::vec3& rho, const glm::vec3& E) {
  sf.scene.rho.assign(sf.scene.faceCount(), rho);
  sf.scene.emission.assign(sf.scene.faceCount(), E);
  refreshAttributes(sf);
}

SceneFile cornellBox(double h) {
  // Published data (Cornell Program of Computer Graphics, "Cornell Box data").
  const glm::vec3 white(0.725f, 0.71f, 0.68f), red(0.63f, 0.065f, 0.05f), green(0.14f, 0.45f, 0.091f);
  const glm::vec3 lightRho(0.78f), lightE = float(kPi) * glm::vec3(17.f, 12.f, 4.f);
  const dvec3 inside(278.0, 274.4, 279.6);
  Builder b;
  // Walls face the interior of the box.
  auto wall = [&](dvec3 p0, dvec3 p1, dvec3 p2, dvec3 p3, const glm::vec3& r) {
    dvec3 n = glm::cross(p2 - p0, p3 - p1);
    if (glm::dot(n, inside - (p0 + p1 + p2 + p3) * 0.25) < 0.0) n = -n;
    b.quadH(p0, p1, p2, p3, h, n, r);
  };
  wall({552.8, 0, 0}, {0, 0, 0}, {0, 0, 559.2}, {549.6, 0, 559.2}, white);              // floor
  wall({549.6, 0, 559.2}, {0, 0, 559.2}, {0, 548.8, 559.2}, {556.0, 548.8, 559.2}, white);  // back
  wall({0, 0, 559.2}, {0, 0, 0}, {0, 548.8, 0}, {0, 548.8, 559.2}, green);              // x = 0
  wall({552.8, 0, 0}, {549.6, 0, 559.2}, {556.0, 548.8, 559.2}, {556.0, 548.8, 0}, red);  // x ~ 556
  // Ceiling 556 x 559.2 cut into 3 x 3 rectangles around the light's hole.
  const double xs[4] = {0.0, 213.0, 343.0, 556.0}, zs[4] = {0.0, 227.0, 332.0, 559.2}, yc = 548.8;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      if (i != 1 || k != 1)
        wall({xs[i], yc, zs[k]}, {xs[i + 1], yc, zs[k]}, {xs[i + 1], yc, zs[k + 1]}, {xs[i], yc, zs[k + 1]}, white);
  // The light, 0.1 mm below the ceiling plane: no coplanar faces.
  const double yl = 548.7;
  b.quadH({343, yl, 227}, {343, yl, 332}, {213, yl, 332}, {213, yl, 227}, h, {0, -1, 0}, lightRho, lightE);
  // Blocks: top corners; the 4 sides and the top face away from the block's centre.
  auto block = [&](const dvec3 (&top)[4], const glm::vec3& r) {
    const double y = top[0].y;
    const dvec3 centre = (top[0] + top[1] + top[2] + top[3]) * 0.25 - dvec3(0, y / 2, 0);
    b.quadH(top[0], top[1], top[2], top[3], h, {0, 1, 0}, r);
    for (int s = 0; s < 4; ++s) {
      const dvec3 a = top[s], c = top[(s + 1) % 4];
      const dvec3 a0(a.x, 0, a.z), c0(c.x, 0, c.z);
      b.quadH(a0, c0, c, a, h, (a + c0) * 0.5 - centre, r);
    }
  };
  const dvec3 shortTop[4] = {{130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114}};
  const dvec3 tallTop[4] = {{423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406}};
  block(shortTop, white);
  block(tallTop, white);
  return b.finish();
}

std::vector<NamedLayer> causticCornellLayers(double h, double hf, int sphereSubdiv) {
  const glm::vec3 white(0.725f, 0.71f, 0.68f), red(0.63f, 0.065f, 0.05f), green(0.14f, 0.45f, 0.091f);
  const glm::vec3 lightRho(0.78f), lightE = float(kPi) * glm::vec3(17.f, 12.f, 4.f);
  const dvec3 inside(278.0, 274.4, 279.6);
  Builder b;
  auto wall = [&](dvec3 p0, dvec3 p1, dvec3 p2, dvec3 p3, const glm::vec3& r, double patch) {
    dvec3 n = glm::cross(p2 - p0, p3 - p1);
    if (glm::dot(n, inside - (p0 + p1 + p2 + p3) * 0.25) < 0.0) n = -n;
    b.quadH(p0, p1, p2, p3, patch, n, r);
  };
  wall({552.8, 0, 0}, {0, 0, 0}, {0, 0, 559.2}, {549.6, 0, 559.2}, white, hf);                // floor
  wall({549.6, 0, 559.2}, {0, 0, 559.2}, {0, 548.8, 559.2}, {556.0, 548.8, 559.2}, white, h);  // back
  wall({0, 0, 559.2}, {0, 0, 0}, {0, 548.8, 0}, {0, 548.8, 559.2}, green, h);                   // x = 0
  wall({552.8, 0, 0}, {549.6, 0, 559.2}, {556.0, 548.8, 559.2}, {556.0, 548.8, 0}, red, h);     // x ~ 556
  const double xs[4] = {0.0, 213.0, 343.0, 556.0}, zs[4] = {0.0, 227.0, 332.0, 559.2}, yc = 548.8;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      if (i != 1 || k != 1)
        wall({xs[i], yc, zs[k]}, {xs[i + 1], yc, zs[k]}, {xs[i + 1], yc, zs[k + 1]}, {xs[i], yc, zs[k + 1]}, white, h);
  const double yl = 548.7;
  b.quadH({343, yl, 227}, {343, yl, 332}, {213, yl, 332}, {213, yl, 227}, std::min(h, 26.0), {0, -1, 0}, lightRho, lightE);
  std::vector<NamedLayer> out;
  out.push_back({"caustic_cornell_box.ply", b.finish()});
  // The glass sphere: outward normals (the glass is inside).
  SceneFile ball = sphere(kGlassRadius, sphereSubdiv, false);
  {
    std::vector<dvec3> pts;
    for (const auto& p : ball.scene.positions) pts.push_back(ball.scene.toWorld(p) + kGlassCentre);
    Scene moved = Scene::fromAbsolute(pts, ball.scene.triangles);
    moved.rho.assign(moved.faceCount(), glm::vec3(1.f));
    moved.emission.assign(moved.faceCount(), glm::vec3(0.f));
    ball.scene = std::move(moved);
    refreshAttributes(ball);
  }
  out.push_back({"caustic_cornell_glass_sphere.ply", std::move(ball)});
  Builder m;
  m.quadH({330, 30, 558.7}, {500, 30, 558.7}, {500, 250, 558.7}, {330, 250, 558.7}, 20.0, {0, 0, -1}, glm::vec3(1.f));
  out.push_back({"caustic_cornell_mirror.ply", m.finish()});
  return out;
}

Scene causticCornell(double h, double hf, int sphereSubdiv, float ior) {
  const auto layers = causticCornellLayers(h, hf, sphereSubdiv);
  Scene s = layers[0].file.scene;
  s.material.assign(s.faceCount(), Material::Diffuse);
  s.ior.assign(s.faceCount(), ior);
  const Material mats[3] = {Material::Diffuse, Material::Glass, Material::Mirror};
  for (size_t k = 1; k < layers.size(); ++k) {
    Scene part = layers[k].file.scene;
    part.material.assign(part.faceCount(), mats[k]);
    part.ior.assign(part.faceCount(), ior);
    part.rho.assign(part.faceCount(), glm::vec3(1.f));
    s.append(part);
  }
  return s;
}

SceneFile glossyBlock(double patch) {
  Builder b;
  const glm::vec3 colour(0.9f, 0.72f, 0.42f);  // brass-like; a glossy layer takes the glossy colour parameter
  const double a = glm::radians(kGlossyTurnDeg), c = std::cos(a), sn = std::sin(a);
  const dvec3 centre(kGlossyCentre.x, 0.0, kGlossyCentre.z);
  dvec3 top[4];
  const double hx[4] = {-1, 1, 1, -1}, hz[4] = {-1, -1, 1, 1};
  for (int k = 0; k < 4; ++k) {
    const double x = kGlossyHalfWidth * hx[k], z = kGlossyHalfWidth * hz[k];
    top[k] = centre + dvec3(c * x + sn * z, kGlossyHeight, -sn * x + c * z);
  }
  b.quadH(top[0], top[1], top[2], top[3], patch, {0, 1, 0}, colour);
  for (int k = 0; k < 4; ++k) {
    const dvec3 p = top[k], q = top[(k + 1) % 4], p0(p.x, 0, p.z), q0(q.x, 0, q.z);
    b.quadH(p0, q0, q, p, patch, (p + q0) * 0.5 - (centre + dvec3(0, kGlossyHeight / 2, 0)), colour);
  }
  return b.finish();
}

std::vector<NamedLayer> causticCornellGlossyLayers(double patchSize, double floorPatch, int sphereSubdiv) {
  std::vector<NamedLayer> out = causticCornellLayers(patchSize, floorPatch, sphereSubdiv);
  out.push_back({"caustic_cornell_glossy_block.ply", glossyBlock(20.0)});
  return out;
}

Scene causticCornellGlossy(double patchSize, double floorPatch, int sphereSubdiv, float ior, float roughness,
                           const glm::vec3& F0) {
  Scene s = causticCornell(patchSize, floorPatch, sphereSubdiv, ior);
  Scene block = glossyBlock(20.0).scene;
  block.material.assign(block.faceCount(), Material::Glossy);
  block.ior.assign(block.faceCount(), ior);
  block.rho.assign(block.faceCount(), F0);
  block.roughness.assign(block.faceCount(), roughness);
  if (s.roughness.empty()) s.roughness.assign(s.faceCount(), roughness);
  s.append(block);
  return s;
}

SceneFile parallelPlates(double L, int n) {
  Builder b;
  const glm::vec3 black(0.f), E(1.f);
  b.quad({-0.5, -0.5, 0}, {0.5, -0.5, 0}, {0.5, 0.5, 0}, {-0.5, 0.5, 0}, n, n, {0, 0, 1}, black, E);
  b.quad({-0.5, -0.5, L}, {0.5, -0.5, L}, {0.5, 0.5, L}, {-0.5, 0.5, L}, n, n, {0, 0, -1}, black);
  return b.finish();
}

SceneFile perpendicularPlates(int n) {
  Builder b;
  const glm::vec3 black(0.f), E(1.f);
  b.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, n, n, {0, 0, 1}, black, E);
  b.quad({0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}, n, n, {1, 0, 0}, black);
  return b.finish();
}

SceneFile sphere(double radius, int subdivisions, bool inward) {
  // Icosahedron, then 4-to-1 splits with midpoints pushed onto the sphere.
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<dvec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                          {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                               {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                               {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (auto& p : v) p = glm::normalize(p);
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t c) {
      auto key = std::minmax(a, c);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(glm::normalize(v[a] + v[c]));
      return mid[key] = uint32_t(v.size() - 1);
    };
    std::vector<glm::uvec3> g;
    g.reserve(f.size() * 4);
    for (const auto& tr : f) {
      const uint32_t ab = midpoint(tr.x, tr.y), bc = midpoint(tr.y, tr.z), ca = midpoint(tr.z, tr.x);
      g.insert(g.end(), {{tr.x, ab, ca}, {tr.y, bc, ab}, {tr.z, ca, bc}, {ab, bc, ca}});
    }
    f.swap(g);
  }
  Builder b;
  for (const auto& p : v) b.vertex(p * radius);
  for (const auto& tr : f) {
    const dvec3 c = (b.pts[tr.x] + b.pts[tr.y] + b.pts[tr.z]) / 3.0;
    b.tri(tr.x, tr.y, tr.z, inward ? -c : c, kGrey, glm::vec3(0.f));
  }
  return b.finish();
}

SceneFile closedBox(double size, int n, bool inward) {
  Builder b;
  const double s = size / 2;
  for (int k = 0; k < 3; ++k)
    for (double sign : {-1.0, 1.0}) {
      // Axis k fixed at sign * s; the other two axes span the face.
      const int u = (k + 1) % 3, w = (k + 2) % 3;
      auto P = [&](double a, double c) {
        dvec3 p;
        p[k] = sign * s;
        p[u] = a;
        p[w] = c;
        return p;
      };
      dvec3 out(0.0);
      out[k] = sign;
      b.quad(P(-s, -s), P(s, -s), P(s, s), P(-s, s), n, n, inward ? -out : out, kGrey);
    }
  return b.finish();
}

SceneFile shadowLeak() {
  Builder b;
  const double X = 2.0, Y = 1.2, Z = 1.0;
  // Room, inward: 5 patches along x (edges at 0.4, 0.8, 1.2 ...), 3 along y and z.
  b.quad({0, 0, 0}, {X, 0, 0}, {X, Y, 0}, {0, Y, 0}, 5, 3, {0, 0, 1}, kGrey);   // floor
  b.quad({0, 0, Z}, {X, 0, Z}, {X, Y, Z}, {0, Y, Z}, 5, 3, {0, 0, -1}, kGrey);  // ceiling
  b.quad({0, 0, 0}, {X, 0, 0}, {X, 0, Z}, {0, 0, Z}, 5, 3, {0, 1, 0}, kGrey);   // side y = 0
  b.quad({0, Y, 0}, {X, Y, 0}, {X, Y, Z}, {0, Y, Z}, 5, 3, {0, -1, 0}, kGrey);  // side y = Y
  b.quad({0, 0, 0}, {0, Y, 0}, {0, Y, Z}, {0, 0, Z}, 3, 3, {1, 0, 0}, kGrey);   // end x = 0
  b.quad({X, 0, 0}, {X, Y, 0}, {X, Y, Z}, {X, 0, Z}, 3, 3, {-1, 0, 0}, kGrey);  // end x = X
  // The partition's two faces, 1 cm beyond the room on every side, so no ray slips past an edge.
  const double e = 0.01;
  for (double x : {1.09, 1.11})
    b.quad({x, -e, -e}, {x, Y + e, -e}, {x, Y + e, Z + e}, {x, -e, Z + e}, 3, 3, {x < 1.1 ? -1.0 : 1.0, 0, 0}, kGrey);
  b.quad({0.3, 0.4, Z - 0.02}, {0.7, 0.4, Z - 0.02}, {0.7, 0.8, Z - 0.02}, {0.3, 0.8, Z - 0.02}, 1, 1, {0, 0, -1},
         glm::vec3(0.f), glm::vec3(1.f));
  return b.finish();
}

SceneFile staircase() {
  Builder b;
  b.quad({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, 8, 8, {0, 0, 1}, kGrey);
  const double l = kStaircaseLight / 2;
  b.quad({-l, -l, 2}, {l, -l, 2}, {l, l, 2}, {-l, l, 2}, 1, 1, {0, 0, -1}, glm::vec3(0.f), glm::vec3(1.f));
  // Occluder: its edge through (0.2, 0, 1) along (sin 30, cos 30), reaching 0.8 towards +x.
  const double c = std::cos(kPi / 6), sn = std::sin(kPi / 6);
  const dvec3 o(0.2, 0, 1), along(sn, c, 0), across(c, -sn, 0);
  b.quad(o - 1.6 * along, o + 1.6 * along, o + 1.6 * along + 0.8 * across, o - 1.6 * along + 0.8 * across, 1, 1,
         {0, 0, -1}, glm::vec3(0.f));
  return b.finish();
}

SceneFile openPlane(double size, int n) {
  Builder b;
  const double s = size / 2;
  b.quad({-s, -s, 0}, {s, -s, 0}, {s, s, 0}, {-s, s, 0}, n, n, {0, 0, 1}, kGrey);
  return b.finish();
}

SceneFile floorWithWall(double floorSize, double wallHeight, int n) {
  Builder b;
  const double hp = floorSize / std::max(n, 1), W = std::max(floorSize, 20.0 * wallHeight), y = W / 2;
  const int ny = std::max(1, int(std::lround(W / hp))), nz = std::max(1, int(std::lround(wallHeight / hp)));
  b.quad({0, -y, 0}, {floorSize, -y, 0}, {floorSize, y, 0}, {0, y, 0}, n, ny, {0, 0, 1}, kGrey);
  b.quad({0, -y, 0}, {0, -y, wallHeight}, {0, y, wallHeight}, {0, y, 0}, nz, ny, {1, 0, 0}, kGrey);
  return b.finish();
}

SceneFile hemisphericalBowl(double radius, int n) {
  Builder b;
  n = std::max(n, 1);
  // Ring k at polar angle theta_k from the bottom; about 4n sin(theta) patches
  // around keeps them near square (edge radius * pi / 2n).
  std::vector<uint32_t> prev = b.ring(0.0, -radius, 1);
  for (int k = 1; k <= n; ++k) {
    const double theta = 0.5 * kPi * k / n;
    const int count = std::max(3, int(std::lround(4.0 * n * std::sin(theta))));
    const double r = k == n ? radius : radius * std::sin(theta), z = k == n ? 0.0 : -radius * std::cos(theta);
    std::vector<uint32_t> cur = b.ring(r, z, count);
    b.zip(prev, cur, [](const dvec3& c) { return -c; }, kGrey);
    prev.swap(cur);
  }
  return b.finish();
}

SceneFile cylindricalHole(double a, double h, int n) {
  Builder b;
  n = std::max(n, 1);
  const double hp = a / n;
  const int m = std::max(3, int(std::lround(2.0 * kPi * n)));
  const dvec3 up(0, 0, 1);
  auto towardsAxis = [](const dvec3& c) { return dvec3(-c.x, -c.y, 0.0); };
  // Wall rings from z = 0 down to z = -h; the top ring is shared with the ground.
  const int nz = std::max(1, int(std::lround(h / hp)));
  std::vector<uint32_t> top = b.ring(a, 0.0, m), prev = top;
  for (int k = 1; k <= nz; ++k) {
    std::vector<uint32_t> cur = b.ring(a, -h * k / nz, m);
    b.zip(prev, cur, towardsAxis, kGrey);
    prev.swap(cur);
  }
  // Bottom disk: rings of radius a k / n around the centre vertex, outer ring shared.
  std::vector<uint32_t> inner = b.ring(0.0, -h, 1);
  for (int k = 1; k < n; ++k) {
    std::vector<uint32_t> cur = b.ring(a * k / n, -h, std::max(3, int(std::lround(2.0 * kPi * k))));
    b.zip(inner, cur, [&](const dvec3&) { return up; }, kGrey);
    inner.swap(cur);
  }
  b.zip(inner, prev, [&](const dvec3&) { return up; }, kGrey);
  // Ground: radii growing geometrically to 10 a, so the patches stay about square.
  const int nr = std::max(1, int(std::ceil(std::log(10.0) / std::log1p(2.0 * kPi / m))));
  prev = top;
  for (int k = 1; k <= nr; ++k) {
    std::vector<uint32_t> cur = b.ring(a * std::pow(10.0, double(k) / nr), 0.0, m);
    b.zip(prev, cur, [&](const dvec3&) { return up; }, kGrey);
    prev.swap(cur);
  }
  return b.finish();
}

SceneFile scanRoom(const Scene& base, size_t triangles, const ScanOptions& o) {
  const size_t nb = base.faceCount();
  if (nb == 0) throw std::invalid_argument("the scan's base mesh has no triangles");
  if (double(nb) > kScanRoomScanShare * double(triangles) || triangles > 200000000)
    throw std::invalid_argument("scan room: " + std::to_string(triangles) + " triangles cannot hold the base's " +
                                std::to_string(nb) + " and a room (at least " +
                                std::to_string(size_t(std::ceil(nb / kScanRoomScanShare))) + ")");
  ScanOptions so = o;
  so.levels = 0;
  while (so.levels < 8 && double(nb) * std::pow(4.0, so.levels + 1) <= kScanRoomScanShare * double(triangles))
    ++so.levels;
  const Scene scan = displacedScan(base, so);
  dvec3 lo(1e300), hi(-1e300);
  for (const auto& p : scan.positions) {
    lo = glm::min(lo, scan.toWorld(p));
    hi = glm::max(hi, scan.toWorld(p));
  }
  const double size = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  if (!(size > 0)) throw std::invalid_argument("the scan's base mesh is flat to a point");
  const dvec3 shift(-0.5 * (lo.x + hi.x), -lo.y, -0.5 * (lo.z + hi.z));
  Builder b;
  for (const auto& p : scan.positions) b.vertex((scan.toWorld(p) + shift) / size + dvec3(0.0, 1e-3, 0.0));
  for (const auto& t : scan.triangles) {
    b.tris.push_back(t);
    b.rho.push_back(glm::vec3(0.6f));
    b.E.push_back(glm::vec3(0.f));
  }
  // The room: area 46.2 (window and light cut out), two triangles per h x h cell.
  const double X = 1.5, Y = 2.5, roomArea = 8 * X * X + 8 * X * Y - 1.2 - 0.64;
  const double left = double(triangles) - double(scan.faceCount());
  const double h = std::sqrt(2.0 * roomArea / std::max(left - 200.0, 64.0));
  const glm::vec3 wall(0.75f), floorRho(0.4f);
  b.quadH({-X, 0, -X}, {X, 0, -X}, {X, 0, X}, {-X, 0, X}, h, {0, 1, 0}, floorRho);
  // The ceiling around the light's rectangle x in [-0.4, 0.4], z in [-0.9, -0.1] (as in
  // the Cornell box: no ceiling hidden behind the light, nowhere black).
  const double lx = 0.4, lz0 = -0.9, lz1 = -0.1;
  auto ceiling = [&](double xa, double xb, double za, double zb) {
    b.quadH({xa, Y, za}, {xb, Y, za}, {xb, Y, zb}, {xa, Y, zb}, h, {0, -1, 0}, wall);
  };
  ceiling(-X, X, -X, lz0);
  ceiling(-X, X, lz1, X);
  ceiling(-X, -lx, lz0, lz1);
  ceiling(lx, X, lz0, lz1);
  b.quadH({-X, 0, -X}, {X, 0, -X}, {X, Y, -X}, {-X, Y, -X}, h, {0, 0, 1}, wall);
  b.quadH({-X, 0, X}, {X, 0, X}, {X, Y, X}, {-X, Y, X}, h, {0, 0, -1}, wall);
  b.quadH({-X, 0, -X}, {-X, 0, X}, {-X, Y, X}, {-X, Y, -X}, h, {1, 0, 0}, wall);
  // The window's wall x = X: four rectangles around the opening.
  const double z0 = -0.6, z1 = 0.6, y0 = 0.8, y1 = 1.8;
  auto windowWall = [&](double za, double zb, double ya, double yb) {
    b.quadH({X, ya, za}, {X, ya, zb}, {X, yb, zb}, {X, yb, za}, h, {-1, 0, 0}, wall);
  };
  windowWall(-X, z0, 0, Y);
  windowWall(z1, X, 0, Y);
  windowWall(z0, z1, 0, y0);
  windowWall(z0, z1, y1, Y);
  const int kl = std::clamp(int(std::lround(0.8 / h)), 1, 10);
  const double yl = Y - 1e-3;
  b.quad({-lx, yl, lz0}, {lx, yl, lz0}, {lx, yl, lz1}, {-lx, yl, lz1}, kl, kl, {0, -1, 0}, glm::vec3(0.78f),
         glm::vec3(1.f));
  return b.finish();
}

std::vector<std::string> names() {
  return {"cornell_box", "cornell_box_fine", "parallel_plates", "perpendicular_plates", "furnace_sphere",
          "closed_box",  "open_plane",       "floor_wall",      "bowl",                 "cylinder_hole",
          "caustic_cornell", "caustic_cornell_glossy", "shadow_leak", "staircase"};
}

std::vector<NamedLayer> layersByName(const std::string& name) {
  if (name == "caustic_cornell") return causticCornellLayers(50.0, 10.0, 5);
  if (name == "caustic_cornell_glossy") return causticCornellGlossyLayers(50.0, 10.0, 5);
  if (name == "caustic_cornell_coarse") return causticCornellLayers(50.0, 20.0, 5);  // benchmarks
  return {{name + ".ply", byName(name)}};
}

SceneFile byName(const std::string& name) {
  if (name == "cornell_box") return cornellBox(50.0);
  if (name == "cornell_box_fine") return cornellBox(25.0);
  if (name == "cornell_box_10k") return cornellBox(19.5);   // benchmarks only (not shipped)
  if (name == "cornell_box_100k") return cornellBox(6.15);  // benchmarks only (not shipped)
  if (name == "parallel_plates") return parallelPlates(1.0, 16);
  if (name == "perpendicular_plates") return perpendicularPlates(16);
  if (name == "furnace_sphere") {
    SceneFile sf = sphere(1.0, 3, true);
    setUniform(sf, glm::vec3(0.5f), glm::vec3(1.f));
    return sf;
  }
  if (name == "closed_box") return closedBox(1.0, 8, true);
  if (name == "shadow_leak") return shadowLeak();
  if (name == "staircase") return staircase();
  if (name == "open_plane") return openPlane(1.0, 16);
  if (name == "floor_wall") return floorWithWall(4.0, 1.0, 20);
  if (name == "bowl") return hemisphericalBowl(1.0, 16);
  if (name == "cylinder_hole") return cylindricalHole(1.0, 1.0, 8);
  if (name.rfind("caustic_cornell", 0) == 0)
    throw std::invalid_argument("'" + name + "' has several layers (files): use layersByName");
  throw std::invalid_argument("unknown scene '" + name + "'");
}

}  // namespace gi::scenes
