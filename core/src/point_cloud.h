// Points in a nanoflann kd-tree: the adaptor nanoflann asks for, over a
// vector of positions. Internal to the engine's sources.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>
#include <nanoflann.hpp>

namespace gi {

struct PointCloud {
  std::vector<glm::vec3> pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
  float kdtree_get_pt(size_t i, size_t d) const { return pts[i][int(d)]; }
  template <class B> bool kdtree_get_bbox(B&) const { return false; }
};
using PointTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointCloud>, PointCloud, 3, uint32_t>;

}  // namespace gi
