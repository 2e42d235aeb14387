// Whitted ray tracing (Whitted 1980, "An Improved Illumination Model for
// Shaded Display"): a tree of perfectly specular rays per eye ray, kept on an
// explicit stack. Glass splits into its reflected (weight F) and refracted
// (1 - F, times eta^2 for radiance) branches; a branch whose weight (the
// product of its reflectances and Fresnel factors, without the eta^2 that
// cancel on leaving the glass) falls below whitted_min_weight is not traced (Hall and Greenberg 1983's adaptive
// tree depth), nor one deeper than max_depth. At diffuse hits: emission
// E / pi plus rho / pi times the direct irradiance of
//   - each area light (a connected set of emitting faces): its exact
//     unoccluded irradiance, sum over its faces of E_f F(x -> f) with Lambert's
//     contour integral (gi/form_factor_analytic.h), times the visibility of
//     ONE shadow ray aimed at the light's centre as seen from x (the
//     F-weighted mean of the centroids of its faces' parts in front of x's
//     tangent plane; its area centroid when all of it is in view, and then
//     the sum is its boundary's contour integral): hard shadows without
//     noise. The ray reaches the light when it meets the front of one of
//     its faces first (a closed light, a sphere, has its centre inside);
//     the centre is never behind x's plane (it once was, for a light partly
//     behind it, and the ray then started inside the object under x);
//   - the point or spot light and the sun's centre: one shadow ray each.
// A shadow ray goes straight through glass, losing the Fresnel reflectance
// F at each interface it crosses (and taking the glass's tint), as classical
// ray tracers attenuate light through transparent objects without bending
// it (Hall and Greenberg 1983): exact for glass of index 1, and for a flat
// pane lit by a light at infinity (the sun) but for its inner reflections.
// A pane shifts a ray sideways, so a light at a finite distance D seen
// through a pane of thickness t is as bright as one at D - t (1 - 1/n): an
// outside audit measured 13% too little light under a pane 0.2 thick, 0.3
// from a point or area light (n = 1.5), about 0.3% for 5 mm at 1 m. Short
// also of a lens's focusing (the caustic map and the path tracer have both).
// The sky lights nothing here (it needs sampled rays: the distributed mode);
// it is seen only along rays that leave the scene. Glossy faces have no
// Whitted counterpart: they reflect one ray in the mirror direction weighted
// by the lobe's Fresnel factor at normal incidence on the microfacets, F(cos theta_o).
#include <algorithm>
#include <cmath>
#include <vector>

#include "gi/form_factor_analytic.h"
#include "gi/specular.h"
#include "render_internal.h"

namespace gi::eye {

namespace {
constexpr float kInvPi = 0.318309886f;
struct Branch {
  Ray ray;
  glm::vec3 w;   // product of reflectances and Fresnel factors: what the cut-off compares
  float scale;   // product of the eta^2 radiance factors (1 again once out of the glass)
  int depth;
  bool lightOnly = false;  // past max_depth: it may only find a light (emission, sky, sun)
};
float maxChannel(const glm::vec3& v) { return std::max({v.r, v.g, v.b}); }

// The area-weighted centroid of the part of triangle v in front of the plane
// through x with normal n (Sutherland and Hodgman's clip against one plane);
// false where no part of it is.
bool frontCentroid(const glm::dvec3& x, const glm::dvec3& n, const glm::dvec3 (&v)[3], glm::dvec3& centroid) {
  glm::dvec3 poly[4];
  int m = 0;
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3 &p = v[k], &q = v[(k + 1) % 3];
    const double dp = glm::dot(n, p - x), dq = glm::dot(n, q - x);
    if (dp > 0.0) poly[m++] = p;
    if ((dp > 0.0) != (dq > 0.0)) poly[m++] = p + (q - p) * (dp / (dp - dq));
  }
  if (m < 3) return false;
  glm::dvec3 sum(0.0);
  double area = 0.0;
  for (int k = 1; k + 1 < m; ++k) {
    const double a = glm::length(glm::cross(poly[k] - poly[0], poly[k + 1] - poly[0]));
    sum += a * (poly[0] + poly[k] + poly[k + 1]) / 3.0;
    area += a;
  }
  if (!(area > 0.0)) return false;
  centroid = sum / area;
  return true;
}
}  // namespace

