#include "scene_defects.h"

#include <algorithm>
#include <cmath>
#include <atomic>
#include <cstdio>
#include <memory>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include "gi/color.h"
#include "point_cloud.h"

namespace gi::detail {

namespace {
constexpr uint32_t kNoFace = 0xffffffffu;
}  // namespace

// Rays start 1e-5 of the bounding box's diagonal off the surfaces (and
// float coordinates centred on the box lose that much precision): a box
// stretched by a few far vertices makes that offset large against the rest
// of the mesh (an outside audit: one triangle 100 m away from a 1.4 m scene
// moved its direct light by 2.4%; one spike vertex 1e6 away turned a floor
// under a cube from 0 to 1 in ambient occlusion). Said when the box's
// diagonal exceeds 100 times that of the bulk of the vertices (each axis
// without its 1% most extreme at either end, at least 8; meshes of 32
// vertices or more).
std::optional<std::string> strayExtentWarning(const Scene& s, const SceneReport& rep) {
  std::vector<uint8_t> used(s.vertexCount(), 0);
  const std::vector<uint8_t> ok = usableFaceMask(s);
  for (size_t f = 0; f < ok.size(); ++f)
    if (ok[f]) used[s.triangles[f].x] = used[s.triangles[f].y] = used[s.triangles[f].z] = 1;
  std::vector<float> c;
  c.reserve(s.vertexCount());
  glm::dvec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    c.clear();
    for (size_t i = 0; i < used.size(); ++i)
      if (used[i]) c.push_back(s.positions[i][a]);
    // Too few vertices to tell a stray one from the shape; at most 1% of
    // them, but at least 8, may lie beyond each side of the bulk's box.
    if (c.size() < 32) return std::nullopt;
    const size_t out = std::max<size_t>(8, c.size() / 100), k0 = out, k1 = c.size() - 1 - out;
    std::nth_element(c.begin(), c.begin() + long(k0), c.end());
    lo[a] = c[k0];
    std::nth_element(c.begin(), c.begin() + long(k1), c.end());
    hi[a] = c[k1];
  }
  const double bulk = glm::length(hi - lo) * s.unit, diag = rep.diagonal;
  if (!(diag > 100.0 * bulk)) return std::nullopt;
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "the bounding box (diagonal %.3g) is %.0f times the extent of the bulk of the vertices (%.3g): rays start "
                "%.3g off the surfaces (1e-5 of the box), %.2g%% of that extent, so shadows, gaps and small parts "
                "read wrong; remove stray far vertices or far parts, or compute them apart",
                diag, diag / std::max(bulk, 1e-300), bulk, rep.rayEpsilon * s.unit,
                100.0 * rep.rayEpsilon * s.unit / std::max(bulk, 1e-300));
  return std::string(buf);
}

// Rays met a face and its copy at random, and both emitted: a Cornell box
// whose light faces were listed twice came out twice as bright in every
// solver, its walls listed twice 27% dark in photon mapping (an outside
// audit). Each copy is left out of the computation (Scene::leftOut) and
// takes its original's values in the output; a copy's corner that is a
// vertex of its own (an unwelded copy) takes the original's corner's.
void leaveOutDuplicates(FilterInput& in, FilterResult& res) {
  Scene& s = in.scene;  // res.sameFaces: the pairs the set-up's scene report found
  s.leftOut.assign(s.faceCount(), 0);
  for (const auto& [copy, original] : res.sameFaces) s.leftOut[copy] = 1;
  std::vector<uint8_t> kept(s.vertexCount(), 0);  // on a face the computation keeps
  const std::vector<uint8_t> ok = usableFaceMask(s);  // the copies left out
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f]) kept[s.triangles[f].x] = kept[s.triangles[f].y] = kept[s.triangles[f].z] = 1;
  for (const auto& [copy, original] : res.sameFaces)
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = s.triangles[copy][k];
      if (kept[v]) continue;
      for (int j = 0; j < 3; ++j)
        if (s.positions[s.triangles[original][j]] == s.positions[v]) res.sameVertices.push_back({v, s.triangles[original][j]});
      kept[v] = 1;  // once
    }
  res.report = analyzeScene(s);  // the copies counted as left out
  res.setupLog += std::string(res.setupLog.empty() ? "" : "; ") + std::to_string(res.sameFaces.size()) +
                  " faces repeat another face's corners in the same turn: each is computed once, its copies "
                  "neither emitting nor blocking light, and shown with its values (MeshLab: Cleaning and "
                  "Repairing > Remove Duplicate Faces removes them)";
}

uint32_t originalFace(const FilterResult& res, uint32_t face) {
  for (const auto& [copyFace, original] : res.sameFaces)
    if (copyFace == face) return original;
  return face;
}

