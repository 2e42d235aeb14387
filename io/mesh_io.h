// Mesh files for the command-line tool: PLY/OBJ/OFF/STL in, PLY out. PLY and
// OFF are read by our own strict readers, OBJ and STL by OpenMesh after a
// strict check; any defect is an error naming the file and the place.
#pragma once
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gi/filter_run.h"
#include "gi/scene.h"
#include "gi/scene_setup.h"

namespace gi::io {

struct LoadedMesh {
  Scene scene;            // positions (re-centred), triangles (polygons fan-triangulated), normals if the file has them
  MeshAttributes attrs;   // face/vertex colours (sRGB bytes), face quality, vertex selection (PLY flags), if in the file
  std::vector<uint32_t> triangleToFace;  // source polygon of each triangle
  // Per-vertex values an earlier filter left (PLY only: the vertex element's
  // other float properties; NAME_x, NAME_y, NAME_z as the vector NAME).
  std::vector<VertexAttribute> attributes;
  // The layers this tool wrote into one PLY (writePly's `layers`), as names
  // and triangle counts in face order; empty when the file records none, or
  // records some that no longer match its faces (edited elsewhere, or
  // polygons): then the file is one layer.
  std::vector<std::pair<std::string, size_t>> layers;
  // What the run's log should warn of: polygons no triangulation of ours
  // could keep inside themselves.
  std::vector<std::string> warnings;
  // The vertices' positions as the file gives them (double): the scene keeps
  // them as floats about its centre, whose sum with the centre moved
  // coordinates by a float step in every file written back (a radiosity run
  // on such a file then differed by up to 0.018 from one on the original;
  // an outside audit). writePly writes these (PlyExtras::positions).
  std::vector<glm::dvec3> points;
};

// Throws std::runtime_error with one sentence ("cannot read X: ...") on failure:
// a damaged or hostile file is never partly loaded.
LoadedMesh loadMesh(const std::string& path);
// The same from bytes in memory; `format` is ply, obj, off or stl and `name`
// names it in messages (an OBJ's material library is not followed).
LoadedMesh parseMesh(std::string_view bytes, const std::string& format, const std::string& name);

// The layers of a loaded file as the scene's layers from `faceOffset` on:
// those it records, else the whole file as one layer named `fileName`.
std::vector<LayerRange> meshLayers(const LoadedMesh& m, const std::string& fileName, size_t faceOffset = 0);

// Appends another mesh as a further part of one scene (colours and face
// quality that only one of them has are filled with defaults: grey 188
// colours, quality 0; per-vertex attributes that not both have are dropped;
// the recorded layers are dropped: take meshLayers of each part first).
// The scene's frame (origin, unit, float positions) is rebuilt from the
// parts' double coordinates, as MeshLab's layers share one: at once
// (Reframing::Now), or, when several parts are appended in a row, deferred
// (Reframing::Deferred) to one call of reframe after the last; rebuilding it at
// each part would cost the square of the part count.
enum class Reframing { Now, Deferred };
void appendMesh(LoadedMesh& into, const LoadedMesh& other, Reframing when = Reframing::Now);
void reframe(LoadedMesh& m);

// Writes a binary PLY: vertices with colour (uchar red/green/blue, if given) and
// "quality" (float, if given), faces with colour and quality if attrs has them,
// and optionally normals and named per-vertex attributes (a scalar as
// "property float NAME", a vector as NAME_x, NAME_y, NAME_z).
// Written whole or not at all (atomic_file.h).
struct PlyExtras {
  std::vector<glm::vec3> normals;  // written as nx, ny, nz if not empty
  std::vector<VertexAttribute> attributes;
  // Two or more layers of one scene written into this file (name, faces, in
  // face order): recorded as "comment gi_layer COUNT NAME" header lines, so
  // that loading the file gives the layers back (MeshLab ignores them).
  std::vector<std::pair<std::string, size_t>> layers;
  // Absolute positions to write instead of the scene's (the file's, as
  // read): as float where every coordinate is one, else as double.
  std::vector<glm::dvec3> positions;
};
void writePly(const std::string& path, const Scene& s, const MeshAttributes& attrs,
              const std::vector<float>& vertexQuality, const std::vector<Rgb8>& vertexColor,
              const PlyExtras& extras = {});
// Whether writePly writes a vertex property of this name itself (x, y, z,
// the normal, the colour, quality): an attribute may not take it.
bool plyVertexPropertyOfItsOwn(const std::string& name);

}  // namespace gi::io