glm::vec3 Context::whittedIrradiance(const glm::vec3& x, const glm::vec3& n, const glm::vec3& from, Counts& c) const {
  glm::vec3 H(0.f);
  const glm::dvec3 xd(x), nd(n);
  for (size_t li = 0; li < areaLights_.size(); ++li) {
    const AreaLight& light = areaLights_[li];
    glm::dvec3 Hl(0.0), centre(0.0);
    double wsum = 0.0;
    bool whole = light.uniform;  // no face clipped: its boundary's contour integral
    for (size_t k = 0; whole && k < light.corners.size(); ++k) whole = glm::dot(nd, light.corners[k] - xd) > 0.0;
    for (size_t k = 0; whole && k < light.faces.size(); ++k) {
      const uint32_t f = light.faces[k];
      whole = glm::dot(glm::dvec3(faceN_[f]), xd - glm::dvec3(s_.positions[s_.triangles[f].x])) > double(eps_);
    }
    if (whole) {
      double sum = 0.0;
      for (const auto& [p, q] : light.boundary) {
        const glm::dvec3 v0 = p - xd, v1 = q - xd, cr = glm::cross(v0, v1);
        const double lc = glm::length(cr);
        if (lc > 0.0) sum += std::atan2(lc, glm::dot(v0, v1)) * glm::dot(nd, cr) / lc;
      }
      const double F = std::fabs(sum) / (2.0 * M_PI);
      Hl = F * glm::dvec3(light.E);
      centre = light.centroid * F;
      wsum = F;
    }
    for (size_t k = 0; !whole && k < light.faces.size(); ++k) {
      const uint32_t f = light.faces[k];
      const auto& t = s_.triangles[f];
      const glm::dvec3 a(s_.positions[t.x]), b(s_.positions[t.y]), cc(s_.positions[t.z]);
      if (glm::dot(glm::dvec3(faceN_[f]), xd - a) <= double(eps_)) continue;  // behind (or in) the one-sided emitter
      const double F = pointToTriangleFormFactor(xd, nd, a, b, cc);
      glm::dvec3 mid;
      if (!(F > 0.0) || !frontCentroid(xd, nd, {a, b, cc}, mid)) continue;
      Hl += F * glm::dvec3(s_.faceEmission(f));
      centre += F * mid;
      wsum += F;
    }
    if (!(wsum > 0.0)) continue;
    centre /= wsum;
    glm::vec3 w = glm::vec3(centre) - x;
    const float r = glm::length(w);
    if (!(r > 0.f)) continue;
    w /= r;
    const Ray ray = shadowRay(from, n, w, glm::vec3(centre), 0.f, eps());
    if (ray.tfar > 0.f) H += glm::vec3(Hl) * whittedTransmittance(ray, c, int(li));
    else H += glm::vec3(Hl);
  }
  if (hasSun_) {
    const float cx = glm::dot(n, o_.sunDirection);
    if (cx > 0.f) H += o_.sunIrradiance * cx * whittedTransmittance(spawn(from, n, o_.sunDirection, 0.f), c);
  }
  if (hasPoint_) {
    glm::vec3 w = o_.point.position - x;
    const float r2 = glm::dot(w, w);
    if (r2 > 0.f) {
      const float r = std::sqrt(r2);
      w /= r;
      const float cx = glm::dot(n, w);
      if (cx > 0.f && spot_.contains(-w)) {
        const Ray ray = shadowRay(from, n, w, o_.point.position, 0.f, 0.f);
        H += o_.point.intensity * (cx / r2) * whittedTransmittance(ray, c);
      }
    }
  }
  return H;
}

glm::vec3 Context::whittedTransmittance(Ray ray, Counts& c, int light) const {
  glm::vec3 T(1.f);
  for (int crossings = 0;; ++crossings) {
    ++c.shadow;
    const Hit h = caster_.intersect(ray);
    if (!h.valid()) return T;
    if (light >= 0 && lightOfFace_[h.face] == light && glm::dot(ray.d, faceN_[h.face]) < 0.f) return T;
    if (s_.faceMaterial(h.face) != Material::Glass || crossings >= 64) return glm::vec3(0.f);
    const float ior = s_.ior.empty() ? 1.5f : s_.ior[h.face];
    // F from the air side at either face: the straight line stands for the
    // refracted ray, which leaves a pane at the angle it entered, losing
    // the same F (Fresnel's F is the same both ways across an interface);
    // evaluated inside at the unbent angle it would turn total beyond the
    // critical angle and black out the pane's shadow.
    const float cosN = std::min(1.f, std::fabs(glm::dot(ray.d, faceN_[h.face])));
    const float F = fresnelDielectric(cosN, 1.f / ior);
    T *= s_.faceRho(h.face) * (1.f - F);
    if (!(T.r > 0.f || T.g > 0.f || T.b > 0.f)) return T;
    ray.tnear = h.t + eps_;  // on past the interface, the same line
  }
}

