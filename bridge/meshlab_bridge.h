// The one bridge between MeshLab (MeshDocument / CMeshO; 2020.09 or 2025.07,
// the differences in ml_compat.h) and the
// engine's Scene: layers in, per-vertex results out, parameter tables to
// RichParameterList and back. Plugins call this and contain no algorithm code.
#pragma once
#include <QString>
#include <functional>
#include <string>
#include <vector>

#include "ml_compat.h"

#include "gi/filter_run.h"
#include "gi/filters.h"
#include "gi/params.h"
#include "gi/refine.h"
#include "gi/run.h"
#include "gi/scene.h"
#include "gi/scene_setup.h"

namespace gi::ml {

struct LayerPart {
  MeshModel* mm = nullptr;
  std::vector<int> sceneVertex;  // per cm.vert index: scene vertex, -1 if deleted
  size_t vertexOffset = 0, vertexCount = 0;
  size_t faceOffset = 0, faceCount = 0;
};

struct BridgeScene {
  Scene scene;
  MeshAttributes attrs;
  std::vector<LayerPart> parts;
  std::vector<std::string> warnings;  // what the run's log should warn of (coordinates too coarse to trust)
  std::vector<std::string> notes;     // and say (visible layers without faces left out)
};

// Layers taking part: the current one, or every visible one with faces (a
// point cloud, such as photon mapping's photon layer, is neither lit nor
// occludes: it was written over with 0s and black; *faceless, if given,
// gets how many were left out). Throws std::invalid_argument if there is none.
std::vector<MeshModel*> participatingLayers(MeshDocument& md, SceneExtent extent, size_t* faceless = nullptr);
// Converts the layers (deleted elements skipped) into one scene. Throws
// std::invalid_argument when there is nothing to work on (no faces).
BridgeScene toScene(const std::vector<MeshModel*>& layers);

// Dialog <-> engine parameters. Distances become RichAbsPerc over the diagonal.
void addParams(RichParameterList& out, const std::vector<ParamSpec>& specs, double diagonal);
ParamValues readParams(const RichParameterList& in, const std::vector<ParamSpec>& specs);
// Diagonal of the layers' bounding boxes (current layer or all visible ones).
double documentDiagonal(MeshDocument& md);

// Writes a filter's result into the layers, after any refined geometry has
// replaced theirs: quality, colour, normals, face values and per-vertex
// attributes (Scalarm or Point3m), each only when the result has it.
// The caller checks first (checkResultFits, before it writes any file).
void writeResult(BridgeScene& b, FilterResult& r);
// Throws std::invalid_argument, before any change, where a layer holds a
// per-vertex attribute of a result's name but another type.
void checkResultFits(const BridgeScene& b, const FilterResult& r);

// Replaces each layer's geometry by its part of `m`, a refinement of
// b.scene (faces whose sourceFace lies in the layer's face range): old
// vertices stay, new ones are appended (position, normal, colour and quality
// interpolated), faces keep colour, quality and selection of their source
// face; topology, face normals and bounding box are updated. Then b (scene,
// attributes, parts) is indexed as toScene would index the new layers.
// Returns, per new scene vertex and face, its index in m.scene. (mesh_replace.cpp)
struct RefinedOrder {
  std::vector<uint32_t> vertex, face;
};
RefinedOrder replaceWithRefined(BridgeScene& b, const RefinedMesh& m);

// MeshLab progress callback -> engine progress (cancellation not supported by
// MeshLab's cb). meshlabserver prints the labels back to back, so there each
// ends with a newline.
ProgressFn progressFrom(vcg::CallBackPos* cb);

// Runs `body`; converts engine exceptions into errorMessage + a log line + false.
// `log` prints one line into MeshLab's log (shown by the GUI and meshlabserver).
bool guarded(QString& errorMessage, const std::function<void(const std::string&)>& log, const QString& filter,
             const std::function<void()>& body);

}  // namespace gi::ml

namespace gi::ml {

// The filter's input from the document: its parameters, the participating
// layers (scene extent) as one scene with their names.
FilterInput gatherInput(MeshDocument& md, const RichParameterList& par, FilterKind kind, BridgeScene& b);
// Each image of the result as a new raster layer with the camera it was seen from.
void addRasters(MeshDocument& md, const FilterResult& r);
// Each new layer of the result (points or triangles, colour, quality,
// normals) as a new mesh layer; the current layer stays current. A layer an
// earlier run of ours made under the same name is refilled instead (a
// re-run does not stack copies); the notes say which.
std::vector<std::string> addLayers(MeshDocument& md, const FilterResult& r);

}  // namespace gi::ml
