// One way to run a filter, whatever the front end. The MeshLab plugins, the
// command-line tool and the tests hand the same FilterInput (the scene of all
// layers, their attributes and names, the parameter values) to runFilter and
// get one FilterResult back; they only read and write data. So a filter
// behaves the same in MeshLab, in meshlabserver scripts and in `gi`, and a new
// filter added to the catalogue (gi/filters.h) appears in all of them at once.
//
// Steps, the same for every filter:
//   1. validate the parameter values against the filter's table;
//   2. apply the scene conventions (reflectance, emitters, mirror and glass
//      layers: docs/design.md, "Conventions");
//   3. run the algorithm;
//   4. map the physical result to the output convention (quality = the
//      physical scalar, colour = its display mapping) and check that nothing
//      non-finite leaves the engine.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "gi/camera.h"
#include "gi/color.h"
#include "gi/filters.h"
#include "gi/image.h"
#include "gi/params.h"
#include "gi/refine.h"
#include "gi/run.h"
#include "gi/scene.h"
#include "gi/scene_setup.h"
#include "gi/vertex_part.h"

namespace gi {

// A per-vertex attribute: MeshLab stores it as a named per-vertex attribute
// (Scalarm or Point3m), the command-line tool as PLY vertex properties.
struct VertexAttribute {
  std::string name;           // e.g. "BentNormal", "StdError", "Radiosity"
  int components = 1;         // 1 (scalar) or 3 (vector)
  std::vector<float> values;  // vertexCount x components
};

// The vertex quality the layers carry, as an input attribute of this name
// (the PLY property's; MeshLab's per-vertex quality, where the layers have it).
inline const char* const kQualityAttribute = "quality";

// What a front end reads from a mesh file a parameter names (the error map's
// reference): its vertex count and per-vertex values ("quality" and the other
// float properties, as FilterInput::attributes). Throws std::runtime_error
// with one sentence on a file it cannot read.
struct VertexFile {
  size_t vertexCount = 0;
  std::vector<VertexAttribute> attributes;
  std::vector<glm::dvec3> positions;  // absolute; empty where a reader has none
};
using VertexFileReader = std::function<VertexFile(const std::string& path)>;

struct FilterInput {
  Scene scene;                     // all layers as one scene (vertex normals are not used: see docs/design.md)
  MeshAttributes attrs;            // colours, face quality and selection, as the meshes carry them
  std::vector<LayerRange> layers;  // layer names and face ranges, in scene order
  ParamValues values;              // every parameter of the filter's table (distances absolute)
  // What an earlier filter left on the mesh, per vertex of the scene (e.g.
  // "Radiosity", the first pass of a two-pass rendering).
  std::vector<VertexAttribute> attributes;
  // The camera stored with the current layer (MeshLab: Filters > Camera >
  // Set Mesh Camera takes the current view), if it has one.
  std::optional<ShotData> layerCamera;
  // The per-vertex estimators compute only this part of the vertices (a run
  // split over processes, see estimateFilter); all of them by default.
  VertexPart vertices;
  // Reads a mesh file a parameter names; unset: the front end reads none.
  VertexFileReader readVertexFile;
  // The number the front end shows for each scene face, where it differs
  // from the face's place in the scene: MeshLab counts a layer's deleted
  // faces until they are compacted (its face k is then not scene face k),
  // after the faces of the layers before it. face_index and the log's face
  // numbers are in it. Empty: the scene's own (the command-line tool).
  std::vector<uint64_t> faceNumbers;
  // The scene face a front end's face number names (faceNumbers), and back.
  std::optional<uint32_t> sceneFace(uint64_t number) const;
  uint64_t faceNumber(uint32_t sceneFace) const { return faceNumbers.empty() ? sceneFace : faceNumbers[sceneFace]; }
  const VertexAttribute* attribute(const std::string& name) const;
};

// An image a filter made (the ray-traced view): linear radiance, the
// exposure of its display, the camera it was seen from, and where to write
// it (PNG for viewing, PFM with the linear values; empty: not written).
struct FilterImage {
  std::string name;
  Image image;
  float exposure = 1.f;
  Camera camera;
  std::string path;
};

// A text file a parameter asked for (radiosity's residual per step as CSV).
struct FilterFile {
  std::string path;
  std::string text;
};

// A new layer a filter made (photon mapping's photons): a point cloud (no
// triangles) or a triangle mesh, with per-vertex colour and quality and,
// optionally, normals. MeshLab adds it to the document; the command-line
// tool writes it as a PLY beside its output (layerPath).
struct FilterLayer {
  std::string name;        // the layer's name (MeshLab) and the file name's suffix (CLI)
  Scene mesh;              // positions (absolute through mesh.toWorld), triangles (empty: points)
  std::vector<float> quality;
  std::vector<Rgb8> color;
  std::vector<glm::vec3> normals;  // unit, per vertex, or empty
};

// Where the command-line tool writes `layer` beside its output PLY:
// "out.ply" and the layer "Photons" -> "out.Photons.ply" (characters other
// than letters, digits, '-' and '_' in the name become '_').
std::string layerPath(const std::string& outputPly, const std::string& layerName);

struct FilterResult {
  // Per vertex / face of the output scene (the input's, or `refined->scene`);
  // an empty array leaves that property of the mesh as it was.
  std::vector<float> vertexQuality;
  std::vector<Rgb8> vertexColor;
  std::vector<glm::vec3> vertexNormal;  // only when a parameter asks to replace the normals
  std::vector<float> faceQuality;
  std::vector<Rgb8> faceColor;
  std::vector<VertexAttribute> attributes;
  std::optional<RefinedMesh> refined;  // the geometry was refined; the arrays above refer to it
  std::vector<FilterImage> images;
  std::vector<FilterFile> files;
  // Files of an earlier run that would describe another result beside
  // this one's (a path-traced view's NAME_stderr images beside a Whitted
  // image written to the same NAME): removed once the result is written.
  std::vector<std::string> staleFiles;
  std::vector<FilterLayer> layers;  // new layers (the input's are not among them)
  // Per face, the linear RGB value the estimate leaves for the output step
  // to map to faceQuality and faceColor (radiosity's face output).
  std::vector<glm::vec3> faceRadiometry;