glm::vec3 Context::traceWhitted(const Ray& primary, const SurfacePoint* first, Counts& c, bool onRay) const {
  thread_local std::vector<Branch> stack;
  stack.clear();
  stack.push_back({primary, glm::vec3(1.f), 1.f, 0});
  glm::vec3 L(0.f);
  // A branch past max_depth still shows a light straight behind the mirror
  // or glass that spawned it, as the path-traced modes do at their limit: a
  // light seen in a mirror is one reflection, as a wall's light is.
  auto push = [&](const Ray& r, const glm::vec3& w, float scale, int depth) {
    if (maxChannel(w) < o_.whittedMinWeight) { ++c.belowWeight; return; }
    if (depth > o_.maxDepth) ++c.cutAtMaxDepth;
    stack.push_back({r, w, scale, depth, depth > o_.maxDepth});
    ++c.specular;
  };
  while (!stack.empty()) {
    const Branch br = stack.back();
    stack.pop_back();
    SurfacePoint sp;
    // A point given apart from the ray (a vertex) leaves lifted along its
    // normal; a hit of the ray (a camera's too) as the path integrator's
    // (leaveFrom: off the free segment it came along near a corner, where
    // the lift crossed the neighbouring face and mirrors showed the sky
    // outside a closed tetrahedron).
    const bool given = first != nullptr && !onRay;
    if (first) {
      sp = *first;
      first = nullptr;
    } else {
      sp = surfaceAt(br.ray, caster_.intersect(br.ray));
    }
    const glm::vec3 d = br.ray.d;
    // Where rays leaving sp on the side br.ray came from start.
    const auto leave = [&] { return given ? sp.x + (glm::dot(d, sp.n) < 0.f ? sp.n : -sp.n) * eps_ : leaveFrom(br.ray, sp); };
    if (!sp.valid()) {
      L += br.w * br.scale * escaped(d, true, 0.f, 1.f);
      continue;
    }
    const Material m = s_.faceMaterial(sp.face);
    if (br.lightOnly) {
      if (m == Material::Diffuse && -glm::dot(sp.n, d) > 0.f) L += br.w * br.scale * s_.faceEmission(sp.face) * kInvPi;
      continue;
    }
    const glm::vec3 tint = s_.faceRho(sp.face);
    if (m == Material::Mirror) {
      push(spawn(leave(), sp.n, glm::normalize(reflectDir(d, sp.n)), 0.f), br.w * tint, br.scale, br.depth + 1);
      continue;
    }
    if (m == Material::Glass) {
      const float ior = s_.ior.empty() ? 1.5f : s_.ior[sp.face];
      const bool entering = glm::dot(d, sp.n) < 0.f;
      const glm::vec3 nf = entering ? sp.n : -sp.n;  // faces the incoming ray
      const float eta = entering ? 1.f / ior : ior;
      const float cosI = std::min(1.f, -glm::dot(d, nf));
      const float F = fresnelDielectric(cosI, eta);  // 1 beyond the critical angle
      push(spawn(leave(), sp.n, glm::normalize(reflectDir(d, nf)), 0.f), br.w * tint * F, br.scale, br.depth + 1);
      if (F < 1.f) {
        const float sin2T = eta * eta * std::max(0.f, 1.f - cosI * cosI);
        const float cosT = std::sqrt(std::max(0.f, 1.f - sin2T));
        const glm::vec3 t = glm::normalize(eta * d + (eta * cosI - cosT) * nf);
        push(spawn(sp.x, sp.n, t), br.w * tint * (1.f - F), br.scale * eta * eta, br.depth + 1);
      }
      continue;
    }
    const float cosO = -glm::dot(sp.n, d);
    if (!(cosO > 0.f)) continue;  // seen from behind: black
    if (m == Material::Glossy) {
      const GgxLobe lobe(s_.faceRoughness(sp.face), tint);
      push(spawn(leave(), sp.n, glm::normalize(reflectDir(d, sp.n)), 0.f), br.w * lobe.fresnel(cosO), br.scale,
           br.depth + 1);
      continue;
    }
    const glm::vec3 w = br.w * br.scale;
    L += w * s_.faceEmission(sp.face) * kInvPi;
    const glm::vec3 rho = s_.faceRho(sp.face);
    if (rho.r > 0.f || rho.g > 0.f || rho.b > 0.f) L += w * rho * kInvPi * whittedIrradiance(sp.x, sp.n, leave(), c);
  }
  return L;
}

}  // namespace gi::eye