// The output's copies of duplicated faces (and their own vertices) take
// their originals' values. A refined mesh keeps the input's vertices first,
// in order, and never splits a copy: its face takes the area-weighted mean
// of the faces its original became (the linear values: the colours follow
// from them, or keep the first face's).
void copyDuplicates(FilterResult& res) {
  auto copy = [](auto& values, const std::vector<std::pair<uint32_t, uint32_t>>& pairs, size_t width = 1) {
    if (values.empty()) return;
    for (const auto& [to, from] : pairs)
      for (size_t c = 0; c < width; ++c) values[width * to + c] = values[width * from + c];
  };
  copy(res.vertexQuality, res.sameVertices);
  copy(res.vertexColor, res.sameVertices);
  copy(res.vertexNormal, res.sameVertices);
  for (VertexAttribute& a : res.attributes) copy(a.values, res.sameVertices, size_t(a.components));
  if (!res.refined) {
    copy(res.faceQuality, res.sameFaces);
    copy(res.faceColor, res.sameFaces);
    copy(res.faceRadiometry, res.sameFaces);
    return;
  }
  if (res.sameFaces.empty() || (res.faceQuality.empty() && res.faceRadiometry.empty())) return;
  const RefinedMesh& m = *res.refined;
  std::vector<uint32_t> originalOf(m.sourceFace.empty() ? 0 : *std::max_element(m.sourceFace.begin(), m.sourceFace.end()) + 1,
                                   kNoFace);
  for (const auto& [copyFace, original] : res.sameFaces)
    if (copyFace < originalOf.size()) originalOf[copyFace] = original;
  // The mean over each original's refined faces.
  std::vector<double> area(originalOf.size(), 0.0), quality(originalOf.size(), 0.0);
  std::vector<glm::dvec3> radiometry(originalOf.size(), glm::dvec3(0.0));
  for (size_t f = 0; f < m.sourceFace.size(); ++f) {
    const uint32_t src = m.sourceFace[f];
    const double a = faceArea(m.scene, f);
    area[src] += a;
    if (!res.faceQuality.empty()) quality[src] += a * res.faceQuality[f];
    if (!res.faceRadiometry.empty()) radiometry[src] += a * glm::dvec3(res.faceRadiometry[f]);
  }
  for (size_t f = 0; f < m.sourceFace.size(); ++f) {
    const uint32_t o = originalOf[m.sourceFace[f]];
    if (o == kNoFace || !(area[o] > 0.0)) continue;
    if (!res.faceQuality.empty()) res.faceQuality[f] = float(quality[o] / area[o]);
    if (!res.faceRadiometry.empty()) res.faceRadiometry[f] = glm::vec3(radiometry[o] / area[o]);
  }
}

std::optional<std::string> nearSurfacesWarning(const Scene& s, const RayCaster& caster) {
  const std::vector<uint8_t> ok = usableFaceMask(s);
  const std::vector<glm::vec3> n = vertexNormalsForRays(s, &ok);
  const float eps = float(sceneScale(s).rayEpsilon);
  std::vector<uint8_t> used(s.vertexCount(), 0);
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f])
      for (int k = 0; k < 3; ++k) used[s.triangles[f][k]] = 1;
  std::atomic<size_t> near{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, s.vertexCount(), 1 << 12), [&](const tbb::blocked_range<size_t>& r) {
    size_t count = 0;
    for (size_t v = r.begin(); v < r.end(); ++v) {
      const float len = glm::length(n[v]);
      if (!used[v] || !(len > 0.f) || !std::isfinite(len)) continue;
      Ray ray;
      ray.d = n[v] / len;
      ray.o = s.positions[v];
      ray.tnear = 0.01f * eps;  // not the vertex's own faces, nor a surface touching it
      ray.tfar = kNearOffsets * eps;
      const Hit h = caster.intersect(ray);
      if (!h.valid() || h.face >= s.faceCount()) continue;
      const glm::uvec3& t = s.triangles[h.face];
      if (t.x == v || t.y == v || t.z == v) continue;
      // Either side: another surface's back this close (a ceiling just
      // above a light's back) lets the vertex's lifted origins pass it as
      // well as its front does.
      if (glm::dot(ray.d, h.ng) != 0.f) ++count;
    }
    near += count;
  });
  if (near == 0) return std::nullopt;
  char b[480];
  std::snprintf(b, sizeof b,
                "%zu vertices face another surface closer than %g ray offsets (%.3g in mesh units) along their "
                "normal: surfaces closer than the offset (%.3g) do not see each other, and the light and occlusion "
                "between them are biased; let such surfaces touch (shared vertices) or keep them farther apart",
                size_t(near), double(kNearOffsets), double(kNearOffsets * eps) * s.unit, double(eps) * s.unit);
  return std::string(b);
}

namespace {

// Points of a triangle at barycentrics away from its centroid and its
// medians: two copies of a quad split along its two diagonals put each
// centroid exactly on the other copy's diagonal edge, where no
// strictly-inside test sees it (a review).
constexpr double kProbe[3][3] = {{0.6, 0.3, 0.1}, {0.1, 0.6, 0.3}, {0.3, 0.1, 0.6}};

// The usable faces' centroids `faces` in a kd-tree.
struct CentroidTree {
  PointCloud cloud;
  std::vector<uint32_t> faces;
  std::unique_ptr<PointTree> tree;
};

}  // namespace

