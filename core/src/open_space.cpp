#include "gi/open_space.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <nanoflann.hpp>

namespace gi {

struct OpenSpaceTest::Impl {
  struct Cloud {
    std::vector<glm::vec3> pts;
    size_t kdtree_get_point_count() const { return pts.size(); }
    float kdtree_get_pt(size_t i, size_t d) const { return pts[i][int(d)]; }
    template <class B> bool kdtree_get_bbox(B&) const { return false; }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3, uint32_t>;
  const Scene& s;
  float eps;
  Cloud cloud;            // centroids of usable faces
  std::vector<uint32_t> face;
  std::vector<float> radius;  // bounding radius around the centroid
  float maxRadius = 0.f;
  std::unique_ptr<Tree> tree;
  Impl(const Scene& sc, float e) : s(sc), eps(e) {}
};

OpenSpaceTest::OpenSpaceTest(const Scene& s, float eps) : impl_(std::make_unique<Impl>(s, eps)) {
  const auto ok = usableFaceMask(s);
  for (size_t f = 0; f < ok.size(); ++f) {
    if (!ok[f]) continue;
    const auto& t = s.triangles[f];
    const glm::vec3 c = (s.positions[t.x] + s.positions[t.y] + s.positions[t.z]) / 3.f;
    float r = 0.f;
    for (int k = 0; k < 3; ++k) r = std::max(r, glm::length(s.positions[t[k]] - c));
    impl_->cloud.pts.push_back(c);
    impl_->face.push_back(uint32_t(f));
    impl_->radius.push_back(r * 1.0001f);
    impl_->maxRadius = std::max(impl_->maxRadius, r * 1.0001f);
  }
  impl_->tree = std::make_unique<Impl::Tree>(3, impl_->cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  impl_->tree->buildIndex();
}

OpenSpaceTest::~OpenSpaceTest() = default;

bool OpenSpaceTest::hemisphereEmpty(const glm::vec3& p, const glm::vec3& n, float maxDistance) const {
  const Impl& m = *impl_;
  if (m.cloud.pts.empty()) return true;
  // Ray origins lie within sqrt(2) eps of p (lifted by eps, and pulled by
  // eps into the faces at lopsided one-rings): reach 2 eps beyond maxDistance.
  const float R = maxDistance + m.maxRadius + 2.f * m.eps;
  std::vector<std::pair<uint32_t, float>> found;
  nanoflann::SearchParams params;
  params.sorted = false;
  const float q[3] = {p.x, p.y, p.z};
  m.tree->radiusSearch(q, R * R, found, params);
  for (const auto& [k, d2] : found) {
    // Outside the reach of every ray (origin p + n eps, length maxDistance)?
    if (std::sqrt(d2) - m.radius[k] > maxDistance + 2.f * m.eps) continue;
    // Entirely at or below the plane at height eps/2 over the tangent plane?
    // Rays start at height eps and go up, so they cannot reach it.
    const auto& t = m.s.triangles[m.face[k]];
    float h = -HUGE_VALF;
    for (int j = 0; j < 3; ++j) h = std::max(h, glm::dot(n, m.s.positions[t[j]] - p));
    if (h < 0.5f * m.eps) continue;
    return false;
  }
  return true;
}

struct SceneBelowTest::Impl {
  struct Node {
    glm::vec3 centre, half;  // box of the node's points
    uint32_t begin, end;     // its points in pts
    int32_t left = -1;       // children left and left + 1; -1: a leaf
  };
  static constexpr uint32_t kLeaf = 8;
  std::vector<glm::vec3> pts;
  std::vector<Node> nodes;
  std::vector<glm::dvec3> extremes;  // the farthest point in each of 26 directions
  std::vector<uint8_t> cornerAbove;  // per vertex: a corner of one of its faces lies above its plane
  const Scene* s = nullptr;
  const std::vector<glm::vec3>* normals = nullptr;
  float eps;

  // Fills nodes[id] over pts[b, e), split at the median of its box's longest side.
  void build(size_t id, uint32_t b, uint32_t e) {
    glm::vec3 lo(HUGE_VALF), hi(-HUGE_VALF);
    for (uint32_t i = b; i < e; ++i) { lo = glm::min(lo, pts[i]); hi = glm::max(hi, pts[i]); }
    nodes[id] = {0.5f * (lo + hi), 0.5f * (hi - lo), b, e, -1};
    if (e - b <= kLeaf) return;
    const glm::vec3 size = hi - lo;
    const int axis = size.x >= size.y && size.x >= size.z ? 0 : size.y >= size.z ? 1 : 2;
    const uint32_t mid = b + (e - b) / 2;
    std::nth_element(pts.begin() + b, pts.begin() + mid, pts.begin() + e,
                     [axis](const glm::vec3& u, const glm::vec3& v) { return u[axis] < v[axis]; });
    const size_t left = nodes.size();
    nodes[id].left = int32_t(left);
    nodes.resize(left + 2);
    build(left, b, mid);
    build(left + 1, mid, e);
  }
};

SceneBelowTest::SceneBelowTest(const Scene& s, float eps, const std::vector<glm::vec3>& normals,
                               const std::vector<uint8_t>* usable)
    : impl_(std::make_unique<Impl>()) {
  std::vector<uint8_t> own;
  const std::vector<uint8_t>& ok = usableFaces(s, usable, own);
  Impl& m = *impl_;
  m.eps = eps;
  m.s = &s;
  m.normals = &normals;
  const double limit = 0.5 * double(eps);
  std::vector<uint8_t> used(s.vertexCount(), 0);
  m.cornerAbove.assign(s.vertexCount(), 0);
  for (size_t f = 0; f < ok.size(); ++f) {
    if (!ok[f]) continue;
    const auto& t = s.triangles[f];
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = t[k];
      used[i] = 1;
      const glm::dvec3 n(normals[i]), p(s.positions[i]);
      for (int j = 1; j < 3; ++j)
        if (glm::dot(n, glm::dvec3(s.positions[t[(k + j) % 3]]) - p) > limit) m.cornerAbove[i] = 1;
    }
  }
  for (size_t v = 0; v < used.size(); ++v)
    if (used[v]) m.pts.push_back(s.positions[v]);
  if (!m.pts.empty()) {
    m.nodes.reserve(2 * (m.pts.size() / (Impl::kLeaf / 2) + 1));
    m.nodes.resize(1);
    m.build(0, 0, uint32_t(m.pts.size()));
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z) {
          if (!(x || y || z)) continue;
          const glm::dvec3 d(x, y, z);
          const auto far = std::max_element(m.pts.begin(), m.pts.end(), [&d](const glm::vec3& u, const glm::vec3& v) {
            return glm::dot(d, glm::dvec3(u)) < glm::dot(d, glm::dvec3(v));
          });
          m.extremes.push_back(glm::dvec3(*far));
        }
  }
}

SceneBelowTest::~SceneBelowTest() = default;

bool SceneBelowTest::sceneBelow(uint32_t v) const {
  const Impl& m = *impl_;
  if (m.cornerAbove[v]) return false;  // its own faces rise above its plane
  if (m.nodes.empty()) return true;
  const glm::vec3& p = m.s->positions[v];
  const glm::vec3& n = (*m.normals)[v];
  // Heights over the tangent plane in double: float rounding stays far below eps / 2.
  const glm::dvec3 nd(n), pd(p), an(glm::abs(nd));
  const double limit = 0.5 * double(m.eps);
  auto bound = [&](const Impl::Node& k) {
    return glm::dot(nd, glm::dvec3(k.centre) - pd) + glm::dot(an, glm::dvec3(k.half)) * (1.0 + 1e-6);
  };
  // Most vertices that are not open have one of the scene's extreme points
  // above their plane: no search for them.
  for (const glm::dvec3& q : m.extremes)
    if (glm::dot(nd, q - pd) > limit) return false;
  if (bound(m.nodes[0]) <= limit) return true;
  int32_t stack[128];  // nodes whose box reaches above the limit
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Impl::Node& k = m.nodes[size_t(stack[--top])];
    if (k.left < 0) {
      for (uint32_t i = k.begin; i < k.end; ++i)
        if (glm::dot(nd, glm::dvec3(m.pts[i]) - pd) > limit) return false;
      continue;
    }
    // The children reaching above the limit, the higher one pushed last so
    // that it is searched first: a vertex that is not open meets a point
    // above its plane soon.
    const int32_t a = k.left, b = k.left + 1;
    const double ha = bound(m.nodes[size_t(a)]), hb = bound(m.nodes[size_t(b)]);
    const bool aFirst = ha >= hb;
    const double hLast = aFirst ? hb : ha, hFirst = aFirst ? ha : hb;
    if (hLast > limit) stack[top++] = aFirst ? b : a;
    if (hFirst > limit) stack[top++] = aFirst ? a : b;
  }
  return true;
}

}  // namespace gi
