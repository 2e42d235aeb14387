// The Morton order of a mesh's vertices (gi/vertex_order.h).
#include "gi/vertex_order.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

namespace gi {

namespace {
// The 21 low bits of x spread to every third bit (bit k to bit 3k).
uint64_t spread3(uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}
}  // namespace

VertexOrder spatialVertexOrder(const Scene& s, size_t minVertices) {
  const size_t nv = s.vertexCount();
  VertexOrder o;
  if (nv < std::max<size_t>(minVertices, 2)) return o;
  glm::vec3 lo(HUGE_VALF), hi(-HUGE_VALF);
  for (const glm::vec3& p : s.positions)
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
  const double edge = lo.x <= hi.x ? std::max({double(hi.x) - lo.x, double(hi.y) - lo.y, double(hi.z) - lo.z}) : 0.0;
  const double scale = edge > 0.0 ? double((1u << 21) - 1) / edge : 0.0;
  struct Keyed {
    uint64_t key;
    uint32_t index;
    bool operator<(const Keyed& b) const { return key != b.key ? key < b.key : index < b.index; }
  };
  std::vector<Keyed> k(nv);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const glm::vec3& p = s.positions[i];
      uint64_t key = ~uint64_t(0);  // non-finite: last
      if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) {
        auto q = [&](float c, float l) { return uint64_t(std::clamp((double(c) - l) * scale, 0.0, double((1u << 21) - 1))); };
        key = spread3(q(p.x, lo.x)) | spread3(q(p.y, lo.y)) << 1 | spread3(q(p.z, lo.z)) << 2;
      }
      k[i] = {key, uint32_t(i)};
    }
  });
  tbb::parallel_sort(k.begin(), k.end());
  auto index = std::make_shared<std::vector<uint32_t>>(nv);
  for (size_t i = 0; i < nv; ++i) (*index)[i] = k[i].index;
  o.meshIndex = std::move(index);
  return o;
}

Scene reorderVertices(const Scene& s, const VertexOrder& o) {
  if (o.identity()) return s;
  const std::vector<uint32_t>& m = *o.meshIndex;
  const size_t nv = s.vertexCount();
  std::vector<uint32_t> place(nv);
  for (size_t i = 0; i < nv; ++i) place[m[i]] = uint32_t(i);
  Scene r = s;  // every per-face array and setting as it is
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 1 << 14), [&](const tbb::blocked_range<size_t>& b) {
    for (size_t i = b.begin(); i < b.end(); ++i) {
      r.positions[i] = s.positions[m[i]];
      if (s.vertexNormals.size() == nv) r.vertexNormals[i] = s.vertexNormals[m[i]];
    }
  });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, s.faceCount(), 1 << 14), [&](const tbb::blocked_range<size_t>& b) {
    for (size_t f = b.begin(); f < b.end(); ++f)
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = s.triangles[f][k];
        r.triangles[f][k] = v < nv ? place[v] : v;
      }
  });
  return r;
}

}  // namespace gi