  // Duplicated faces left out of the computation (Scene::leftOut), as
  // (copy, original) pairs of faces, and of vertices where a copy's corner
  // is a vertex of its own: the output gives each its original's values.
  std::vector<std::pair<uint32_t, uint32_t>> sameFaces, sameVertices;

  SceneReport report;    // the scene the algorithm saw (after the conventions)
  std::string setupLog;  // reflectance, emitters, materials: what the conventions chose
  std::vector<std::string> setupWarnings;  // what of it the log warns of (added to stats by the estimate)
  RunStats stats;        // the algorithm's numbers, notes and warnings

  const VertexAttribute* attribute(const std::string& name) const;
  // The two log lines every front end prints: the scene and what was computed.
  std::vector<std::string> logLines(const std::string& title) const;
  // Reorders the per-vertex and per-face arrays: new index i takes old index order[i].
  void reorder(const std::vector<uint32_t>& vertexOrder, const std::vector<uint32_t>& faceOrder);
};

// Runs filter `kind` on `in` (its scene takes the conventions' reflectance,
// emission and materials). Throws std::invalid_argument with one sentence
// for unusable input or parameters, gi::Cancelled if progress asks to stop.
FilterResult runFilter(FilterKind kind, FilterInput& in, const Progress& progress = Progress(nullptr));

// runFilter in two halves, for a front end that may reuse a stored result of
// the same prepared scene: steps 1-2 (the result holds the scene report and
// the set-up log), then steps 3-4.
FilterResult prepareFilter(FilterKind kind, FilterInput& in);
void computeFilter(FilterKind kind, FilterInput& in, FilterResult& res, const Progress& progress = Progress(nullptr));

// Steps 3 and 4 apart, for one mesh split over processes (docs/design.md,
// "Split runs"): estimateFilter computes the physical per-vertex values of
// the vertices in `in.vertices` (vertexQuality, vertexNormal and the
// attributes; the other vertices' entries are 0), the front end gathers the
// parts' values into one result, and outputFilter maps them to the output
// convention (the automatic exposure needs every vertex) and checks them.
// computeFilter is the two in a row. Only the per-vertex estimators can be
// split (splitsVertices); estimateFilter refuses a part for the others.
bool splitsVertices(FilterKind kind);
void estimateFilter(FilterKind kind, FilterInput& in, FilterResult& res, const Progress& progress = Progress(nullptr));
void outputFilter(FilterKind kind, FilterInput& in, FilterResult& res);

// Writes each image that has a path: the PNG there (sRGB at its exposure)
// and the linear values beside it as PFM (same name, .pfm); and each text
// file. Throws std::runtime_error naming the file on failure.
void writeOutputFiles(const FilterResult& r);

}  // namespace gi
