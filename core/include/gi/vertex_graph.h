// Which vertices share a face: the mesh rings that the shared ambient
// occlusion estimator pools over and the reference's error bars read.
#pragma once
#include <cstdint>
#include <vector>

#include "gi/scene.h"

namespace gi {

// Vertex adjacency from the usable faces (compressed rows, no duplicates).
struct VertexGraph {
  std::vector<uint32_t> offset;  // vertexCount + 1
  std::vector<uint32_t> nbr;
  static VertexGraph build(const Scene& s, const std::vector<uint8_t>* usable = nullptr);  // usable: usableFaceMask(s) if known
  size_t degree(uint32_t v) const { return offset[v + 1] - offset[v]; }
};

// Per vertex, at least the mean of x over about two rings around it (the
// 1-ring's mean, the vertex included, taken twice; only vertices marked in
// `use` take part and change): the error bars' variance where a vertex's
// own few samples are skewed low (a luminaire picked rarely, a small bright
// patch most gather rays miss) while its neighbours', which see nearly the
// same light, catch what it missed.
void atLeastRingMean(const VertexGraph& g, const std::vector<uint8_t>& use, std::vector<double>& x);

}  // namespace gi
