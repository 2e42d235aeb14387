// A spatial order of a mesh's vertices, for memory locality.
//   key(p) = bits of q_x, q_y, q_z interleaved, q = floor(2^21 (p - lo) / L)
// over the bounding box (lo, edge L of its bounding cube): the Morton or
// Z-order curve (Morton 1966). Vertices near each other in space are then
// mostly near each other in memory, so the passes over the vertices of a
// per-vertex filter (normals, ray origins, the neighbourhoods of the shared AO
// estimator, the rays of consecutive vertices through the same part of the
// BVH, Embree's build) read memory that is already in the cache. Meshes
// written by subdivision list each level's new vertices after the old ones:
// on a Loop-subdivided 1.9M-vertex scan half the edges join vertices more
// than 100k indices apart.
//
// A filter computes on the reordered copy and writes its results back in the
// mesh's order; every random number stays keyed by the mesh's index of its
// vertex (VertexPart::ids, read through VertexPart::meshIndex), so a vertex
// gets the same rays in either order.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "gi/scene.h"

namespace gi {

// Meshes from this many vertices are reordered by the filters that read
// them vertex by vertex (below it their data stays in the caches anyway).
constexpr size_t kSpatialOrderFrom = size_t(1) << 16;

struct VertexOrder {
  // The mesh's index of the vertex at each place of the order; null: the
  // mesh's own order (nothing reordered).
  std::shared_ptr<const std::vector<uint32_t>> meshIndex;
  bool identity() const { return !meshIndex; }
};

// The Morton order of the vertices (ties, and vertices with NaN or Inf
// coordinates, last, in index order), or the identity below minVertices.
VertexOrder spatialVertexOrder(const Scene& s, size_t minVertices = 0);

// The scene with its vertices (positions, vertex normals) in the order and the
// triangles' indices renumbered; the faces and per-face data keep their order
// (so per-vertex sums over faces add in the same order: same bits). Indices
// out of range stay out of range.
Scene reorderVertices(const Scene& s, const VertexOrder& o);

// Values per place of the order back into the mesh's order.
template <class T>
std::vector<T> toMeshOrder(const std::vector<T>& v, const VertexOrder& o) {
  if (o.identity() || v.empty()) return v;
  const std::vector<uint32_t>& m = *o.meshIndex;
  std::vector<T> out(v.size());
  for (size_t i = 0; i < m.size() && i < v.size(); ++i) out[m[i]] = v[i];
  return out;
}

}  // namespace gi
