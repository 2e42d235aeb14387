// Mesh files for the command-line tool (OpenMesh): PLY/OBJ/OFF/STL in, PLY out.
#pragma once
#include <string>
#include <vector>

#include "gi/filter_run.h"
#include "gi/scene.h"
#include "gi/scene_setup.h"

namespace gi::io {

struct LoadedMesh {
  Scene scene;            // positions (re-centred), triangles (polygons fan-triangulated), normals if the file has them
  MeshAttributes attrs;   // face/vertex colours (sRGB bytes), face quality, if present in the file
  std::vector<uint32_t> triangleToFace;  // source polygon of each triangle
};

// Throws std::runtime_error with one sentence ("cannot read X: ...") on failure.
LoadedMesh loadMesh(const std::string& path);

// Appends another mesh as a further part of one scene (attributes that only
// one of them has are filled with defaults: grey 188 colours, quality 0).
void appendMesh(LoadedMesh& into, const LoadedMesh& other);

// Writes a binary PLY: vertices with colour (uchar red/green/blue, if given) and
// "quality" (float, if given), faces with colour and quality if attrs has them,
// and optionally normals and named per-vertex attributes (a scalar as
// "property float NAME", a vector as NAME_x, NAME_y, NAME_z).
struct PlyExtras {
  std::vector<glm::vec3> normals;  // written as nx, ny, nz if not empty
  std::vector<VertexAttribute> attributes;
};
void writePly(const std::string& path, const Scene& s, const MeshAttributes& attrs,
              const std::vector<float>& vertexQuality, const std::vector<Rgb8>& vertexColor,
              const PlyExtras& extras = {});

}  // namespace gi::io
