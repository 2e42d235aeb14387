// The eye pass's integrator: the shared one (path_integrator.h) with the
// rules of the mode, and Whitted's area lights.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "gi/color.h"
#include "gi/specular.h"
#include "render_internal.h"

namespace gi::eye {

namespace {

paths::LightSettings lightsOf(const RenderOptions& o) {
  paths::LightSettings l;
  l.skyRadiance = o.skyRadiance;
  l.sunDirection = o.sunDirection;
  l.sunIrradiance = o.sunIrradiance;
  l.sunAngularRadiusDeg = o.sunAngularRadiusDeg;
  l.point = o.point;
  return l;
}

// The modes as rules of the shared integrator: only the path-traced mode
// follows diffuse interreflection (and needs Russian roulette); the others
// end at the first diffuse vertex with its direct light (plus, in two-pass,
// the first pass's light).
paths::PathRules rulesOf(const RenderOptions& o) {
  paths::PathRules r;
  r.maxDepth = o.maxDepth;
  r.maxDiffuseBounces = o.maxDiffuseBounces;
  r.firstLightSamples = o.lightSamples;
  r.interreflection = o.mode == RenderMode::PathTraced;
  r.roulette = o.mode == RenderMode::PathTraced;
  return r;
}

}  // namespace

Context::Context(const Scene& s, const RayCaster& c, const RenderOptions& o, const TwoPassData* tp)
    : paths::Integrator(s, c, lightsOf(o), rulesOf(o), tp ? static_cast<const paths::StoredLight*>(this) : nullptr),
      o_(o), tp_(tp) {
  if (o.mode != RenderMode::Whitted) return;
  // Whitted's area lights: connected sets of emitting faces (shared vertices).
  const auto ok = usableFaceMask(s);
  std::vector<uint32_t> parent(s.vertexCount());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f] && emits(uint32_t(f)))
      for (int k = 1; k < 3; ++k) parent[find(s.triangles[f][k])] = find(s.triangles[f][0]);
  std::vector<int> group(s.vertexCount(), -1);
  lightOfFace_.assign(s.faceCount(), -1);
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!ok[f] || !emits(uint32_t(f))) continue;
    const uint32_t root = find(s.triangles[f][0]);
    if (group[root] < 0) {
      group[root] = int(areaLights_.size());
      areaLights_.emplace_back();
    }
    areaLights_[size_t(group[root])].faces.push_back(uint32_t(f));
    lightOfFace_[f] = group[root];
  }
  for (AreaLight& l : areaLights_) {
    std::map<std::pair<uint32_t, uint32_t>, int> edges;  // directed edge -> uses
    std::vector<uint32_t> verts;
    double area = 0.0;
    l.E = s.faceEmission(l.faces[0]);
    for (const uint32_t f : l.faces) {
      const auto& t = s.triangles[f];
      l.uniform = l.uniform && s.faceEmission(f) == l.E;
      for (int k = 0; k < 3; ++k) {
        ++edges[{t[k], t[(k + 1) % 3]}];
        verts.push_back(t[k]);
      }
      const double a = faceArea(s, f);
      l.centroid += a * (glm::dvec3(s.positions[t.x]) + glm::dvec3(s.positions[t.y]) + glm::dvec3(s.positions[t.z])) / 3.0;
      area += a;
    }
    l.centroid /= area;
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    for (const uint32_t v : verts) l.corners.push_back(glm::dvec3(s.positions[v]));
    for (const auto& [e, n] : edges)
      if (!edges.count({e.second, e.first}))
        for (int k = 0; k < n; ++k) l.boundary.push_back({glm::dvec3(s.positions[e.first]), glm::dvec3(s.positions[e.second])});
  }
}

}  // namespace gi::eye