std::optional<std::string> overlappingEmittersWarning(const Scene& s) {
  const std::vector<uint8_t> ok = usableFaceMask(s);
  const size_t nf = s.faceCount();
  std::vector<uint8_t> emits(nf, 0);
  bool anyEmitter = false;
  for (size_t f = 0; f < nf; ++f) {
    emits[f] = ok[f] && luminance(s.faceEmission(f)) > 0.f;
    anyEmitter = anyEmitter || emits[f];
  }
  if (!anyEmitter) return std::nullopt;
  const double eps = sceneScale(s).rayEpsilon;
  const std::vector<glm::vec3> N = unitFaceNormals(s);
  auto corner = [&](size_t f, int k) { return glm::dvec3(s.positions[s.triangles[f][k]]); };
  auto centroid = [&](size_t f) { return (corner(f, 0) + corner(f, 1) + corner(f, 2)) / 3.0; };
  // Two trees: the emitters' centroids and the others'. Every pair with an
  // emitter in it is then found from one side: an emitter's ball finds the
  // faces whose centroid lies in it, a face's ball the emitters' centroids
  // (a lamp smaller than the ceiling cell it lies in). Querying every face
  // against every centroid cost n^2 on a fan of slivers (a review).
  CentroidTree trees[2];  // [0] the others, [1] the emitters
  for (size_t f = 0; f < nf; ++f)
    if (ok[f]) {
      CentroidTree& t = trees[emits[f]];
      t.cloud.pts.push_back(glm::vec3(centroid(f)));
      t.faces.push_back(uint32_t(f));
    }
  for (CentroidTree& t : trees) {
    if (t.faces.empty()) continue;  // (a tree of no points is not searched)
    t.tree = std::make_unique<PointTree>(3, t.cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    t.tree->buildIndex();
  }
  // Whether face a lies on face b: one plane within the ray offset, facing
  // the same way, and one of a's probe points strictly inside b.
  auto liesOn = [&](uint32_t a, uint32_t b) {
    if (a == b || glm::dot(glm::dvec3(N[a]), glm::dvec3(N[b])) < 0.9999) return false;
    const glm::dvec3 p0 = corner(b, 0), e1 = corner(b, 1) - p0, e2 = corner(b, 2) - p0, n(N[b]);
    const double d00 = glm::dot(e1, e1), d01 = glm::dot(e1, e2), d11 = glm::dot(e2, e2);
    const double den = d00 * d11 - d01 * d01;
    if (!(den > 0.0)) return false;
    for (const auto& w : kProbe) {
      const glm::dvec3 x = w[0] * corner(a, 0) + w[1] * corner(a, 1) + w[2] * corner(a, 2) - p0;
      if (std::fabs(glm::dot(x, n)) > eps) return false;
      const double d20 = glm::dot(x, e1), d21 = glm::dot(x, e2);
      const double v = (d11 * d20 - d01 * d21) / den, u = (d00 * d21 - d01 * d20) / den;
      constexpr double kInside = 1e-6;
      if (v > kInside && u > kInside && 1.0 - v - u > kInside) return true;
    }
    return false;
  };
  // Marks gathered per task (no two tasks write one flag).
  tbb::combinable<std::vector<uint32_t>> marks;
  auto search = [&](const CentroidTree& from, const CentroidTree& in, bool both) {
    if (from.faces.empty() || in.faces.empty()) return;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, from.faces.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<std::pair<uint32_t, float>> found;
      std::vector<uint32_t>& mine = marks.local();
      for (size_t k = r.begin(); k < r.end(); ++k) {
        const uint32_t b = from.faces[k];
        const glm::dvec3 c = centroid(b);
        const double radius =
            std::max({glm::length(corner(b, 0) - c), glm::length(corner(b, 1) - c), glm::length(corner(b, 2) - c)}) + eps;
        const float q[3] = {float(c.x), float(c.y), float(c.z)};
        found.clear();
        in.tree->radiusSearch(q, float(radius * radius), found, nanoflann::SearchParams(32, 0.f, false));
        for (const auto& hit : found) {
          const uint32_t a = in.faces[hit.first];
          if (liesOn(a, b) || (both && liesOn(b, a))) mine.push_back(a), mine.push_back(b);
        }
      }
    });
  };
  search(trees[1], trees[0], true);   // emitters' balls, the others' centroids
  search(trees[1], trees[1], true);   // emitters among themselves
  search(trees[0], trees[1], true);   // the others' balls, the emitters' centroids
  std::vector<uint8_t> over(nf, 0);
  marks.combine_each([&](const std::vector<uint32_t>& v) {
    for (uint32_t f : v) over[f] = 1;
  });
  size_t count = 0;
  for (uint8_t o : over) count += o;
  if (count == 0) return std::nullopt;
  return std::to_string(count) +
         " faces lie on another face in the same plane, facing the same way, where one of them emits (a lamp "
         "listed twice and triangulated otherwise, or lying in the ceiling's plane): both copies emit, or they "
         "hide each other by turns, and the light is wrong (a lamp modelled twice is twice as bright); remove "
         "the copies, or lift the lamp off the surface";
}

}  // namespace gi::detail
