// A mesh file's per-vertex values without its geometry: what the error map
// reads as a reference (gi/filter_run.h, VertexFileReader). PLY only, by our
// strict reader (mesh_parts.h); no OpenMesh, so the MeshLab bridge links it too.
#pragma once
#include <string>
#include <vector>

#include "gi/filter_run.h"

namespace gi::io {

// The vertex count and the vertex element's float properties of a PLY
// ("quality", "StdError"; NAME_x, NAME_y, NAME_z as the vector NAME).
// Throws std::runtime_error "cannot read PATH: WHY." on any defect.
VertexFile readVertexFile(const std::string& path);

namespace detail {
struct Polygons;
// The kept vertex properties as named attributes, as writePly writes them.
std::vector<VertexAttribute> vertexAttributes(const Polygons& p);
}  // namespace detail

}  // namespace gi::io
