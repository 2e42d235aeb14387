#include "gi/open_space.h"

#include <algorithm>
#include <cmath>

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
  const float R = maxDistance + m.maxRadius + m.eps;
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

}  // namespace gi
